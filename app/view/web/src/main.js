// bvc3d view: the page. Picks what to show from the index (and the URL: ?a=TRIAL&b=TRIAL&world=W&i=N&cell=K),
// builds one or two panes, and drives them with one slider.
import { get, isExport } from './api.js';
import { TrialPane, WorldPane, RecordingPane } from './panes.js';

const $ = (id) => document.getElementById(id);

const viewer = {
  panes: [],
  ready: false,
  readyAt: null,   // performance.now() when the first step of every pane was drawn
  frames: 0,       // animation frames in which some pane was drawn
  timings: {},     // performance.now() at each stage of opening: index, panes (arrays and worlds asked for)
  playing: false,
  sample: 0,
};
window.bvc3dViewer = viewer;

function setStatus(text) { $('status').textContent = text; }

function fillSelect(select, values, chosen, empty) {
  select.innerHTML = '';
  if (empty !== undefined) select.appendChild(Object.assign(document.createElement('option'), { value: '', textContent: empty }));
  for (const v of values) select.appendChild(Object.assign(document.createElement('option'), { value: v, textContent: v }));
  select.value = chosen || '';
}

// Other panes follow the first by their position along the trial (the same index when lengths match).
function follow(pane, i, lead) {
  if (pane === lead || lead.length <= 1) return i;
  return Math.round((i * (pane.length - 1)) / (lead.length - 1));
}

function setSample(i) {
  const lead = viewer.panes[0];
  if (!lead || !lead.length) return;
  i = Math.max(0, Math.min(lead.length - 1, Math.round(i)));
  viewer.sample = i;
  $('slider').value = i;
  const t = lead.timeAt ? lead.timeAt(i) : null;
  $('slider-label').textContent = `sample ${i} / ${lead.length - 1}` + (Number.isFinite(t) ? ` · ${t.toFixed(1)} s` : '');
  for (const p of viewer.panes) p.moveTo(follow(p, i, lead));
}
viewer.setSample = setSample;

// Every pane's world, steps (or probes) have arrived (or failed).
viewer.idle = () => viewer.panes.every((p) => !p.loadingWorld && (!p.loader || p.loader.idle()));

function loop() {
  let drew = false;
  if (viewer.playing) {
    const lead = viewer.panes[0];
    const next = viewer.sample + Number($('speed').value);
    setSample(next >= lead.length ? 0 : next);
  }
  for (const p of viewer.panes) if (p.view && p.view.render()) drew = true;
  if (drew) viewer.frames++;
  requestAnimationFrame(loop);
}

function navigate(params) {
  const url = new URL(window.location.href);
  for (const [k, v] of Object.entries(params)) {
    if (v === '' || v === null || v === undefined) url.searchParams.delete(k);
    else url.searchParams.set(k, v);
  }
  window.location.href = url.toString();
}

async function main() {
  const params = new URLSearchParams(window.location.search);
  let index;
  try {
    index = await get('index');
  } catch (e) {
    $('panes').innerHTML = '';
    $('panes').appendChild(Object.assign(document.createElement('div'), { className: 'error', textContent: `cannot reach bvc3d view: ${e.message}` }));
    return;
  }
  viewer.timings.index = performance.now();
  const a = params.get('a') || index.open[0] || index.trials[0] || '';
  const b = params.get('b') ?? (index.open[1] || '');
  const world = params.get('world') || index.world;
  const container = $('panes');
  const trialMode = a && !params.get('world');
  const recordingMode = !trialMode && index.recording && !params.get('world');
  fillSelect($('pick-a'), index.trials, a);
  fillSelect($('pick-b'), index.trials, b, '—');
  fillSelect($('pick-world'), index.worlds, trialMode || recordingMode ? '' : world, trialMode || recordingMode ? '—' : undefined);
  if (!index.trials.length) { $('pick-a-label').classList.add('hidden'); $('pick-b-label').classList.add('hidden'); }
  if (!index.worlds.length) $('pick-world-label').classList.add('hidden');
  $('pick-a').addEventListener('change', (e) => navigate({ a: e.target.value, world: '' }));
  $('pick-b').addEventListener('change', (e) => navigate({ b: e.target.value, world: '' }));
  $('pick-world').addEventListener('change', (e) => navigate({ world: e.target.value }));

  if (trialMode) {
    viewer.panes.push(new TrialPane(container, a));
    if (b) viewer.panes.push(new TrialPane(container, b));
  } else if (recordingMode) {
    viewer.panes.push(new RecordingPane(container));
  } else if (world) {
    viewer.panes.push(new WorldPane(container, world, params.get('world') ? '' : index.trajectory));
  }
  setStatus(isExport() ? 'exported page (static files)' : 'served by bvc3d view');
  await Promise.all(viewer.panes.map((p) => p.open()));
  viewer.timings.panes = performance.now();
  const lead = viewer.panes[0];
  const slider = $('slider');
  if (lead && lead.length) {
    slider.max = lead.length - 1;
    slider.addEventListener('input', () => setSample(Number(slider.value)));
    $('play').addEventListener('click', () => {
      viewer.playing = !viewer.playing;
      $('play').textContent = viewer.playing ? '❚❚' : '▶';
    });
    document.addEventListener('keydown', (e) => {
      if (e.target.tagName === 'SELECT') return;
      if (e.key === ' ') { e.preventDefault(); $('play').click(); }
      if (e.key === 'ArrowRight') setSample(viewer.sample + 1);
      if (e.key === 'ArrowLeft') setSample(viewer.sample - 1);
    });
    setSample(Number(params.get('i') || 0));
    const cell = params.get('cell');
    if (cell !== null) viewer.panes.forEach((p) => p.pick && p.trial && p.pick(Number(cell)));
  } else {
    $('transport').classList.add('hidden');
  }
  requestAnimationFrame(loop);
  // Ready once every pane's first step is drawn.
  const waitReady = () => {
    if (viewer.idle()) {
      requestAnimationFrame(() => {
        viewer.ready = true;
        viewer.readyAt = performance.now();
        document.body.dataset.ready = '1';
      });
    } else {
      setTimeout(waitReady, 5);
    }
  };
  waitReady();
}

document.addEventListener('DOMContentLoaded', main);
