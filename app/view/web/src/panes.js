// A pane shows one thing: a trial (world, trajectory, returns, BVCs, place cells, maps), a world on
// its own, or a recording (scans with their poses). Two trial panes side by side share the slider.
import { get, exportedSteps } from './api.js';
import { View3D } from './view3d.js';
import { BvcMaps, Population, BinMap } from './panels.js';

const el = (tag, props = {}, ...children) => {
  const e = Object.assign(document.createElement(tag), props);
  e.append(...children);
  return e;
};
const fmt = (v, digits = 3) => (v === null || v === undefined || !Number.isFinite(v) ? '—' : Number(v).toFixed(digits));

function showError(container, message) {
  container.appendChild(el('div', { className: 'error', textContent: message }));
}

// Fetches one step at a time: while one is in flight only the newest request waits, so scrubbing
// never queues up stale steps.
class StepLoader {
  constructor(load, apply) {
    this.load = load;
    this.apply = apply;
    this.busy = false;
    this.pending = null;
    this.loaded = 0;
  }

  request(i) {
    if (this.busy) {
      this.pending = i;
      return;
    }
    this.busy = true;
    this.load(i)
      .then((step) => { this.loaded++; this.apply(step); })
      .catch((e) => this.apply(null, e))
      .finally(() => {
        this.busy = false;
        if (this.pending !== null) {
          const next = this.pending;
          this.pending = null;
          this.request(next);
        }
      });
  }

  idle() { return !this.busy && this.pending === null; }
}

function nearest(sorted, i) {
  if (!sorted || !sorted.length) return i;
  let lo = 0, hi = sorted.length - 1;
  while (hi - lo > 1) {
    const mid = (lo + hi) >> 1;
    if (sorted[mid] <= i) lo = mid; else hi = mid;
  }
  return Math.abs(sorted[lo] - i) <= Math.abs(sorted[hi] - i) ? sorted[lo] : sorted[hi];
}

class Pane {
  constructor(container, title) {
    this.root = el('section', { className: 'pane' });
    this.heading = el('h2', { textContent: title });
    this.sub = el('div', { className: 'sub' });
    this.root.append(this.heading, this.sub);
    container.appendChild(this.root);
    this.length = 0;
  }

  addView() {
    this.viewBox = el('div', { className: 'view3d' });
    this.legend = el('div', { className: 'legend' });
    this.viewBox.appendChild(this.legend);
    this.root.appendChild(this.viewBox);
    this.view = new View3D(this.viewBox);
    this.readout = el('div', { className: 'readout' });
    this.root.appendChild(this.readout);
  }

  error(message) {
    showError(this.root, message);
    this.failed = message;
  }
}

export class TrialPane extends Pane {
  constructor(container, path) {
    super(container, path);
    this.path = path;
    this.selected = -1;
  }

  async open() {
    let trial;
    try {
      trial = await get('trial', { path: this.path });
    } catch (e) {
      this.error(`cannot open ${this.path}: ${e.message}`);
      return false;
    }
    this.trial = trial;
    const h = trial.header, a = trial.arrays;
    this.length = h.samples;
    this.heading.textContent = h.name;
    const m = h.metrics;
    this.sub.textContent = `${h.world} · model ${h.model_name} · seed ${h.seed} · ${h.samples} samples · ${h.n_place} cells · ` +
      `MSAI ${fmt(m.msai)} · multimodal ${fmt(m.frac_multimodal)} · decoding median ${fmt(m.decode_median_m, 2)} m`;
    this.addView();
    this.view.setTrajectory(a.x, a.y, a.z);
    this.steps = exportedSteps(this.path);
    if (h.world_problem) showError(this.root, h.world_problem);
    else {
      this.loadingWorld = get('world', { trial: this.path }).then((w) => this.view.setWorld(w))
        .catch((e) => showError(this.root, e.message)).finally(() => { this.loadingWorld = null; });
    }
    if (h.model_problem) showError(this.root, h.model_problem);
    this.legend.textContent = h.drawn_sensor
      ? `returns: ${h.drawn_sensor.name} scanner, ${h.drawn_sensor.rows} rows; colored by range 0–${h.drawn_sensor.max_range} m; large = rows the model keeps`
      : '';

    const row1 = el('div', { className: 'row' });
    const bvcBox = el('div', { className: 'box' }, el('h3', { textContent: 'BVC activity per layer (distance × direction)' }));
    const popBox = el('div', { className: 'box' }, el('h3', { textContent: 'place cells (click one for its map)' }));
    row1.append(bvcBox, popBox);
    const row2 = el('div', { className: 'row' });
    const cellBox = el('div', { className: 'box cell-map' });
    const saiBox = el('div', { className: 'box sai-map' });
    row2.append(cellBox, saiBox);
    this.root.append(row1, row2);
    if (h.model) this.bvcMaps = new BvcMaps(bvcBox, h.model.bvc);
    this.population = new Population(popBox, h.n_place, h.rate_max, (k) => this.pick(k));
    this.cellMap = new BinMap(cellBox, 'rate map: pick a cell');
    this.saiMap = new BinMap(saiBox, 'spatial aliasing index per bin');
    this.prepareMaps();
    this.drawSai();
    this.loader = new StepLoader((i) => get('step', { path: this.path, i }), (s, e) => this.applyStep(s, e));
    return true;
  }

