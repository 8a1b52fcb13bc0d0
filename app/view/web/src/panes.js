// A pane shows one thing: a trial (world, trajectory, returns, BVCs, place cells, maps), a world on
// its own, or a recording (scans with their poses). Two trial panes side by side share the slider.
import { get, exportedSteps } from './api.js';
import { View3D } from './view3d.js';
import { BvcMaps, Population, BinMap, colorBar } from './panels.js';

const el = (tag, props = {}, ...children) => {
  const e = Object.assign(document.createElement(tag), props);
  e.append(...children);
  return e;
};
const fmt = (v, digits = 3) => (v === null || v === undefined || !Number.isFinite(v) ? '—' : Number(v).toFixed(digits));
const pct = (v) => (Number.isFinite(v) ? `${Math.round(100 * v)} %` : '—');
const degrees = (rad) => `${(rad * 180 / Math.PI).toFixed(1)}°`;

// What a model reads of a recorded scan, in words.
function readingWords(r) {
  if (!r) return '';
  const which = { upper_half: 'at or above the horizon', all: 'at every elevation',
    horizontal_slice: `within ±${degrees(r.slice_half_width)} of the horizontal` }[r.selection] || r.selection;
  return `points ${fmt(r.min_range, 1)}–${fmt(r.max_range, 1)} m away, ${which}`;
}

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
    this.legendText = el('div');
    this.legend.appendChild(this.legendText);
    this.viewBox.appendChild(this.legend);
    this.root.appendChild(this.viewBox);
    this.view = new View3D(this.viewBox);
    this.readout = el('div', { className: 'readout' });
    this.root.appendChild(this.readout);
  }

  // The 3-D view's legend: what the points are, and a color bar of their distance from the scanner.
  setLegend(text, maxRange) {
    this.legendText.textContent = text;
    if (!this.rangeBar) this.rangeBar = colorBar(this.legend, { label: 'distance from the scanner (m)', map: 'turbo' });
    this.rangeBar.set({ lo: 0, hi: maxRange });
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
    const m = h.metrics, rec = h.recording;
    const where = rec ? `replay of recording '${rec.name}'${rec.scans ? ` (${rec.scans} scans)` : ''}` : `world ${h.world}`;
    this.sub.textContent = `${where} · model ${h.model_name} · seed ${h.seed} · ${h.samples} samples · ${h.n_place} place cells · ` +
      `mean spatial aliasing (MSAI) ${fmt(m.msai)} · cells with several fields ${pct(m.frac_multimodal)} · ` +
      `median decoding error ${fmt(m.decode_median_m, 2)} m` +
      (Number.isFinite(m.frac_undecoded) ? ` (${pct(m.frac_undecoded)} of samples undecoded)` : '');
    this.addView();
    this.view.setTrajectory(a.x, a.y, a.z);
    this.steps = exportedSteps(this.path);
    // A replay's world is its recording's map: framed on the path and 10 m around it (far returns
    // would push the camera away).
    const around = h.recording ? this.around(a) : null;
    if (around) this.view.frame(around);
    if (h.world_problem) showError(this.root, h.world_problem);
    else {
      this.loadingWorld = get('world', { trial: this.path }).then((w) => { this.view.setWorld(w); if (around) this.view.frame(around); })
        .catch((e) => showError(this.root, e.message)).finally(() => { this.loadingWorld = null; });
    }
    if (h.model_problem) showError(this.root, h.model_problem);
    if (rec) {
      this.maxRange = rec.reading ? rec.reading.max_range : 20;
      this.setLegend(`LiDAR points of recorded scan (recording '${rec.name}'), all of the scan; large: the points the model ` +
        `read (${readingWords(rec.reading)}) near a BVC layer's elevation`, this.maxRange);
    } else if (h.drawn_sensor) {
      const d = h.drawn_sensor;
      this.maxRange = d.max_range;
      this.setLegend(`LiDAR returns of a simulated ${d.name} scanner (${d.rows} rows of beams, ${d.azimuth_count} per row); ` +
        `large: the rows the model's BVCs read`, d.max_range);
    }

    const row1 = el('div', { className: 'row' });
    const bvcTitle = rec ? 'boundary vector cells (BVCs): their rates as the replay recorded them, one disc per layer'
      : 'boundary vector cells (BVCs): how strongly each responds to the walls around, one disc per layer';
    const bvcBox = el('div', { className: 'box' }, el('h3', { textContent: bvcTitle }));
    const popBox = el('div', { className: 'box' }, el('h3', { textContent: 'place cells, one square each (click one for its map)' }));
    row1.append(bvcBox, popBox);
    const row2 = el('div', { className: 'row' });
    const cellBox = el('div', { className: 'box cell-map' });
    const saiBox = el('div', { className: 'box sai-map' });
    row2.append(cellBox, saiBox);
    this.root.append(row1, row2);
    if (h.model) this.bvcMaps = new BvcMaps(bvcBox, h.model.bvc);
    this.population = new Population(popBox, h.n_place, h.rate_max, (k) => this.pick(k));
    this.cellMap = new BinMap(cellBox, 'rate map: click a place cell above', 'mean rate in each bin');
    this.saiMap = new BinMap(saiBox, 'spatial aliasing: how alike the population looks here and elsewhere',
      'spatial aliasing index (0: unique)');
    this.prepareMaps();
    this.drawSai();
    this.loader = new StepLoader((i) => get('step', { path: this.path, i }), (s, e) => this.applyStep(s, e));
    return true;
  }

  around(a) {
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < a.x.length; i++) {
      const p = [a.x[i], a.y[i], a.z ? a.z[i] : 0];
      for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], p[k]); hi[k] = Math.max(hi[k], p[k]); }
    }
    return [[lo[0] - 10, lo[1] - 10, lo[2] - 2], [hi[0] + 10, hi[1] + 10, hi[2] + 2]];
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
    this.saiMap.info.textContent = `mean over the bins (MSAI) ${fmt(this.trial.header.metrics.msai)}; the red dot is the agent`;
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
    this.cellMap.title.textContent = `rate map of place cell ${k}: its mean rate at each place`;
    this.cellMap.draw(this.mapArgs(`cell ${k}`, this.cellValues.values, this.cellValues.top));
    const mi = a.modality ? a.modality[k] : null;
    this.cellMap.info.dataset.cell = k;
    this.cellMap.info.dataset.mi = mi;
    this.cellMap.info.textContent = `cell ${k} · fields (modality index) ${mi ?? '—'} · ` +
      `spatial information ${fmt(a.spatial_info && a.spatial_info[k])} bits · ` +
      `peak rate ${fmt(a.peak_rate && a.peak_rate[k])} · rate now ${fmt(this.population.rates && this.population.rates[k])}; ` +
      'the red dot is the agent';
  }

  // Seconds since the trial's start at sample i (as the trial file has them).
  timeAt(i) { return this.trial.arrays.t[i]; }

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
    const h = step.header, a = step.arrays, model = this.trial.header.model, rec = this.trial.header.recording;
    if (a.points.length) this.view.setReturns(a.points, a.range, a.kept, this.maxRange);
    if (this.bvcMaps) this.bvcMaps.draw(a.bvc, h.heading);
    this.population.draw(a.place);
    let top = 0, best = 0;
    a.place.forEach((v, k) => { if (v > top) { top = v; best = k; } });
    let kept = 0;
    for (const k of a.kept) kept += k;
    this.readout.dataset.sample = h.sample;
    this.readout.dataset.returns = h.returns ?? 0;
    const seen = rec
      ? `scan ${h.scan} (${h.scan_name}): ${h.points} points, of which the model read ${h.returns} ` +
        `(${readingWords(rec.reading)}); ${kept} near a BVC layer's elevation, drawn large`
      : h.returns !== undefined
        ? `${h.returns} LiDAR returns drawn, ${kept} of them in the rows the model's BVCs read (drawn large); ` +
          `the model's own scanner gets ${h.model_returns}`
        : 'no returns: the trial\'s world is not shown';
    this.readout.textContent =
      `sample ${h.sample}  t ${h.t.toFixed(3)} s since the trial's start  x ${h.x.toFixed(4)} m  y ${h.y.toFixed(4)} m  ` +
      `z ${h.z.toFixed(3)} m  heading ${h.heading.toFixed(4)} rad (${degrees(h.heading)})\n` + seen + '\n' +
      `most active place cell ${best}, rate ${top.toFixed(4)}` + (this.steps ? `  [exported step nearest to sample ${this.target}]` : '');
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
  // `trajectory`: the name of a path to draw over the world (bvc3d view WORLD --trajectory FILE), or ''.
  constructor(container, source, trajectory = '') {
    super(container, source);
    this.source = source;
    this.trajectoryName = trajectory;
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
    if (this.trajectoryName) {
      try {
        this.path = await get('trajectory');
      } catch (e) {
        this.error(`cannot open trajectory ${this.trajectoryName}: ${e.message}`);
        return false;
      }
      const a = this.path.arrays;
      this.length = this.path.header.steps;
      this.view.setTrajectory(a.x, a.y, a.z);
      this.sub.textContent += ` · trajectory ${this.trajectoryName}: ${this.length} steps over ${fmt(a.t[this.length - 1] - a.t[0], 1)} s`;
      this.steps = exportedSteps('#trajectory');
    }
    if (!w.header.probe) return true;
    const headingInput = el('input', { type: 'number', value: '0', step: '15', className: 'probe-heading', title: 'heading, degrees' });
    const bvcBox = el('div', { className: 'box' }, el('h3', { textContent: 'boundary vector cells (BVCs) at the probe: how strongly each responds to the walls around, one disc per layer' }),
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
    if (!this.path) this.loader.request(this.pose);
    return true;
  }

  // Seconds since the trajectory's first row.
  timeAt(i) {
    return this.path ? this.path.arrays.t[i] - this.path.arrays.t[0] : null;
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
      const d = h.drawn_sensor;
      this.setLegend(`LiDAR returns at the probe: model ${h.model.name}'s simulated ${d.name} scanner (${d.rows} rows of ` +
        `beams, ${d.azimuth_count} per row); large: the rows the model's BVCs read`, d.max_range);
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
    const along = h.step !== undefined ? `step ${h.step} of trajectory ${this.trajectoryName}: ` : '';
    this.readout.dataset.step = h.step !== undefined ? h.step : '';
    this.readout.textContent = `${along}probe at x ${h.x.toFixed(3)} m  y ${h.y.toFixed(3)} m  heading ${h.heading.toFixed(4)} rad ` +
      `(${degrees(h.heading)}): ${h.returns} LiDAR returns drawn, ${kept} of them in the rows the model's BVCs read ` +
      `(drawn large); the model's own scanner gets ${h.model_returns}`;
  }

  // Along the trajectory: the agent at step i, the probe there (in an export, at the nearest exported step).
  moveTo(i) {
    if (!this.path || !this.loader) return;
    i = Math.max(0, Math.min(this.length - 1, i));
    const a = this.path.arrays;
    this.view.moving();
    this.view.setAgent(a.x[i], a.y[i], a.z[i], a.heading[i]);
    this.loader.request({ step: this.steps ? nearest(this.steps, i) : i });
  }
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
    this.setLegend(`LiDAR points of each recorded scan, all of the scan; large: the points model ${h.model.name} reads ` +
      `(${readingWords(h.reading)}) near a BVC layer's elevation`, 20);
    const times = h.times.filter((t) => t !== null);
    this.t0 = times.length ? times[0] : null;
    const bvcBox = el('div', { className: 'box' }, el('h3', { textContent:
      `boundary vector cells (BVCs) of model ${h.model.name}: their rates for this scan, one disc per layer` }));
    this.root.appendChild(el('div', { className: 'row' }, bvcBox));
    this.bvcMaps = new BvcMaps(bvcBox, h.model.bvc);
    this.steps = exportedSteps('#recording');
    this.loader = new StepLoader((i) => get('scan', { i }), (s, e) => this.applyStep(s, e));
    return true;
  }

  // Seconds since the first scan (null for a recording without times).
  timeAt(i) {
    const t = this.rec.header.times[i];
    return t === null || this.t0 === null ? null : t - this.t0;
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
    far = Math.min(far, 60);
    this.view.setReturns(a.points, a.range, a.kept, far);
    this.rangeBar.set({ hi: far });
    this.bvcMaps.draw(a.bvc, this.heading_of(h.scan));
    let kept = 0;
    for (const k of a.kept) kept += k;
    this.readout.dataset.sample = h.scan;
    this.readout.dataset.returns = h.returns;
    // Times since the first scan (a recording's own times are often seconds since 1970: in the tooltip).
    const since = h.t !== undefined && this.t0 !== null ? `  t ${(h.t - this.t0).toFixed(3)} s since the first scan` : '';
    this.readout.title = h.t !== undefined ? `recorded time ${h.t} s` : '';
    this.readout.textContent = `scan ${h.scan} (${h.name})${since}  ` +
      `sensor at x ${h.sensor_origin[0].toFixed(3)} m  y ${h.sensor_origin[1].toFixed(3)} m  z ${h.sensor_origin[2].toFixed(3)} m\n` +
      `${h.points} points, of which the model reads ${h.returns}; ${kept} near a BVC layer's elevation, drawn large`;
  }
}
