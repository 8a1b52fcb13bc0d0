// End-to-end tests of `bvc3d view` in headless Chromium: a short trial made here is opened, the
// page's numbers are checked against the trial file read with h5py, the returns against
// `bvc3d scan`, the BVC rates against the rates the trial recorded; a world YAML with a mesh, a
// recording, two trials side by side and the static export are opened too. Screenshots are kept
// in the folder printed at the start (test artifacts).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { writeFileSync, copyFileSync, existsSync, readFileSync, mkdirSync } from 'node:fs';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';
import { execFileSync } from 'node:child_process';
import { artifacts, scratch, run, h5, serve, launch, openPage, waitReady, paintedPixels, source, python } from './helpers.mjs';

let dir, server, browser;

before(async () => {
  console.log(`# screenshots: ${artifacts}`);
  dir = scratch('viewer');
  run(['run', '--tilt', '45', '--hours', '0.05', '--record-bvc', '--out', join(dir, 't45.h5')]);
  run(['run', '--tilt', '45', '--model', '2d', '--hours', '0.05', '--out', join(dir, 't45-2d.h5')]);
  server = await serve([dir]);
  browser = await launch();
});

after(async () => {
  if (browser) await browser.close();
  if (server) assert.equal(await server.stop(), 0);
});

async function shot(page, name, fullPage = true) {
  const file = join(artifacts, `${name}.png`);
  await page.screenshot({ path: file, fullPage });
  return file;
}

// The numbers of the step the page shows.
const shownStep = (page, pane = 0) => page.evaluate((p) => {
  const s = window.bvc3dViewer.panes[p].step;
  return { header: s.header, place: s.arrays.place ? Array.from(s.arrays.place) : [], bvc: Array.from(s.arrays.bvc),
    firstPoints: Array.from(s.arrays.points.subarray(0, 30)), returns: s.arrays.range.length,
    readout: window.bvc3dViewer.panes[p].readout.textContent };
}, pane);

async function moveSlider(page, i) {
  await page.locator('#slider').fill(String(i));
  await page.waitForFunction((k) => window.bvc3dViewer.panes.every((p) => p.readout.dataset.sample === String(k)) &&
    window.bvc3dViewer.idle(), i);
}

function sensorYaml() {
  const file = join(dir, 'spherical-all.yaml');
  writeFileSync(file, 'preset: spherical\nkeep_rows: all\n');
  return file;
}

test('a trial opens: the 3-D view is drawn and the step numbers are the file\'s', async () => {
  const page = await openPage(browser, `${server.url}?a=t45.h5`);
  await waitReady(page);
  const pixels = await paintedPixels(page, '.view3d canvas');
  const area = await page.$eval('.view3d canvas', (c) => c.width * c.height);
  assert.ok(pixels > 0.05 * area, `the 3-D view is nearly blank: ${pixels} of ${area} pixels drawn`);
  const file = join(dir, 't45.h5');
  const want = h5(file, '{k: float(f["samples/" + k][0]) for k in ["t", "x", "y", "heading"]}');
  const step = await shownStep(page);
  for (const k of ['t', 'x', 'y', 'heading']) assert.equal(step.header[k], want[k], `${k} of sample 0`);
  assert.match(step.readout, new RegExp(`x ${want.x.toFixed(4)} m\\s+y ${want.y.toFixed(4)} m`));
  assert.deepEqual(page.foreignRequests, [], 'the page asked for something elsewhere');
  assert.deepEqual(page.consoleErrors, []);
  await shot(page, 'trial');
  await page.close();
});

