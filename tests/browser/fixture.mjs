// The browser tests' shared page fixture (node --test; scripts/browser-test.sh
// runs every tests/browser/*.test.mjs): playwright-core drives Debian's
// headless Chromium (SwiftShader WebGL) against build-web/site served on
// localhost, launched once per test file (startBrowser), with helpers for
// reading the canvas's pixels and comparing them (PSNR) with the native
// CLI's images. Every check measures something; a test fails when any of
// its checks does.
//
// Environment: TESSERA_CLI (native tessera, for the reference images and
// test files; default build/tessera), TESSERA_SITE (default build-web/site),
// CHROMIUM (default /usr/bin/chromium), TESSERA_SHOTS (write screenshots
// there), TESSERA_BENCH=1 (render.test.mjs also times ch2 at 512x512),
// TESSERA_HEADFUL=1 (Chromium with its window on the X display $DISPLAY, at
// the screen's top left, the page at the window's size: for input sent
// through the X server, latency.test.mjs's TESSERA_LATENCY_INPUT=x11; run
// under xvfb-run).
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { before, after } from 'node:test';
import http from 'node:http';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
export const cli = process.env.TESSERA_CLI || path.join(root, 'build/tessera');
export const site = process.env.TESSERA_SITE || path.join(root, 'build-web/site');
const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';
export const shots = process.env.TESSERA_SHOTS || '';
export const bench = process.env.TESSERA_BENCH === '1' || process.argv.includes('--bench');
export const SIZE = 256;
export const VOLUME = 'gen:shepp-logan:96';
// The page samples adaptively but post-classified (webDefaultSampling() in
// frontends/web/src/WebSession.cpp); CLI renders compared with the page's own frames
// take the same sampling.
export const PAGE_SAMPLING = ['--preintegrate', 'off'];
export const CH2 = '/usr/share/mricron/templates/ch2.nii.gz';