  prepareMaps() {
    const h = this.trial.header, a = this.trial.arrays;
    const centers = a.bin_centers;
    this.dims = centers ? centers.shape[1] : 2;
    const grid = Object.assign({}, h.grid || {});
    let [x0, x1, y0, y1] = h.extent || [Infinity, -Infinity, Infinity, -Infinity];
    if (!h.extent && centers) {
      for (let b = 0; b < centers.length / this.dims; b++) {
        x0 = Math.min(x0, centers[b * this.dims]); x1 = Math.max(x1, centers[b * this.dims]);
        y0 = Math.min(y0, centers[b * this.dims + 1]); y1 = Math.max(y1, centers[b * this.dims + 1]);
      }
      const px = grid.sx || 0.2, py = grid.sy || 0.2;
      x0 -= px; x1 += px; y0 -= py; y1 += py;
    }
    this.bounds = [x0, x1, y0, y1];
    if (this.dims === 3 && centers) {
      const zs = [...new Set(Array.from({ length: centers.length / 3 }, (_, b) => centers[3 * b + 2]))].sort((p, q) => p - q);
      const xs = [...new Set(Array.from({ length: centers.length / 3 }, (_, b) => centers[3 * b]))].sort((p, q) => p - q);
      grid.step = xs.length > 1 ? Math.min(...xs.slice(1).map((v, i) => v - xs[i])) : 0.25;
      this.slices = zs;
      this.slice = zs[0];
      const pick = el('select', { className: 'slice' });
      zs.forEach((z) => pick.appendChild(el('option', { value: z, textContent: `z = ${z.toFixed(2)} m` })));
      pick.addEventListener('change', () => { this.slice = Number(pick.value); this.drawCell(); this.drawSai(); });
      this.cellMap.title.after(pick);
    }
    this.grid = grid;
  }

  mapArgs(key, values, vmax) {
    const a = this.trial.arrays;
    return { key: `${key}@${this.slice}`, centers: a.bin_centers, dims: this.dims, values, grid: this.grid, bounds: this.bounds,
      marker: this.step ? [this.step.header.x, this.step.header.y] : null, vmax, slice: this.slice };
  }

  drawSai() {
    const sai = this.trial.arrays.sai;
    if (!sai) return;
    if (this.saiTop === undefined) {
      this.saiTop = 0;
      for (const v of sai) if (Number.isFinite(v)) this.saiTop = Math.max(this.saiTop, v);
    }
    const top = this.saiTop;
    this.saiMap.draw(this.mapArgs('sai', sai, top));
    this.saiMap.info.textContent = `MSAI ${fmt(this.trial.header.metrics.msai)} (mean over bins); color 0 – ${fmt(top)}`;
  }

  pick(k) {
    this.selected = k;
    this.population.selected = k;
    this.population.draw(this.population.rates);
    this.drawCell();
  }

  drawCell() {
    const k = this.selected, a = this.trial.arrays, h = this.trial.header;
    if (k < 0 || !a.rate_maps) return;
    if (!this.cellValues || this.cellValues.cell !== k) {
      const B = a.rate_maps.shape[0], n = h.n_place, values = new Float32Array(B);
      let top = 0;
      for (let b = 0; b < B; b++) {
        values[b] = a.rate_maps[b * n + k];
        top = Math.max(top, values[b]);
      }
      this.cellValues = { cell: k, values, top };
    }
    this.cellMap.title.textContent = `rate map of cell ${k}`;
    this.cellMap.draw(this.mapArgs(`cell ${k}`, this.cellValues.values, this.cellValues.top));
    const mi = a.modality ? a.modality[k] : null;
    this.cellMap.info.dataset.cell = k;
    this.cellMap.info.dataset.mi = mi;
    this.cellMap.info.textContent = `cell ${k} · MI (modality) ${mi ?? '—'} · spatial info ${fmt(a.spatial_info && a.spatial_info[k])} bits · ` +
      `peak ${fmt(a.peak_rate && a.peak_rate[k])} · rate now ${fmt(this.population.rates && this.population.rates[k])}`;
  }

