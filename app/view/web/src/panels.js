// The 2-D panels of a pane, drawn on canvases: BVC activity per layer as polar heat maps
// (distance × direction), the place-cell population, a cell's rate map (hexagons as in the
// figures, or voxel slices) and the SAI map.
import { viridis, turbo, css, viridisTable, entry } from './colormap.js';

const el = (tag, props = {}, ...children) => {
  const e = Object.assign(document.createElement(tag), props);
  e.append(...children);
  return e;
};

// A number for a scale's label: no more digits than it needs.
export const tick = (v) => String(Number(Number(v).toPrecision(3)));

// A color bar: the colormap from `lo` (left) to `hi` (right) with its ends and middle labeled and
// what the color means; data-lo, data-hi and data-label say it for tests and readers of the page.
export function colorBar(container, { label, lo = 0, hi = 1, map = 'viridis' }) {
  const bar = el('div', { className: 'colorbar' });
  // A CSS gradient, not a canvas: the page's canvases are its panels.
  const fn = map === 'turbo' ? turbo : viridis, stops = [], rgb = [0, 0, 0];
  for (let k = 0; k <= 16; k++) stops.push(`${css(fn(k / 16, rgb))} ${(100 * k) / 16}%`);
  const strip = el('div', { className: 'strip' });
  strip.style.background = `linear-gradient(to right, ${stops.join(', ')})`;
  const ticks = el('div', { className: 'ticks' });
  bar.append(el('span', { className: 'label' }), strip, ticks);
  container.appendChild(bar);
  const set = (range) => {
    const a = range.lo ?? lo, b = range.hi ?? hi;
    bar.dataset.lo = a;
    bar.dataset.hi = b;
    bar.dataset.label = range.label ?? label;
    bar.querySelector('.label').textContent = `${range.label ?? label}: `;
    ticks.replaceChildren(...[a, (a + b) / 2, b].map((v) => el('span', { textContent: tick(v) })));
  };
  set({});
  bar.set = set;
  return bar;
}

// Round steps for an axis spanning `span`: 1, 2 or 5 × 10^k, about `count` of them.
export function niceStep(span, count = 5) {
  const raw = span / count, p = 10 ** Math.floor(Math.log10(raw)), f = raw / p;
  return p * (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10);
}


function canvas(w, h, cls = 'map') {
  const c = document.createElement('canvas');
  c.width = w;
  c.height = h;
  c.className = cls;
  return c;
}

// One polar map per BVC layer: direction k is the wedge around azimuth 2πk/n_dir (0 = +x to the
// right, counter-clockwise), distance d_m the ring at radius d_m (0 .. max_dist, white circles every
// 2 m); color = rate / 0.5 (the largest normalized rate). A red line shows the agent's heading.
export class BvcMaps {
  constructor(container, bvc) {
    this.bvc = bvc;
    this.el = document.createElement('div');
    this.el.className = 'bvc-maps';
    container.appendChild(this.el);
    this.canvases = [];
    for (let l = 0; l < bvc.n_layers; l++) {
      const fig = document.createElement('figure');
      const c = canvas(150, 150);
      const label = bvc.elevations.length
        ? `layer ${l + 1}: walls seen ${(bvc.elevations[l] * 180 / Math.PI).toFixed(1)}° above the horizon`
        : 'walls seen at the height of the scanner (2-D)';
      fig.append(c, Object.assign(document.createElement('figcaption'), { textContent: label }));
      this.el.appendChild(fig);
      this.canvases.push(c);
    }
    // The rings' labels (m) as drawn, for readers and tests.
    this.rings = [2, 4, 6, 8, 10, 12, 14, 16, 18, 20].filter((v) => v < bvc.max_dist);
    this.el.dataset.rings = JSON.stringify(this.rings);
    this.el.dataset.maxDist = bvc.max_dist;
    const key = el('div', { className: 'key' });
    key.textContent = `Seen from above, centered on the agent: each cell's preferred distance from the center outward ` +
      `(white rings every 2 m, labeled; the rim is ${tick(bvc.max_dist)} m), its direction as on a map (east = +x to the ` +
      `right, north = +y up); red line: the agent's heading. ${bvc.n_dir} directions × ${bvc.n_per_axis} distances ` +
      `per layer.`;
    container.appendChild(key);
    this.colorBar = colorBar(container, { label: 'BVC rate (0.5 is the most a cell fires)', lo: 0, hi: 0.5 });
  }

