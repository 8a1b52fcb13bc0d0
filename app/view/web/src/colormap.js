// Colormaps as matplotlib draws the figures: viridis for rates and maps, and a range map for returns.
// Control points sampled from matplotlib's tables; linear in between.
const viridisStops = [
  [0.267, 0.005, 0.329], [0.283, 0.141, 0.458], [0.254, 0.265, 0.530], [0.207, 0.372, 0.553],
  [0.164, 0.471, 0.558], [0.128, 0.567, 0.551], [0.135, 0.659, 0.518], [0.267, 0.749, 0.441],
  [0.478, 0.821, 0.318], [0.741, 0.873, 0.150], [0.993, 0.906, 0.144],
];
const turboStops = [
  [0.190, 0.072, 0.232], [0.275, 0.404, 0.867], [0.155, 0.692, 0.960], [0.096, 0.900, 0.710],
  [0.469, 0.992, 0.330], [0.816, 0.914, 0.204], [0.996, 0.660, 0.183], [0.914, 0.331, 0.048], [0.480, 0.016, 0.011],
];

function lookup(stops, v, out, offset = 0) {
  const t = Math.min(1, Math.max(0, Number.isFinite(v) ? v : 0)) * (stops.length - 1);
  const i = Math.min(stops.length - 2, Math.floor(t));
  const f = t - i;
  for (let k = 0; k < 3; k++) out[offset + k] = stops[i][k] + f * (stops[i + 1][k] - stops[i][k]);
  return out;
}

export const viridis = (v, out = [0, 0, 0], offset = 0) => lookup(viridisStops, v, out, offset);
export const turbo = (v, out = [0, 0, 0], offset = 0) => lookup(turboStops, v, out, offset);

export function css(rgb) {
  return `rgb(${Math.round(rgb[0] * 255)},${Math.round(rgb[1] * 255)},${Math.round(rgb[2] * 255)})`;
}

// 256-entry tables as bytes, for drawing many pixels: table[3·i .. 3·i+2] is the color of i/255.
function table(fn) {
  const t = new Uint8ClampedArray(256 * 3), rgb = [0, 0, 0];
  for (let i = 0; i < 256; i++) {
    fn(i / 255, rgb);
    t[3 * i] = Math.round(255 * rgb[0]);
    t[3 * i + 1] = Math.round(255 * rgb[1]);
    t[3 * i + 2] = Math.round(255 * rgb[2]);
  }
  return t;
}
export const viridisTable = table(viridis);

// The table entry of v in [0, 1] (clamped; NaN → 0).
export const entry = (v) => (v > 0 ? (v < 1 ? Math.round(v * 255) : 255) : 0);