  // The sample to show: the agent moves at once; the step's data follows when it arrives.
  moveTo(i) {
    if (!this.trial) return;
    i = Math.max(0, Math.min(this.length - 1, i));
    this.target = i;
    this.view.moving();
    const a = this.trial.arrays;
    this.view.setAgent(a.x[i], a.y[i], a.z ? a.z[i] : 0, a.heading[i]);
    this.loader.request(this.steps ? nearest(this.steps, i) : i);
  }

  applyStep(step, error) {
    if (!step) {
      showError(this.root, `step: ${error.message}`);
      return;
    }
    this.step = step;
    const h = step.header, a = step.arrays, model = this.trial.header.model;
    if (a.points.length) this.view.setReturns(a.points, a.range, a.kept, this.trial.header.drawn_sensor.max_range);
    if (this.bvcMaps) this.bvcMaps.draw(a.bvc, h.heading);
    this.population.draw(a.place);
    let top = 0, best = 0;
    a.place.forEach((v, k) => { if (v > top) { top = v; best = k; } });
    let kept = 0;
    for (const k of a.kept) kept += k;
    this.readout.dataset.sample = h.sample;
    this.readout.dataset.returns = h.returns ?? 0;
    this.readout.textContent =
      `sample ${h.sample}  t ${h.t.toFixed(3)} s  x ${h.x.toFixed(4)}  y ${h.y.toFixed(4)}  z ${h.z.toFixed(3)}  heading ${h.heading.toFixed(4)} rad\n` +
      `returns ${h.returns ?? 0} (${kept} in rows the model keeps; the model saw ${h.model_returns ?? 0})  ` +
      `most active cell ${best} at ${top.toFixed(4)}` + (this.steps ? `  [exported step nearest to sample ${this.target}]` : '');
    if (model) this.readout.title = `${model.bvc.n_cells} BVCs in ${model.bvc.n_layers} layers`;
    if (this.selected >= 0) this.drawCell();
    else this.cellMap.draw(this.mapArgs('none', null, 1));
    this.drawSai();
    this.view.dirty = true;
  }
}

// A world on its own, with a probe: the default model's scanner and BVCs at a pose on the floor.
// Click the floor (without dragging) to move the probe there; the heading field turns it.
export class WorldPane extends Pane {
  constructor(container, source) {
    super(container, source);
    this.source = source;
  }

  async open() {
    this.addView();
    let w;
    try {
      w = await get('world', { source: this.source });
    } catch (e) {
      this.error(`cannot open world ${this.source}: ${e.message}`);
      return false;
    }
    this.view.setWorld(w);
    this.heading.textContent = `world ${w.header.name}`;
    this.sub.textContent = `${this.source} · ${w.header.triangles} triangles` +
      (w.header.tilt_deg !== undefined ? ` · tilt ${w.header.tilt_deg}°` : '') + ' · click the floor to probe there';
    this.readout.dataset.triangles = w.header.triangles;
    this.readout.textContent = 'orbit: drag · zoom: wheel · pan: right-drag';
    if (!w.header.probe) return true;
    const headingInput = el('input', { type: 'number', value: '0', step: '15', className: 'probe-heading', title: 'heading, degrees' });
    const bvcBox = el('div', { className: 'box' }, el('h3', { textContent: 'BVC activity per layer at the probe (distance × direction)' }),
      el('label', { textContent: 'heading ° ' }, headingInput));
    this.root.appendChild(el('div', { className: 'row' }, bvcBox));
    this.bvcBox = bvcBox;
    this.pose = { ...w.header.probe };
    headingInput.addEventListener('change', () => {
      this.pose.heading = ((Number(headingInput.value) || 0) * Math.PI / 180).toFixed(4);
      this.loader.request(this.pose);
    });
    this.loader = new StepLoader((pose) => get('probe', { source: this.source, ...pose }), (s, e) => this.applyProbe(s, e));
    this.view.onFloorClick = (x, y) => {
      this.pose = { x: x.toFixed(3), y: y.toFixed(3), heading: this.pose.heading };
      this.loader.request(this.pose);
    };
    this.loader.request(this.pose);
    return true;
  }