test('moving the slider changes the returns and the numbers, which match the file and bvc3d scan', async () => {
  const page = await openPage(browser, `${server.url}?a=t45.h5`);
  await waitReady(page);
  const before0 = await shownStep(page);
  const canvasImage = () => page.$eval('.view3d canvas', (c) => {
    window.bvc3dViewer.panes[0].view.settle();
    window.bvc3dViewer.panes[0].view.render(true);
    return c.toDataURL();
  });
  const canvasBefore = await canvasImage();
  const n = h5(join(dir, 't45.h5'), 'int(f["samples/x"].shape[0])');
  const i = Math.floor((2 * n) / 3);
  await moveSlider(page, i);
  const step = await shownStep(page);
  const file = join(dir, 't45.h5');
  const want = h5(file, `{"t": float(f["samples/t"][${i}]), "x": float(f["samples/x"][${i}]), "y": float(f["samples/y"][${i}]), ` +
    `"heading": float(f["samples/heading"][${i}]), "rates": f["samples/rates"][${i}].astype(float).tolist(), ` +
    `"bvc": f["samples/bvc_rates"][${i}].astype(float).tolist()}`);
  for (const k of ['t', 'x', 'y', 'heading']) assert.equal(step.header[k], want[k], `${k} of sample ${i}`);
  assert.deepEqual(step.place, want.rates, 'place-cell rates are the recorded ones');
  const bvcError = Math.max(...step.bvc.map((v, k) => Math.abs(v - want.bvc[k])));
  assert.ok(bvcError < 1e-6, `BVC rates differ from the recorded ones by ${bvcError}`);
  assert.notDeepEqual(step.firstPoints, before0.firstPoints, 'the returns did not change');
  const canvasAfter = await canvasImage();
  assert.notEqual(canvasAfter, canvasBefore, 'the 3-D view did not change');
  // The returns drawn are the full spherical scan at that pose: as many as `bvc3d scan` gives.
  const csv = run(['scan', '--world', 'cross', '--tilt', '45', '--sensor', sensorYaml(), '--pose', `${want.x},${want.y},${want.heading}`]);
  assert.equal(step.returns, csv.trim().split('\n').length - 1, 'returns differ from bvc3d scan');
  assert.match(step.readout, new RegExp(`${step.returns} LiDAR returns drawn`));
  await shot(page, 'trial-scrubbed');
  await page.close();
});

test('clicking a place cell shows its rate map and MI', async () => {
  const file = join(dir, 't45.h5');
  const modality = h5(file, 'f["metrics/modality"][:].tolist()');
  const cell = Math.max(0, modality.findIndex((m) => m > 0));
  const page = await openPage(browser, `${server.url}?a=t45.h5`);
  await waitReady(page);
  const blank = await paintedPixels(page, '.cell-map canvas');
  const [cx, cy] = await page.evaluate((k) => window.bvc3dViewer.panes[0].population.cellCenter(k), cell);
  await page.locator('canvas.population').click({ position: { x: cx, y: cy } });
  await page.waitForFunction((k) => document.querySelector('.cell-map .cell-info').dataset.cell === String(k), cell);
  const info = await page.$eval('.cell-map .cell-info', (e) => ({ mi: e.dataset.mi, text: e.textContent }));
  assert.equal(Number(info.mi), modality[cell]);
  assert.match(info.text, new RegExp(`cell ${cell} · fields \\(modality index\\) ${modality[cell]}`));
  const painted = await paintedPixels(page, '.cell-map canvas');
  assert.ok(painted > blank + 50, `the rate map is not drawn (${painted} pixels)`);
  assert.ok((await paintedPixels(page, '.sai-map canvas')) > 50, 'the SAI map is not drawn');
  await shot(page, 'cell');
  await page.close();
});

test('two trials side by side follow one slider', async () => {
  const page = await openPage(browser, `${server.url}?a=t45.h5&b=t45-2d.h5&cell=0`);
  await waitReady(page);
  assert.equal(await page.locator('.pane').count(), 2);
  await moveSlider(page, 123);
  const a = await shownStep(page, 0), b = await shownStep(page, 1);
  assert.equal(a.header.sample, 123);
  assert.equal(b.header.sample, 123);
  // Same seed, same world: the walks are the same; the 2-D model's scanner is the horizontal one.
  assert.equal(a.header.x, b.header.x);
  assert.ok(b.returns <= 720 && a.returns > 720);
  for (const canvas of await page.locator('.view3d canvas').all()) {
    const n = await canvas.evaluate((c) => c.width * c.height);
    assert.ok(n > 0);
  }
  await shot(page, 'side-by-side');
  await page.close();
});