// Checks log one line each; the failed ones of the running test are kept
// for checksPassed().
let failed = [];
export function check(name, ok, detail) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${name}${detail ? ` — ${detail}` : ''}`);
  if (!ok) failed.push(name);
}
// Runs `body` (a group of checks) and fails the node test when any failed.
export async function checksPassed(body) {
  failed = [];
  await body();
  assert.deepEqual(failed, [], `failed checks: ${failed.join('; ')}`);
}

// The native CLI (stdout as a string).
export const run = (...args) => execFileSync(cli, args, { stdio: ['ignore', 'pipe', 'pipe'] }).toString();

// One Chromium for the whole test file: registers the file's before/after
// hooks and returns the wrapper that runs a function (context, url, tmp, run)
// as a node test whose checks must all pass.
export function browserSuite() {
  let browser;
  before(async () => { browser = await startBrowser(); });
  after(async () => { if (browser) await browser.close(); });
  return (f) => () => checksPassed(() => f(browser.context, browser.url, browser.tmp, browser.run));
}

// A temporary folder for the test's files, the site served with it under
// /data/ (and the mricron templates under /templates/), and Chromium.
// close() removes them all.
export async function startBrowser() {
  if (!fs.existsSync(path.join(site, 'tessera-core.wasm'))) throw new Error(`no web build in ${site} (scripts/web.sh)`);
  if (!fs.existsSync(cli)) throw new Error(`no native tessera at ${cli} (set TESSERA_CLI)`);
  const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'tessera-browser-'));
  if (shots) fs.mkdirSync(shots, { recursive: true });
  const { server, url } = await serve(site, { '/data/': tmp, '/templates/': path.dirname(CH2) });
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'tessera-chromium-'));
  const headful = process.env.TESSERA_HEADFUL === '1';
  if (headful && !process.env.DISPLAY) throw new Error('TESSERA_HEADFUL=1 needs an X display (run under xvfb-run)');
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: chromiumPath,
    headless: !headful,
    viewport: headful ? null : { width: 1280, height: 900 },
    acceptDownloads: true,
    args: ['--no-sandbox', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--disable-quic',
      '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
      ...(headful ? ['--ozone-platform=x11', '--window-position=0,0', '--window-size=1280,1000'] : [])],
  });
  return {
    context, url, tmp, run,
    async close() {
      await context.close();
      server.close();
      fs.rmSync(profile, { recursive: true, force: true });
      fs.rmSync(tmp, { recursive: true, force: true });
    },
  };
}

// The site, and under /data/ the test's files (one origin, so the page may
// fetch them with ?url=), with Content-Length for the page's progress bar.
const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript',
  '.css': 'text/css', '.wasm': 'application/wasm', '.png': 'image/png', '.json': 'application/json' };
// Data prefixes serve their folder trees (an OME-Zarr store is one); a test
// may slow some paths down (served.delayMs) and count what was served.
// A single-range Range header ("bytes=A-B", "bytes=A-", "bytes=-N") is
// answered 206 with Content-Range, as nginx does, unless served.ranges is
// false (a server that ignores Range: 200 with the whole body); `log` has
// each answer's path, range, status and body bytes.
export const served = { delayMs: () => 0, fails: () => false, ranges: true, requests: 0, bytes: 0, paths: [], log: [] };
export async function serve(dir, dataDirs) {
  const server = http.createServer((req, res) => {
    const p = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    let file = null;
    for (const [prefix, d] of Object.entries(dataDirs)) {
      if (p.startsWith(prefix)) file = path.join(d, path.normalize(`/${p.slice(prefix.length)}`));
    }
    if (!file) file = path.join(dir, path.normalize(p === '/' ? '/index.html' : p));
    fs.stat(file, (err, st) => setTimeout(() => {
      served.requests++;
      served.paths.push(p);
      if (served.fails(p)) {
        served.log.push({ path: p, range: req.headers.range || '', status: 500, bytes: 0 });
        res.writeHead(500, { 'Content-Type': 'text/plain' });
        res.end('injected failure');
        return;
      }
      if (err || !st.isFile()) {
        served.log.push({ path: p, range: req.headers.range || '', status: 404, bytes: 0 });
        res.writeHead(404, { 'Content-Type': 'text/plain' });
        res.end('not found');
        return;
      }
      const type = TYPES[path.extname(file)] || 'application/octet-stream';
      const range = /^bytes=(\d*)-(\d*)$/.exec(req.headers.range || '');
      if (range && served.ranges && (range[1] !== '' || range[2] !== '')) {
        const size = st.size;
        const start = range[1] === '' ? Math.max(0, size - parseInt(range[2], 10)) : parseInt(range[1], 10);
        const end = range[1] === '' || range[2] === '' ? size - 1 : Math.min(size - 1, parseInt(range[2], 10));
        if (start >= size || end < start) {
          served.log.push({ path: p, range: req.headers.range, status: 416, bytes: 0 });
          res.writeHead(416, { 'Content-Range': `bytes */${size}` });
          res.end();
          return;
        }
        served.bytes += end - start + 1;
        served.log.push({ path: p, range: req.headers.range, status: 206, bytes: end - start + 1 });
        res.writeHead(206, { 'Content-Type': type, 'Content-Length': end - start + 1,
          'Content-Range': `bytes ${start}-${end}/${size}`, 'Cache-Control': 'no-store' });
        fs.createReadStream(file, { start, end }).pipe(res);
        return;
      }
      served.bytes += st.size;
      served.log.push({ path: p, range: req.headers.range || '', status: 200, bytes: st.size });
      res.writeHead(200, { 'Content-Type': type, 'Content-Length': st.size, 'Cache-Control': 'no-store' });
      fs.createReadStream(file).pipe(res);
    }, served.delayMs(p)));
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  return { server, url: `http://127.0.0.1:${server.address().port}` };
}

// A PNG decoded by the browser: {width, height, data (RGBA)}.
export function decodePng(page, pngPath) {
  return page.evaluate(async (b64) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width;
    c.height = img.height;
    const ctx = c.getContext('2d');
    ctx.drawImage(img, 0, 0);
    return { width: c.width, height: c.height, data: Array.from(ctx.getImageData(0, 0, c.width, c.height).data) };
  }, fs.readFileSync(pngPath).toString('base64'));
}

// PSNR (dB) over R, G, B of the canvas against a PNG, computed in the page
// (the browser decodes the PNG), as reference::psnr does.
export async function psnrAgainst(page, pngPath) {
  const { data } = await decodePng(page, pngPath);
  return page.evaluate((ref) => {
    const px = window.tessera.pixels();
    if (px.length !== ref.length) return { error: `sizes differ: ${px.length} vs ${ref.length}` };
    let sum = 0;
    for (let i = 0; i < px.length; i += 4) {
      for (let k = 0; k < 3; k++) { const d = px[i + k] - ref[i + k]; sum += d * d; }
    }
    const mse = sum / (px.length / 4 * 3);
    return { psnr: mse === 0 ? 999 : 10 * Math.log10(255 * 255 / mse), mse };
  }, data);
}

