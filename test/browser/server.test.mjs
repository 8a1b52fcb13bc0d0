// The server behind `bvc3d view`: loopback only, nothing outside the served folder, errors as
// pages (never a crash), several clients at once, read-only, Ctrl-C stops it.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { request } from 'node:http';
import { readFileSync, writeFileSync, symlinkSync, mkdirSync } from 'node:fs';
import { join } from 'node:path';
import { spawnSync } from 'node:child_process';
import { scratch, run, serve, launch, openPage, waitReady, bvc3d } from './helpers.mjs';

let dir, server;

before(async () => {
  dir = scratch('server');
  run(['run', '--hours', '0.02', '--out', join(dir, 'good.h5')]);
  writeFileSync(join(dir, 'broken.h5'), Buffer.from('\x89HDF\r\n\x1a\n and then nothing a trial file would hold'));
  writeFileSync(join(dir, 'half.h5'), readFileSync(join(dir, 'good.h5')).subarray(0, 4000));  // cut short
  mkdirSync(join(dir, 'sub'));
  symlinkSync('/etc', join(dir, 'sub', 'out'));  // a link leading out of the folder
  server = await serve([dir]);
});

after(async () => {
  if (server) assert.equal(await server.stop(), 0);
});

// A raw GET: the path goes out exactly as written (no URL normalization on the client's side).
function get(path, method = 'GET') {
  return new Promise((resolve, reject) => {
    const req = request({ host: '127.0.0.1', port: server.port, path, method, agent: false }, (res) => {
      const chunks = [];
      res.on('data', (c) => chunks.push(c));
      res.on('end', () => resolve({ status: res.statusCode, type: res.headers['content-type'], body: Buffer.concat(chunks) }));
    });
    req.on('error', reject);
    req.end();
  });
}

// Listening sockets on `port` from /proc/net/tcp and tcp6: local addresses in the kernel's hex.
function listeners(port) {
  const hexPort = port.toString(16).toUpperCase().padStart(4, '0');
  const found = [];
  for (const table of ['/proc/net/tcp', '/proc/net/tcp6']) {
    let text = '';
    try { text = readFileSync(table, 'utf8'); } catch { continue; }
    for (const line of text.trim().split('\n').slice(1)) {
      const [, local, , state] = line.trim().split(/\s+/);
      const [address, p] = local.split(':');
      if (p === hexPort && state === '0A') found.push(address);  // 0A: LISTEN
    }
  }
  return found;
}

test('listens on the loopback address only', () => {
  // 0100007F is 127.0.0.1 (little-endian); 00000000 would be every interface.
  assert.deepEqual(listeners(server.port), ['0100007F']);
});

test('paths outside the served folder are refused, however written', async () => {
  const attempts = [
    '/../../../../etc/passwd', '/%2e%2e/%2e%2e/%2e%2e/etc/passwd', '/..%2f..%2f..%2fetc%2fpasswd', '//etc/passwd',
    '/api/trial?path=../../../../etc/passwd', '/api/trial?path=%2e%2e%2f%2e%2e%2fetc%2fpasswd', '/api/trial?path=/etc/passwd',
    '/api/trial?path=%2Fetc%2Fpasswd', '/api/trial?path=sub/out/passwd', '/api/world?source=../../../../etc/passwd',
    '/api/world?source=/etc/passwd', '/api/step?path=..%5c..%5cetc%5cpasswd&i=0',
  ];
  for (const path of attempts) {
    const r = await get(path);
    assert.ok(r.status === 403 || r.status === 404 || r.status === 400, `${path}: status ${r.status}`);
    assert.ok(!r.body.toString().includes('root:'), `${path} leaked /etc/passwd`);
  }
  // The served files themselves are reachable.
  assert.equal((await get('/api/trial?path=good.h5')).status, 200);
  assert.equal((await get('/viewer.js')).status, 200);
});

test('a missing or corrupt trial file gives an error, and the server goes on', async () => {
  const missing = await get('/api/trial?path=nothing.h5');
  assert.equal(missing.status, 404);
  assert.match(JSON.parse(missing.body).error, /does not exist/);
  for (const name of ['broken.h5', 'half.h5']) {
    const r = await get(`/api/trial?path=${name}`);
    assert.equal(r.status, 422, name);
    assert.match(JSON.parse(r.body).error, new RegExp(name));
    assert.equal((await get(`/api/step?path=${name}&i=0`)).status, 422);
  }
  assert.equal((await get('/api/step?path=good.h5&i=99999999')).status, 404);
  assert.equal((await get('/api/step?path=good.h5&i=-1')).status, 400);
  const page404 = await get('/no-such-page.html');
  assert.equal(page404.status, 404);
  assert.match(page404.type, /text\/html/);
  assert.match(page404.body.toString(), /no such page/);
  assert.equal((await get('/api/index')).status, 200, 'the server stopped answering');
  assert.equal(server.child.exitCode, null);
});

test('the page shows the error of a corrupt trial file', async () => {
  const browser = await launch();
  try {
    const page = await openPage(browser, `${server.url}?a=broken.h5`);
    await page.waitForSelector('.error');
    assert.match(await page.textContent('.error'), /broken\.h5/);
    await page.close();
  } finally {
    await browser.close();
  }
});

test('read-only: other methods are refused', async () => {
  for (const method of ['POST', 'PUT', 'DELETE']) assert.equal((await get('/api/index', method)).status, 405, method);
});

test('two browsers at once', async () => {
  const [b1, b2] = await Promise.all([launch(), launch()]);
  try {
    const pages = await Promise.all([openPage(b1, `${server.url}?a=good.h5&i=10`), openPage(b2, `${server.url}?a=good.h5&i=20`)]);
    await Promise.all(pages.map((p) => waitReady(p)));
    const samples = await Promise.all(pages.map((p) => p.evaluate(() => window.bvc3dViewer.panes[0].step.header.sample)));
    assert.deepEqual(samples, [10, 20]);
    await Promise.all(pages.map((p) => p.close()));
  } finally {
    await Promise.all([b1.close(), b2.close()]);
  }
  // And many requests at once give the same bytes as one at a time.
  const one = await get('/api/step?path=good.h5&i=5');
  const many = await Promise.all(Array.from({ length: 12 }, () => get('/api/step?path=good.h5&i=5')));
  for (const r of many) assert.ok(r.status === 200 && r.body.equals(one.body));
});

test('Ctrl-C stops the server cleanly', async () => {
  const s = await serve([join(dir, 'good.h5')]);
  assert.equal(await s.stop(), 0);
  assert.match(s.output(), /stopped/);
});

test('bad arguments: a clear message and exit status 2', () => {
  for (const args of [['view', join(dir, 'nothing.h5')], ['view', '--port', '99999'], ['view', '--scans', dir]]) {
    const r = spawnSync(bvc3d, args, { encoding: 'utf8' });
    assert.ok(r.status === 2 || r.status === 105 || r.status === 106, `${args}: status ${r.status}`);
    assert.ok(r.stderr.length > 0, `${args}: no message`);
  }
  const r = spawnSync(bvc3d, ['view', join(dir, 'nothing.h5')], { encoding: 'utf8' });
  assert.equal(r.status, 2);
  assert.match(r.stderr, /nothing\.h5' does not exist/);
});