// A trial binned in 3-D (as flying agents' trials will be): the trial made above with heights and a
// voxel lattice written into it by h5py. The rate map shows one slice of voxels at a time.
test('voxel slices for trials binned in 3-D', async () => {
  const code = `import h5py, numpy as np, shutil
shutil.copy(${JSON.stringify(join(dir, 't45.h5'))}, ${JSON.stringify(join(dir, 'flying.h5'))})
with h5py.File(${JSON.stringify(join(dir, 'flying.h5'))}, 'r+') as f:
    n = f['samples/x'].shape[0]
    f['samples'].create_dataset('z', data=np.linspace(0.5, 1.5, n))
    g = f['metrics']
    xs = np.arange(-4.5, 5, 1.0)
    centers = np.array([[x, y, z] for z in (0.5, 1.0, 1.5) for y in xs for x in xs])
    maps = np.zeros((len(centers), 250), np.float32)
    maps[:, 0] = (centers[:, 2] == 1.0) * np.exp(-(centers[:, 0] ** 2 + centers[:, 1] ** 2) / 4)
    for k in ('bin_centers', 'rate_maps', 'sai', 'bin_counts'):
        del g[k]
    g['bin_centers'], g['rate_maps'] = centers, maps
    g['sai'], g['bin_counts'] = np.linspace(0, 1, len(centers)), np.ones(len(centers), np.int64)
`;
  execFileSync(python, ['-c', code]);
  const page = await openPage(browser, `${server.url}?a=flying.h5&cell=0`);
  await waitReady(page);
  const slices = await page.$$eval('.cell-map select.slice option', (o) => o.map((e) => Number(e.value)));
  assert.deepEqual(slices, [0.5, 1, 1.5]);
  const image = () => page.$eval('.cell-map canvas', (c) => c.toDataURL());
  await page.selectOption('.cell-map select.slice', '1');
  const middle = await image();
  assert.ok((await paintedPixels(page, '.cell-map canvas')) > 5000, 'no voxels drawn');
  await page.selectOption('.cell-map select.slice', '0.5');
  assert.notEqual(await image(), middle, 'the slices look the same');
  const z = await page.evaluate(() => window.bvc3dViewer.panes[0].step.header.z);
  assert.equal(z, 0.5);
  await shot(page, 'voxels');
  await page.close();
});

test('a world YAML with a mesh renders, and a click probes the floor', async () => {
  const yaml = join(source, 'configs', 'worlds', 'two-rooms.yaml');
  const world = await serve([yaml]);
  try {
    const page = await openPage(browser, world.url);
    await waitReady(page);
    const pixels = await paintedPixels(page, '.view3d canvas');
    assert.ok(pixels > 20000, `the world is not drawn (${pixels} pixels)`);
    // 54 triangles from two_rooms.obj, 5 boxes of 12, one tilted wall of 12.
    assert.equal(await page.$eval('.readout', (e) => Number(e.dataset.triangles)), 54 + 5 * 12 + 12);
    // The probe: the default model (3d-0.2) at the world's first start point; as many returns as
    // `bvc3d scan` gives there with all 90 rows of the spherical scanner.
    const count = async () => {
      const s = await shownStep(page);
      const csv = run(['scan', '--world', yaml, '--sensor', sensorYaml(), '--pose', `${s.header.x},${s.header.y},${s.header.heading}`]);
      assert.equal(s.returns, csv.trim().split('\n').length - 1, `returns at ${s.header.x}, ${s.header.y}`);
      return s;
    };
    const first = await count();
    assert.ok(first.returns > 10000);
    assert.ok((await paintedPixels(page, '.bvc-maps canvas')) > 5000, 'no BVC map');
    const box = await page.locator('.view3d canvas').boundingBox();
    await page.mouse.click(box.x + box.width * 0.6, box.y + box.height * 0.55);
    await page.waitForFunction((x) => window.bvc3dViewer.panes[0].readout.dataset.x !== String(x) && window.bvc3dViewer.idle(), first.header.x);
    const second = await count();
    assert.notDeepEqual([second.header.x, second.header.y], [first.header.x, first.header.y]);
    assert.deepEqual(page.foreignRequests, []);
    assert.deepEqual(page.consoleErrors, []);
    await shot(page, 'world-two-rooms');
    await page.close();
  } finally {
    assert.equal(await world.stop(), 0);
  }
});