  // Which BVC each pixel shows, computed once: its distance picks the ring (nearest preferred
  // distance), its angle the direction (nearest preferred azimuth), as in the BVCs' own indexing
  // (l·n_dir + k)·n_per_axis + m; -1 outside the disc.
  pixelCells(size) {
    if (this.cells && this.cells.size === size) return this.cells.index;
    const { n_dir: nd, n_per_axis: nm } = this.bvc;
    const index = new Int32Array(size * size), c = size / 2, R = size / 2 - 3;
    for (let row = 0; row < size; row++) {
      for (let col = 0; col < size; col++) {
        const dx = col + 0.5 - c, dy = c - (row + 0.5), r = Math.hypot(dx, dy);
        if (r > R) { index[row * size + col] = -1; continue; }
        const m = Math.min(nm - 1, Math.round((r / R) * (nm - 1)));
        let a = Math.atan2(dy, dx);
        if (a < 0) a += 2 * Math.PI;
        const k = Math.round((a * nd) / (2 * Math.PI)) % nd;
        index[row * size + col] = k * nm + m;
      }
    }
    this.cells = { size, index };
    return index;
  }

  draw(rates, heading) {
    const { n_dir: nd, n_per_axis: nm, max_dist: maxDist } = this.bvc;
    this.canvases.forEach((c, l) => {
      const g = c.getContext('2d');
      const size = c.width, cx = size / 2, cy = size / 2, R = size / 2 - 3;
      const index = this.pixelCells(size);
      const image = g.createImageData(size, size), px = image.data;
      const ok = rates && rates.length >= (l + 1) * nd * nm, layer = l * nd * nm;
      for (let p = 0; p < index.length; p++) {
        const o = 4 * p, cell = index[p];
        if (cell < 0) { px[o] = px[o + 1] = px[o + 2] = 255; px[o + 3] = 255; continue; }
        const e = 3 * entry(ok ? rates[layer + cell] / 0.5 : 0);
        px[o] = viridisTable[e]; px[o + 1] = viridisTable[e + 1]; px[o + 2] = viridisTable[e + 2]; px[o + 3] = 255;
      }
      g.putImageData(image, 0, 0);
      g.strokeStyle = 'rgba(255,255,255,0.5)';
      g.lineWidth = 1;
      g.font = '9px "DejaVu Sans", sans-serif';
      g.textAlign = 'center';
      for (const d of this.rings) {
        g.beginPath();
        g.arc(cx, cy, (d / maxDist) * R, 0, 2 * Math.PI);
        g.stroke();
      }
      // Every other ring labeled along the south-east diagonal, and the rim.
      g.fillStyle = 'rgba(255,255,255,0.9)';
      for (const d of [...this.rings.filter((v, k) => k % 2 === 1), maxDist]) {
        const r = (d / maxDist) * R - (d === maxDist ? 6 : 0), a = -Math.PI / 4;
        g.fillText(`${tick(d)} m`, cx + r * Math.cos(a), cy - r * Math.sin(a) + 3);
      }
      if (Number.isFinite(heading)) {
        g.strokeStyle = '#c0392b';
        g.lineWidth = 2;
        g.beginPath();
        g.moveTo(cx, cy);
        g.lineTo(cx + R * Math.cos(heading), cy - R * Math.sin(heading));
        g.stroke();
      }
    });
  }
}

