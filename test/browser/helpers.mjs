// Shared by the browser tests: where the program is, a trial made for the tests, `bvc3d view` as a
// child process, and headless Chromium (Debian's) driven by playwright-core.
import { spawn, execFileSync } from 'node:child_process';
import { mkdtempSync, mkdirSync, existsSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const source = resolve(dirname(fileURLToPath(import.meta.url)), '..', '..');
export const build = process.env.BVC3D_BUILD_DIR ? resolve(process.env.BVC3D_BUILD_DIR) : join(source, 'build');
export const bvc3d = join(build, 'bvc3d');
export const python = '/usr/bin/python3';

// Screenshots go here (printed, kept after the run): BVC3D_ARTIFACTS or build/test-artifacts/viewer.
export const artifacts = process.env.BVC3D_ARTIFACTS ? resolve(process.env.BVC3D_ARTIFACTS) : join(build, 'test-artifacts', 'viewer');
mkdirSync(artifacts, { recursive: true });

export function scratch(name) {
  return mkdtempSync(join(tmpdir(), `bvc3d-${name}-`));
}

export function run(args, options = {}) {
  return execFileSync(bvc3d, args, { encoding: 'utf8', ...options });
}

// Reads datasets of a trial file with h5py (the independent reader): returns the parsed JSON of
// what `expr` evaluates to with `f` the open file and numpy as np.
export function h5(file, expr) {
  const code = `import h5py, json, numpy as np\nwith h5py.File(${JSON.stringify(file)}) as f:\n    print(json.dumps(${expr}))`;
  return JSON.parse(execFileSync(python, ['-c', code], { encoding: 'utf8' }));
}

// Starts `bvc3d view ARGS` on a free port; resolves with {url, port, child, stop()}.
export function serve(args, options = {}) {
  return new Promise((resolvePromise, reject) => {
    const child = spawn(bvc3d, ['view', ...args], { stdio: ['ignore', 'pipe', 'pipe'], ...options });
    let out = '', err = '';
    const timer = setTimeout(() => { child.kill('SIGKILL'); reject(new Error(`bvc3d view did not start: ${out} ${err}`)); }, 20000);
    child.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/http:\/\/127\.0\.0\.1:(\d+)\//);
      if (m) {
        clearTimeout(timer);
        // Ctrl-C; a server that has not stopped 15 s later is killed, and stop() says so.
        const stop = () => new Promise((done) => {
          if (child.exitCode !== null || child.signalCode !== null) return done(child.exitCode);
          const killer = setTimeout(() => child.kill('SIGKILL'), 15000);
          child.once('exit', (code, signal) => {
            clearTimeout(killer);
            done(signal === 'SIGKILL' ? 'killed: did not stop on SIGINT' : code);
          });
          child.kill('SIGINT');
        });
        resolvePromise({ url: m[0], port: Number(m[1]), child, stop, output: () => out + err });
      }
    });
    child.stderr.on('data', (d) => { err += d; });
    child.on('exit', (code) => { clearTimeout(timer); reject(new Error(`bvc3d view exited ${code}: ${out} ${err}`)); });
  });
}

// Debian's Chromium, headless, with software WebGL and no network of its own. playwright-core
// starts it with a fresh, empty profile of its own each time (it refuses --user-data-dir here).
export async function launch() {
  return chromium.launch({
    executablePath: process.env.BVC3D_CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
}

// A page that records every request it makes that is not to `origin` (there must be none).
export async function openPage(browser, url, viewport = { width: 1400, height: 1000 }) {
  const page = await browser.newPage({ viewport });
  page.setDefaultTimeout(90000);  // a loaded 2-core machine renders in software slowly
  const origin = new URL(url).origin;
  page.foreignRequests = [];
  page.consoleErrors = [];
  page.on('request', (r) => {
    const u = r.url();
    if (!u.startsWith(origin) && !u.startsWith('file:') && !u.startsWith('data:') && !u.startsWith('blob:')) page.foreignRequests.push(u);
  });
  page.on('console', (m) => { if (m.type() === 'error') page.consoleErrors.push(m.text()); });
  page.on('pageerror', (e) => page.consoleErrors.push(String(e)));
  await page.goto(url);
  return page;
}

export async function waitReady(page, timeout = 90000) {
  await page.waitForFunction(() => window.bvc3dViewer && window.bvc3dViewer.ready, null, { timeout });
}

// Counts the canvas's pixels that differ from its background (the corner's color), in the browser.
export async function paintedPixels(page, selector) {
  return page.$eval(selector, (c) => {
    // A WebGL canvas keeps its pixels only until they are shown: draw it again in this task.
    for (const p of window.bvc3dViewer.panes) if (p.view && p.view.renderer.domElement === c) { p.view.settle(); p.view.render(true); }
    const w = c.width, h = c.height;
    let data;
    const gl = c.getContext('webgl2') || c.getContext('webgl');
    if (gl) {
      data = new Uint8Array(w * h * 4);
      gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, data);
    } else {
      data = c.getContext('2d').getImageData(0, 0, w, h).data;
    }
    const bg = [data[0], data[1], data[2]];
    let n = 0;
    for (let i = 0; i < data.length; i += 4) {
      if (Math.abs(data[i] - bg[0]) + Math.abs(data[i + 1] - bg[1]) + Math.abs(data[i + 2] - bg[2]) > 24) n++;
    }
    return n;
  });
}

export function have(path) { return existsSync(path); }