test('a Gazebo world (.world) renders with all its triangles', async () => {
  // A room of SDF boxes: a floor slab, four walls and a pillar, each a box of 12 triangles.
  const dir = scratch('gazebo');
  mkdirSync(join(dir, 'worlds'));
  const box = (name, [x, y, z], [sx, sy, sz]) =>
    `<model name="${name}"><static>true</static><pose>${x} ${y} ${z} 0 0 0.3</pose><link name="l"><visual name="v">` +
    `<geometry><box><size>${sx} ${sy} ${sz}</size></box></geometry></visual></link></model>`;
  const boxes = [box('floor', [0, 0, -0.1], [8, 8, 0.2]), box('n', [0, 4.05, 1], [8.2, 0.1, 2]), box('s', [0, -4.05, 1], [8.2, 0.1, 2]),
    box('e', [4.05, 0, 1], [0.1, 8, 2]), box('w', [-4.05, 0, 1], [0.1, 8, 2]), box('pillar', [1, 1, 1], [0.5, 0.5, 2])];
  const file = join(dir, 'worlds', 'room.world');
  writeFileSync(file, `<?xml version="1.0"?>\n<sdf version="1.6"><world name="w">${boxes.join('\n')}</world></sdf>\n`);
  const world = await serve([file]);
  try {
    const page = await openPage(browser, world.url);
    await waitReady(page);
    assert.ok((await paintedPixels(page, '.view3d canvas')) > 20000, 'the world is not drawn');
    assert.equal(await page.$eval('.readout', (e) => Number(e.dataset.triangles)), boxes.length * 12);
    assert.ok((await shownStep(page)).returns > 1000);
    assert.deepEqual(page.consoleErrors, []);
    await shot(page, 'world-gazebo');
    await page.close();
  } finally {
    assert.equal(await world.stop(), 0);
  }
});

// A recording made here: three ASCII PCD scans of points on a 4 m square at sensor height, and
// KITTI poses that move the sensor along x.
function makeRecording() {
  const rec = scratch('recording');
  const poses = [];
  for (let s = 0; s < 3; s++) {
    const pts = [];
    for (let k = 0; k < 200 + 50 * s; k++) {
      const a = (2 * Math.PI * k) / (200 + 50 * s);
      pts.push(`${(4 * Math.cos(a)).toFixed(4)} ${(4 * Math.sin(a)).toFixed(4)} ${(0.5 * Math.sin(3 * a)).toFixed(4)}`);
    }
    writeFileSync(join(rec, `${s}.pcd`), `# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n` +
      `WIDTH ${pts.length}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS ${pts.length}\nDATA ascii\n${pts.join('\n')}\n`);
    poses.push(`1 0 0 ${s} 0 1 0 0 0 0 1 1`);
  }
  writeFileSync(join(rec, 'poses.txt'), poses.join('\n') + '\n');
  return rec;
}

test('a recording: scans step with the slider, in the world frame', async () => {
  const rec = makeRecording();
  const srv = await serve(['--scans', rec, '--poses', join(rec, 'poses.txt')]);
  try {
    const page = await openPage(browser, srv.url);
    await waitReady(page);
    let s = await shownStep(page);
    assert.equal(s.returns, 200);
    await moveSlider(page, 2);
    s = await shownStep(page);
    assert.equal(s.returns, 300);
    assert.deepEqual(s.header.sensor_origin, [2, 0, 1]);
    // The first point, (4, 0, 0) in the sensor frame, lies at (6, 0, 1) in the world.
    assert.deepEqual(s.firstPoints.slice(0, 3), [6, 0, 1]);
    // The returns are drawn: hiding them takes pixels away (seen from close by).
    await page.evaluate(() => window.bvc3dViewer.panes[0].view.frame([[-3, -5, 0], [7, 5, 2]]));
    const painted = await paintedPixels(page, '.view3d canvas');
    await page.evaluate(() => window.bvc3dViewer.panes[0].view.returns.forEach((r) => { r.points.visible = false; }));
    const without = await paintedPixels(page, '.view3d canvas');
    assert.ok(painted > without + 100, `${painted} pixels drawn, ${without} without the returns`);
    await page.evaluate(() => window.bvc3dViewer.panes[0].view.returns.forEach((r) => { r.points.visible = true; }));
    await shot(page, 'recording');
    await page.close();
  } finally {
    await srv.stop();
  }
});