// Mean absolute difference of the canvas now against `before` (0..255),
// and the fraction of non-black pixels.
export async function snapshot(page) {
  return page.evaluate(() => {
    const p = window.tessera.pixels();
    let lit = 0;
    for (let i = 0; i < p.length; i += 4) if (p[i] + p[i + 1] + p[i + 2] > 24) lit++;
    return { pixels: Array.from(p), lit: lit / (p.length / 4) };
  });
}
// Fraction of pixels where some channel differs by more than 8 levels.
export function changedFraction(a, b) {
  let n = 0;
  for (let i = 0; i < a.length; i += 4) {
    if (Math.abs(a[i] - b[i]) > 8 || Math.abs(a[i + 1] - b[i + 1]) > 8 || Math.abs(a[i + 2] - b[i + 2]) > 8) n++;
  }
  return n / (a.length / 4);
}
// Pixels where some channel differs by more than `tol` levels.
export function differingPixels(a, b, tol) {
  let n = 0;
  for (let i = 0; i < a.length; i += 4) {
    if (Math.abs(a[i] - b[i]) > tol || Math.abs(a[i + 1] - b[i + 1]) > tol || Math.abs(a[i + 2] - b[i + 2]) > tol) n++;
  }
  return n;
}
export function meanAbsDiff(a, b) {
  let s = 0;
  for (let i = 0; i < a.length; i++) s += Math.abs(a[i] - b[i]);
  return s / a.length;
}

export async function openPage(context, base, query) {
  const page = await context.newPage();
  const logs = [];
  page.on('console', (m) => logs.push(`${m.type()}: ${m.text()}`));
  page.on('pageerror', (e) => logs.push(`pageerror: ${e.message}`));
  await page.goto(`${base}/index.html?${query}`);
  try {
    await page.evaluate(() => window.tessera.ready);
  } catch (e) {
    console.log(logs.join('\n'));
    throw e;
  }
  return { page, logs };
}

// A NIfTI-1 file with a PIL orientation (index x runs posterior, y
// inferior, z left) in its sform, and a bright off-centre ball, so that
// every format converted from it carries a non-trivial affine.
export function writePilNifti(file) {
  const [nx, ny, nz] = [40, 32, 24];
  const h = Buffer.alloc(352);
  h.writeInt32LE(348, 0);
  [3, nx, ny, nz, 1, 1, 1, 1].forEach((d, i) => h.writeInt16LE(d, 40 + 2 * i));
  h.writeInt16LE(2, 70);  // uint8
  h.writeInt16LE(8, 72);
  [1, 1.5, 1, 2, 1, 1, 1, 1].forEach((p, i) => h.writeFloatLE(p, 76 + 4 * i));
  h.writeFloatLE(352, 108);
  h.writeInt16LE(1, 254);  // sform_code scanner
  const srow = [[0, 0, -2, 30], [-1.5, 0, 0, 20], [0, -1, 0, 10]];
  srow.forEach((row, r) => row.forEach((v, c) => h.writeFloatLE(v, 280 + 16 * r + 4 * c)));
  h.write('n+1\0', 344, 'latin1');
  const data = Buffer.alloc(nx * ny * nz);
  for (let z = 0; z < nz; z++) {
    for (let y = 0; y < ny; y++) {
      for (let x = 0; x < nx; x++) {
        const d = Math.hypot((x - 15) / 12, (y - 18) / 10, (z - 11) / 8);
        data[x + nx * (y + ny * z)] = d < 1 ? 120 + Math.round(120 * (1 - d)) : 10;
      }
    }
  }
  fs.writeFileSync(file, Buffer.concat([h, data]));
}

// Opens `files` through the picker; resolves with the page's state once the
// volume named `name` is shown, or with the error the page shows instead.
export async function openThroughPicker(page, files, name) {
  await page.evaluate(() => { document.getElementById('error').hidden = true; });
  await page.setInputFiles('#file', files);
  await page.waitForFunction((n) => window.tessera.state().name === n || window.tessera.error() !== '',
    name, { timeout: 30000 });
  await page.evaluate(() => window.tessera.render());
  return { state: await page.evaluate(() => window.tessera.state()), error: await page.evaluate(() => window.tessera.error()) };
}

export async function withoutOverlays(page) {
  await page.uncheck('#box');
  await page.uncheck('#axes');
  await page.evaluate(() => window.tessera.render());
}

export function psnrOf(a, b) {
  let sum = 0;
  for (let i = 0; i < a.length; i += 4) for (let k = 0; k < 3; k++) sum += (a[i + k] - b[i + k]) ** 2;
  const mse = sum / (a.length / 4 * 3);
  return mse === 0 ? 999 : 10 * Math.log10(255 * 255 / mse);
}