// The population: one square per place cell, color = rate / the trial's largest rate. Click picks a cell.
export class Population {
  constructor(container, nPlace, rateMax, onPick) {
    this.n = nPlace;
    this.rateMax = rateMax > 0 ? rateMax : 1;
    this.cols = Math.ceil(Math.sqrt(nPlace * 2.5));
    this.rows = Math.ceil(nPlace / this.cols);
    this.size = Math.max(6, Math.min(16, Math.floor(380 / this.cols)));
    this.canvas = canvas(this.cols * this.size, this.rows * this.size, 'map population');
    container.appendChild(this.canvas);
    this.colorBar = colorBar(container, { label: 'place-cell rate (the largest in the trial is the top)', lo: 0, hi: this.rateMax });
    this.selected = -1;
    this.canvas.addEventListener('click', (e) => {
      const r = this.canvas.getBoundingClientRect();
      const col = Math.floor((e.clientX - r.left) / this.size), row = Math.floor((e.clientY - r.top) / this.size);
      const cell = row * this.cols + col;
      if (col >= 0 && col < this.cols && cell >= 0 && cell < this.n) onPick(cell);
    });
  }

  // Where cell i is drawn (for tests and tooltips): the center of its square, in canvas pixels.
  cellCenter(i) {
    return [(i % this.cols + 0.5) * this.size, (Math.floor(i / this.cols) + 0.5) * this.size];
  }

  draw(rates) {
    this.rates = rates;
    const g = this.canvas.getContext('2d'), s = this.size, rgb = [0, 0, 0];
    g.fillStyle = '#fff';
    g.fillRect(0, 0, this.canvas.width, this.canvas.height);
    for (let i = 0; i < this.n; i++) {
      g.fillStyle = css(viridis(rates ? rates[i] / this.rateMax : 0, rgb));
      g.fillRect((i % this.cols) * s, Math.floor(i / this.cols) * s, s - 1, s - 1);
    }
    if (this.selected >= 0) {
      g.strokeStyle = '#c0392b';
      g.lineWidth = 2;
      g.strokeRect((this.selected % this.cols) * s + 1, Math.floor(this.selected / this.cols) * s + 1, s - 3, s - 3);
    }
  }
}

// A map over the trial's bins. Hexagons: matplotlib's hexbin polygon, sx wide with vertices at
// ±sy/3 (pointy top). Voxels: the slice at one height, squares of the grid step.
export class BinMap {
  constructor(container, title, scale) {
    this.title = Object.assign(document.createElement('h3'), { textContent: title });
    this.canvas = canvas(380, 300);
    this.base = canvas(380, 300);
    this.key = null;
    this.info = Object.assign(document.createElement('div'), { className: 'cell-info' });
    container.append(this.title, this.canvas);
    this.colorBar = colorBar(container, { label: scale, lo: 0, hi: 1 });
    container.append(this.info);
  }

  // centers: B × D; values: B (NaN: no value); bounds: [x0, x1, y0, y1]. The map is drawn again
  // only when `key` changes; each call draws the marker (the agent) on it.
  draw({ key, centers, dims, values, grid, bounds, marker, vmax, slice }) {
    const c = this.canvas, g = c.getContext('2d');
    if (key !== this.key) {
      this.key = key;
      this.paint({ centers, dims, values, grid, bounds, vmax, slice });
    }
    g.drawImage(this.base, 0, 0);
    if (marker && values) {
      const [px, py] = this.project(marker[0], marker[1]);
      g.fillStyle = '#c0392b';
      g.beginPath();
      g.arc(px, py, 4, 0, 2 * Math.PI);
      g.fill();
    }
  }