// Issue 32, finding 4: a trial file of `bvc3d replay` shows the recording it replayed (not a world
// it never had), the points the model read, and the BVC rates the replay recorded.
test('a replay\'s trial file shows its recording and its recorded rates', async () => {
  run(['export-scans', '--world', 'cross', '--tilt', '45', '--hours', '0.004', '--seed', '5', '--format', 'pcd', '--out', 'walk'], { cwd: dir });
  run(['replay', '--scans', 'walk', '--poses', 'walk/poses.txt', '--model', '3d-0.2', '--out', 'replay.h5'], { cwd: dir });
  const page = await openPage(browser, `${server.url}?a=replay.h5`);
  await waitReady(page);
  assert.deepEqual(await page.$$eval('.pane .error', (e) => e.map((x) => x.textContent)), [], 'the page shows errors');
  const legend = await page.$eval('.legend', (e) => e.textContent);
  assert.match(legend, /recorded scan \(recording 'walk'\)/);
  assert.doesNotMatch(legend, /spherical|90 rows/, 'a recording described as a simulated scanner');
  const map = await page.evaluate(() => window.bvc3dViewer.panes[0].view.world.children
    .filter((c) => c.isPoints).reduce((n, c) => n + c.geometry.attributes.position.count, 0));
  assert.ok(map > 1000, `the recording's map has ${map} points`);
  const file = join(dir, 'replay.h5');
  const n = h5(file, 'int(f["samples/x"].shape[0])');
  for (const i of [0, n - 1]) {
    await moveSlider(page, i);
    const step = await shownStep(page);
    const want = h5(file, `f["samples/bvc_rates"][${i}].astype(float).tolist()`);
    assert.deepEqual(step.bvc, want, `sample ${i}: the BVC maps do not show the recorded rates`);
    assert.ok(step.bvc.some((v) => v > 0), 'the BVC rates are all zero');
    const header = readFileSync(join(dir, 'walk', `${String(i).padStart(6, '0')}.pcd`)).subarray(0, 400).toString('latin1');
    assert.equal(step.returns, Number(header.match(/POINTS (\d+)/)[1]), `sample ${i}: not every point of its scan drawn`);
    assert.match(step.readout, new RegExp(`scan ${i} \\(${String(i).padStart(6, '0')}\\.pcd\\)`));
  }
  const painted = await paintedPixels(page, '.bvc-maps canvas');
  assert.ok(painted > 5000, 'the BVC maps are empty');
  assert.deepEqual(page.consoleErrors, []);
  await shot(page, 'replay');
  await page.close();
});