// Sets the page's checkboxes ({ id: checked, ... }), sends one 'change'
// from the last of them (the page's handler reads the whole group) and
// waits for the frame it renders.
export function setCheckboxes(page, states) {
  return page.evaluate(async (s) => {
    const ids = Object.keys(s);
    for (const id of ids) document.getElementById(id).checked = s[id];
    document.getElementById(ids[ids.length - 1]).dispatchEvent(new Event('change'));
    await window.tessera.render();
  }, states);
}

// The level-0 chunk keys of a store's box [begin, end) (x, y, z).
export function chunkKeys(store, begin, end) {
  const meta = JSON.parse(fs.readFileSync(path.join(store, '0', '.zarray'), 'utf8'));
  const chunk = [...meta.chunks].reverse();  // x, y, z
  const keys = [];
  for (let cz = Math.floor(begin[2] / chunk[2]); cz * chunk[2] < end[2]; cz++) {
    for (let cy = Math.floor(begin[1] / chunk[1]); cy * chunk[1] < end[1]; cy++) {
      for (let cx = Math.floor(begin[0] / chunk[0]); cx * chunk[0] < end[0]; cx++) {
        keys.push(`/data/ch2.ome.zarr/0/${cz}/${cy}/${cx}`);
      }
    }
  }
  return keys;
}

// The 3-channel u16 store of tests/support/ChannelStore.h (NGFF 0.4 on
// Zarr v2, one uncompressed chunk per channel and level): a sphere (channel 0), a
// slab (1), a rod (2) on a background of 100, with omero colours and windows
// (channels.test.mjs, context-loss.test.mjs).
export function writeChannelStore(dir, [nx, ny, nz]) {
  fs.rmSync(dir, { recursive: true, force: true });
  fs.mkdirSync(path.join(dir, '0'), { recursive: true });
  fs.writeFileSync(path.join(dir, '.zgroup'), JSON.stringify({ zarr_format: 2 }));
  const axis = (name) => ({ name, type: 'space', unit: 'millimeter' });
  const win = (min, max, start, end) => ({ min, max, start, end });
  fs.writeFileSync(path.join(dir, '.zattrs'), JSON.stringify({
    multiscales: [{ version: '0.4', name: 'channels',
      axes: [{ name: 'c', type: 'channel' }, axis('z'), axis('y'), axis('x')],
      datasets: [{ path: '0', coordinateTransformations: [{ type: 'scale', scale: [1, 1, 1, 1] }] },
        { path: '1', coordinateTransformations: [{ type: 'scale', scale: [1, 2, 2, 2] },
          { type: 'translation', translation: [0, 0.5, 0.5, 0.5] }] }] }],
    omero: { channels: [
      { label: 'sphere', color: 'FF0000', active: true, window: win(100, 3000, 100, 3000) },
      { label: 'slab', color: '00FF00', active: true, window: win(100, 2000, 50, 2500) },
      { label: 'rod', color: '0080FF', active: true, window: win(100, 4000, 100, 4000) }] },
  }));
  const inside = (c, x, y, z) => {
    const fx = (x + 0.5) / nx, fy = (y + 0.5) / ny, fz = (z + 0.5) / nz;
    if (c === 0) return (fx - 0.35) ** 2 + (fy - 0.4) ** 2 + (fz - 0.5) ** 2 < 0.22 ** 2;
    if (c === 1) return fy > 0.62 && fy < 0.78;
    return (fx - 0.72) ** 2 + (fz - 0.45) ** 2 < 0.08 ** 2;
  };
  const value = [3000, 2000, 4000];
  // Level 1 (every other voxel): the page's bricks layout needs a level
  // coarser than the one it refines to.
  for (const [level, f] of [[0, 1], [1, 2]]) {
    const [lx, ly, lz] = [nx / f, ny / f, nz / f];
    fs.mkdirSync(path.join(dir, String(level)), { recursive: true });
    fs.writeFileSync(path.join(dir, String(level), '.zarray'), JSON.stringify({
      zarr_format: 2, shape: [3, lz, ly, lx], chunks: [1, lz, ly, lx], dtype: '<u2', compressor: null,
      fill_value: 0, order: 'C', filters: null, dimension_separator: '/' }));
    for (let c = 0; c < 3; c++) {
      const bytes = Buffer.alloc(lx * ly * lz * 2);
      let i = 0;
      for (let z = 0; z < lz; z++) for (let y = 0; y < ly; y++) for (let x = 0; x < lx; x++, i += 2) {
        bytes.writeUInt16LE(inside(c, x * f, y * f, z * f) ? value[c] : 100, i);
      }
      const chunk = path.join(dir, String(level), String(c), '0', '0');
      fs.mkdirSync(chunk, { recursive: true });
      fs.writeFileSync(path.join(chunk, '0'), bytes);
    }
  }
}