  paint({ centers, dims, values, grid, bounds, vmax, slice }) {
    const c = this.base, g = c.getContext('2d'), rgb = [0, 0, 0];
    g.fillStyle = '#fff';
    g.fillRect(0, 0, c.width, c.height);
    if (!centers || !values) return;
    // Room on the left and below for the axes (metres).
    const [x0, x1, y0, y1] = bounds, pad = 8, left = 40, bottom = 30;
    const scale = Math.min((c.width - left - pad) / (x1 - x0), (c.height - bottom - pad) / (y1 - y0));
    const ox = left + (c.width - left - pad - scale * (x1 - x0)) / 2;
    const oy = bottom + (c.height - bottom - pad - scale * (y1 - y0)) / 2;
    const px = (x) => ox + (x - x0) * scale, py = (y) => c.height - oy - (y - y0) * scale;
    this.project = (x, y) => [px(x), py(y)];
    const top = vmax > 0 ? vmax : 1;
    this.colorBar.set({ lo: 0, hi: top });
    this.axes(g, { x0, x1, y0, y1, px, py, left: ox, bottom: c.height - oy });
    const B = values.length;
    const hex = grid && grid.kind === 'hex' ? [[0.5, -0.5], [0.5, 0.5], [0, 1], [-0.5, 0.5], [-0.5, -0.5], [0, -1]]
      .map(([a, b]) => [a * grid.sx, (b * grid.sy) / 3]) : null;
    const voxel = dims === 3 ? (grid && grid.step) || 0.25 : 0;
    for (let b = 0; b < B; b++) {
      const v = values[b];
      if (!Number.isFinite(v)) continue;
      const x = centers[b * dims], y = centers[b * dims + 1];
      if (dims === 3 && Math.abs(centers[b * dims + 2] - slice) > 1e-6) continue;
      g.fillStyle = css(viridis(v / top, rgb));
      if (hex) {
        g.beginPath();
        hex.forEach(([dx, dy], k) => (k ? g.lineTo(px(x + dx), py(y + dy)) : g.moveTo(px(x + dx), py(y + dy))));
        g.closePath();
        g.fill();
      } else {
        const s = Math.max(2, voxel * scale);
        g.fillRect(px(x) - s / 2, py(y) - s / 2, s, s);
      }
    }
  }

  // Axes in metres below and left of the map, ticks at round values; the ticks drawn (value and
  // pixel) are kept in data-axes for readers and tests.
  axes(g, { x0, x1, y0, y1, px, py, left, bottom }) {
    const step = niceStep(Math.max(x1 - x0, y1 - y0));
    const ticks = (lo, hi) => {
      const out = [];
      for (let v = Math.ceil(lo / step) * step; v <= hi + 1e-9; v += step) out.push(Math.round(v / step) * step);
      return out;
    };
    const drawn = { unit: 'm', x: [], y: [] };
    g.strokeStyle = '#555';
    g.fillStyle = '#333';
    g.lineWidth = 1;
    g.font = '10px "DejaVu Sans", sans-serif';
    g.beginPath();
    g.moveTo(px(x0), bottom + 3); g.lineTo(px(x1), bottom + 3);
    g.moveTo(left - 3, py(y0)); g.lineTo(left - 3, py(y1));
    g.stroke();
    g.textAlign = 'center';
    for (const v of ticks(x0, x1)) {
      g.beginPath(); g.moveTo(px(v), bottom + 3); g.lineTo(px(v), bottom + 7); g.stroke();
      g.fillText(tick(v), px(v), bottom + 17);
      drawn.x.push([v, px(v)]);
    }
    g.textAlign = 'right';
    for (const v of ticks(y0, y1)) {
      g.beginPath(); g.moveTo(left - 3, py(v)); g.lineTo(left - 7, py(v)); g.stroke();
      g.fillText(tick(v), left - 9, py(v) + 3);
      drawn.y.push([v, py(v)]);
    }
    g.textAlign = 'left';
    g.fillText('x (m)', px(x1) - 28, bottom + 27);
    g.save();
    g.translate(10, py(y1) + 30);
    g.rotate(-Math.PI / 2);
    g.fillText('y (m)', 0, 0);
    g.restore();
    this.canvas.dataset.axes = JSON.stringify(drawn);
  }
}