// Issue 32, finding 10: every panel can be read without the docs: the BVC maps' distance rings
// are labeled and their colors have a scale, the place cells a color bar, the maps axes in metres
// (checked: the agent's dot sits where the axes say its position is), times since the start, and
// no jargon.
test('every panel says what it shows: scales, axes in metres, times since the start', async () => {
  const file = join(dir, 't45.h5');
  const n = h5(file, 'int(f["samples/x"].shape[0])');
  const i = Math.floor(n / 2);
  const page = await openPage(browser, `${server.url}?a=t45.h5&i=${i}&cell=0`);
  await waitReady(page);
  const bvc = await page.$eval('.bvc-maps', (e) => ({ rings: JSON.parse(e.dataset.rings), maxDist: Number(e.dataset.maxDist),
    key: e.parentElement.querySelector('.key').textContent, bar: { ...e.parentElement.querySelector('.colorbar').dataset } }));
  assert.deepEqual(bvc.rings, [2, 4, 6, 8, 10]);
  assert.equal(bvc.maxDist, 12);
  assert.match(bvc.key, /rings every 2 m.*the rim is 12 m/);
  assert.equal(Number(bvc.bar.lo), 0);
  assert.equal(Number(bvc.bar.hi), 0.5);
  const bars = await page.$$eval('.colorbar', (b) => b.map((e) => ({ ...e.dataset, ticks: e.querySelector('.ticks').textContent })));
  const rateMax = h5(file, 'float(f["samples/rates"][:].max())');
  const population = bars.find((b) => /place-cell rate/.test(b.label));
  assert.ok(population, 'no color bar for the place cells');
  assert.ok(Math.abs(Number(population.hi) - rateMax) < 1e-6 * rateMax, `${population.hi} vs ${rateMax}`);
  const saiMax = h5(file, 'float(np.nanmax(f["metrics/sai"][:]))');
  const sai = bars.find((b) => /spatial aliasing index/.test(b.label));
  assert.ok(sai && Math.abs(Number(sai.hi) - saiMax) < 1e-6, `SAI color bar ${sai && sai.hi} vs ${saiMax}`);
  assert.ok(bars.some((b) => /distance from the scanner/.test(b.label) && Number(b.hi) === 20), 'no color bar for the returns');
  // The maps' axes: metres, and the agent's red dot where the axes put the sample's x and y.
  const at = h5(file, `[float(f["samples/x"][${i}]), float(f["samples/y"][${i}])]`);
  for (const selector of ['.cell-map canvas', '.sai-map canvas']) {
    const found = await page.$eval(selector, (c) => {
      const axes = JSON.parse(c.dataset.axes), d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      let sx = 0, sy = 0, k = 0;
      for (let p = 0; p < d.length; p += 4) {
        if (d[p] === 192 && d[p + 1] === 57 && d[p + 2] === 43) { sx += (p / 4) % c.width; sy += Math.floor(p / 4 / c.width); k++; }
      }
      return { axes, dot: [sx / k + 0.5, sy / k + 0.5], k };
    });
    assert.equal(found.axes.unit, 'm');
    assert.ok(found.axes.x.length >= 2 && found.axes.y.length >= 2, `${selector}: too few ticks`);
    assert.ok(found.k > 10, `${selector}: no red dot`);
    const metres = (ticks, pixel) => {
      const [[v0, p0], [v1, p1]] = [ticks[0], ticks[ticks.length - 1]];
      return v0 + ((pixel - p0) * (v1 - v0)) / (p1 - p0);
    };
    const x = metres(found.axes.x, found.dot[0]), y = metres(found.axes.y, found.dot[1]);
    assert.ok(Math.hypot(x - at[0], y - at[1]) < 0.15, `${selector}: the dot reads (${x}, ${y}), the agent is at ${at}`);
  }
  const readout = await page.$eval('.readout', (e) => e.textContent);
  assert.match(readout, /s since the trial's start/);
  const text = await page.$eval('.pane', (e) => e.textContent);
  for (const jargon of [/rows the model keeps/, /MI \(modality\)/, /\bMSAI \d/, /BVC activity per layer/]) {
    assert.doesNotMatch(text, jargon);
  }
  await shot(page, 'readable');
  await page.close();
});

test('a recording\'s times are shown since its first scan, not as recorded (seconds since 1970)', async () => {
  const rec = makeRecording();
  writeFileSync(join(rec, 'scans.txt'), [0, 1, 2].map((s) => `${s}.pcd ${1700000000 + 0.5 * s}`).join('\n') + '\n');
  const srv = await serve(['--scans', join(rec, 'scans.txt'), '--poses', join(rec, 'poses.txt')]);
  try {
    const page = await openPage(browser, srv.url);
    await waitReady(page);
    await moveSlider(page, 2);
    const readout = await page.$eval('.readout', (e) => e.textContent);
    assert.match(readout, /t 1\.000 s since the first scan/);
    assert.doesNotMatch(readout, /1700000/);
    assert.equal(await page.$eval('#slider-label', (e) => e.textContent), 'sample 2 / 2 · 1.0 s');
    await page.close();
  } finally {
    await srv.stop();
  }
});

test('the real recording (hall-lidar), when present: map and scans', async (t) => {
  const hall = join(source, '..', 'shared', 'data', 'hall-lidar');
  if (!existsSync(join(hall, 'poses.csv'))) return t.skip(`no recording at ${hall}`);
  const srv = await serve(['--scans', hall, '--poses', join(hall, 'poses.csv')]);
  try {
    const page = await openPage(browser, srv.url);
    await waitReady(page);
    await moveSlider(page, 10);
    const s = await shownStep(page);
    // Every point of the scan is drawn: as many as its PCD header counts, less non-finite ones.
    const header = readFileSync(join(hall, '0010.pcd')).subarray(0, 400).toString('latin1');
    const points = Number(header.match(/POINTS (\d+)/)[1]);
    assert.equal(s.returns + s.header.dropped_nonfinite, points);
    const map = await page.evaluate(() => window.bvc3dViewer.panes[0].view.world.children
      .filter((c) => c.isPoints).reduce((n, c) => n + c.geometry.attributes.position.count, 0));
    assert.ok(map > 100000, `map of ${map} points`);
    assert.ok((await paintedPixels(page, '.view3d canvas')) > 20000);
    await shot(page, 'recording-hall');
    await page.close();
  } finally {
    await srv.stop();
  }
});

test('the exported page opens from disk and shows the same data', async () => {
  const out = join(scratch('export'), 'page');
  const printed = run(['view', '--export', out, '--export-steps', '5', join(dir, 't45.h5')]);
  assert.match(printed, /5 steps/);
  const page = await openPage(browser, pathToFileURL(join(out, 'index.html')).href);
  await waitReady(page);
  assert.ok((await paintedPixels(page, '.view3d canvas')) > 20000);
  const n = h5(join(dir, 't45.h5'), 'int(f["samples/x"].shape[0])');
  // Exported steps are evenly spaced; the slider shows the nearest one.
  const last = n - 1;
  await page.locator('#slider').fill(String(last));
  await page.waitForFunction((k) => window.bvc3dViewer.panes[0].readout.dataset.sample === String(k), last);
  const step = await shownStep(page);
  const want = h5(join(dir, 't45.h5'), `float(f["samples/x"][${last}])`);
  assert.equal(step.header.x, want);
  assert.deepEqual(page.foreignRequests, []);
  assert.deepEqual(page.consoleErrors, []);
  await shot(page, 'export');
  await page.close();
  // A world exports with its probe at the proposed pose.
  const worldOut = join(scratch('export-world'), 'page');
  run(['view', '--export', worldOut, join(source, 'configs', 'worlds', 'two-rooms.yaml')]);
  const worldPage = await openPage(browser, pathToFileURL(join(worldOut, 'index.html')).href);
  await waitReady(worldPage);
  assert.ok((await shownStep(worldPage)).returns > 10000);
  assert.deepEqual(worldPage.consoleErrors, []);
  await worldPage.close();
});

// docs/figures/viewer.png: the 2-D model beside the 3-D three-layer one at 60°, half an hour each,
// with the most informative cell of the first picked.
test('README screenshot', { skip: !process.env.BVC3D_UPDATE_FIGURES && 'set BVC3D_UPDATE_FIGURES=1 to update docs/figures/viewer.png' }, async () => {
  const readme = scratch('readme');
  run(['run', '--tilt', '60', '--model', '3d-3l', '--hours', '0.5', '--out', join(readme, 'cross-60_3d-3l.h5')]);
  run(['run', '--tilt', '60', '--model', '2d', '--hours', '0.5', '--out', join(readme, 'cross-60_2d.h5')]);
  const cell = h5(join(readme, 'cross-60_3d-3l.h5'), 'int(np.nanargmax(f["metrics/spatial_info"][:]))');
  const srv = await serve([readme]);
  try {
    const page = await openPage(browser, `${srv.url}?a=cross-60_3d-3l.h5&b=cross-60_2d.h5&i=2000&cell=${cell}`,
      { width: 1600, height: 1320 });
    await waitReady(page);
    await page.evaluate(() => window.bvc3dViewer.panes.forEach((p) => { p.view.settle(); p.view.render(true); }));
    copyFileSync(await shot(page, 'readme', false), join(source, 'docs', 'figures', 'viewer.png'));
    await page.close();
  } finally {
    await srv.stop();
  }
});