  applyProbe(probe, error) {
    if (!probe) {
      showError(this.root, `probe: ${error.message}`);
      return;
    }
    this.step = probe;
    const h = probe.header, a = probe.arrays;
    if (!this.bvcMaps) {
      this.bvcMaps = new BvcMaps(this.bvcBox, h.model.bvc);
      this.legend.textContent = `probe: model ${h.model.name}, ${h.drawn_sensor.name} scanner, ${h.drawn_sensor.rows} rows; ` +
        `colored by range 0–${h.drawn_sensor.max_range} m; large = rows the model keeps`;
    }
    this.maxRange = h.drawn_sensor.max_range;
    this.view.setAgent(h.x, h.y, h.z, h.heading);
    this.view.setReturns(a.points, a.range, a.kept, this.maxRange);
    this.bvcMaps.draw(a.bvc, h.heading);
    let kept = 0;
    for (const k of a.kept) kept += k;
    this.readout.dataset.x = h.x;
    this.readout.dataset.y = h.y;
    this.readout.dataset.returns = h.returns;
    this.readout.textContent = `probe at x ${h.x.toFixed(3)}  y ${h.y.toFixed(3)}  heading ${h.heading.toFixed(4)} rad: ` +
      `returns ${h.returns} (${kept} in rows the model keeps; the model saw ${h.model_returns})`;
  }

  moveTo() {}
}

export class RecordingPane extends Pane {
  constructor(container) {
    super(container, 'recording');
  }

  async open() {
    try {
      this.rec = await get('recording');
    } catch (e) {
      this.error(`cannot open the recording: ${e.message}`);
      return false;
    }
    const h = this.rec.header;
    this.length = h.scans;
    this.heading.textContent = `recording: ${h.scans} scans`;
    this.sub.textContent = `poses paired ${h.paired_by_time ? 'by time' : 'in order'} · BVCs of model ${h.model.name}`;
    this.addView();
    const p = this.rec.arrays.position;
    const n = h.scans, x = new Float32Array(n), y = new Float32Array(n), z = new Float32Array(n);
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < n; i++) {
      x[i] = p[3 * i]; y[i] = p[3 * i + 1]; z[i] = p[3 * i + 2];
      for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], p[3 * i + k]); hi[k] = Math.max(hi[k], p[3 * i + k]); }
    }
    this.view.setTrajectory(x, y, z);
    // Frame the path and 10 m around it: a map's far returns would push the camera away.
    const around = [[lo[0] - 10, lo[1] - 10, lo[2] - 2], [hi[0] + 10, hi[1] + 10, hi[2] + 2]];
    this.view.frame(around);
    this.loadingWorld = get('world', { recording: 1 }).then((w) => {
      this.view.setWorld(w);
      this.view.frame(around);
    }).catch((e) => showError(this.root, e.message)).finally(() => { this.loadingWorld = null; });
    this.legend.textContent = 'returns colored by range; large = near a BVC layer\'s elevation';
    const bvcBox = el('div', { className: 'box' }, el('h3', { textContent: `BVC activity per layer (model ${h.model.name})` }));
    this.root.appendChild(el('div', { className: 'row' }, bvcBox));
    this.bvcMaps = new BvcMaps(bvcBox, h.model.bvc);
    this.steps = exportedSteps('#recording');
    this.loader = new StepLoader((i) => get('scan', { i }), (s, e) => this.applyStep(s, e));
    return true;
  }

  heading_of(i) {
    const r = this.rec.arrays.rotation;
    return Math.atan2(r[9 * i + 3], r[9 * i]);
  }

  moveTo(i) {
    if (!this.rec) return;
    i = Math.max(0, Math.min(this.length - 1, i));
    const p = this.rec.arrays.position;
    this.view.moving();
    this.view.setAgent(p[3 * i], p[3 * i + 1], p[3 * i + 2] - 0.12, this.heading_of(i));
    this.loader.request(this.steps ? nearest(this.steps, i) : i);
  }

  applyStep(step, error) {
    if (!step) {
      showError(this.root, `scan: ${error.message}`);
      return;
    }
    this.step = step;
    const h = step.header, a = step.arrays;
    let far = 1;
    for (const r of a.range) far = Math.max(far, r);
    this.view.setReturns(a.points, a.range, a.kept, Math.min(far, 60));
    this.bvcMaps.draw(a.bvc, this.heading_of(h.scan));
    this.readout.dataset.sample = h.scan;
    this.readout.dataset.returns = h.returns;
    this.readout.textContent = `scan ${h.scan} (${h.name})${h.t !== undefined ? `  t ${h.t.toFixed(3)} s` : ''}  ` +
      `sensor at ${h.sensor_origin.map((v) => v.toFixed(3)).join(', ')}  returns ${h.returns}`;
  }
}
