// Browser test: the WebGL context lost and restored (WEBGL_lose_context, as
// a phone's browser does when the page goes to the background) in WebGL 2
// and WebGL 1, on a 390x844 phone at pixel ratio 3 (the canvas fixed at
// SIZE² pixels): the page rebuilds its GPU side by itself (the session made
// again on the new context, frontends/web/src/WebSession.cpp recoverContext)
// and shows the same image as before the loss (>= 60 dB) for
//  - ch2 as an OME-Zarr store, refined, then a region of its level 0 shown
//    at native resolution (it must come back as the region, not the store);
//  - then, in the same page, the head opened as a file (ch2 box-filtered
//    by 2, in core), with its look away from the defaults, then with a
//    region of it shown at native resolution and the crop box on;
//  - a three-channel store shown with its channels together, with a
//    channel hidden, a colour and a window edited (the same channels after).
// The status line says the context was lost, then restored; the view still
// turns after. Two pages per WebGL version, their cases in turn; every wait
// is on a signal of the page (status line, frames, store statistics), never
// a fixed sleep. Every figure is printed.
import { test } from 'node:test';
import fs from 'node:fs';
import path from 'node:path';
import { CH2, check, changedFraction, openPage, psnrOf, browserSuite, writeChannelStore } from './fixture.mjs';

const checks = browserSuite();

for (const webgl of [2, 1]) {
  test(`WebGL ${webgl} context lost and restored: an OME-Zarr store and a region of it, then the head in core ` +
       'and a region of it: the same images', checks((context, url, tmp, run) => storeThenFile(context, url, tmp, run, webgl)));
  test(`WebGL ${webgl} context lost and restored: a store's channels shown together, the same image and channels`,
    checks((context, url, tmp) => channels(context, url, tmp, webgl)));
}

const SIZE = 128;
const PHONE = { width: 390, height: 844, deviceScaleFactor: 3, mobile: true };

const statusOf = (page) => page.evaluate(() => document.getElementById('status').textContent);
// The canvas's RGBA pixels (top row first), sent as base64 (a quarter of
// the JSON array's bytes).
const pixelsOf = async (page) => Buffer.from(await page.evaluate(() => {
  const p = window.tessera.pixels();
  let text = '';
  for (let i = 0; i < p.length; i += 0x8000) text += String.fromCharCode.apply(null, p.subarray(i, i + 0x8000));
  return btoa(text);
}), 'base64');
const same = (a, b) => JSON.stringify(a) === JSON.stringify(b);
// Equal but for numbers within 1e-6 (a colour kept as float or as double).
const near = (a, b) => (typeof a === 'number' && typeof b === 'number' ? Math.abs(a - b) <= 1e-6
  : a && b && typeof a === 'object' ? Object.keys(a).length === Object.keys(b).length && Object.keys(a).every((k) => near(a[k], b[k]))
    : a === b);
const dB = (psnr) => (psnr >= 999 ? 'identical (inf dB)' : `${psnr.toFixed(2)} dB`);

const T0 = Date.now();
const mark = (what) => console.log(`[${((Date.now() - T0) / 1000).toFixed(1)} s] ${what}`);
async function phonePage(context, url, query, webgl) {
  mark(`open ${query}`);
  const opened = await openPage(context, url, `size=${SIZE}&${query}${webgl === 1 ? '&webgl=1' : ''}`);
  const cdp = await context.newCDPSession(opened.page);
  await cdp.send('Emulation.setDeviceMetricsOverride', PHONE);
  mark('opened');
  return opened;
}

// Loses the canvas's context (WEBGL_lose_context) and waits for the page to
// say so; `whileLost` runs then (input that must not throw or draw); then
// restores it, waits for the page to say so and for `settled` (a store
// opened again and refined), and reads the frame the page then shows.
async function loseAndRestore(page, { whileLost = async () => {}, settled = async () => {} } = {}) {
  mark('lose');
  const t = Date.now();
  await page.evaluate(() => {
    const c = document.getElementById('canvas');
    const gl = c.getContext('webgl2') || c.getContext('webgl');
    window.loseExt = gl.getExtension('WEBGL_lose_context');
    window.loseExt.loseContext();
  });
  await page.waitForFunction(() => document.getElementById('status').textContent.includes('WebGL context lost'),
    null, { timeout: 10000 });
  const lost = await statusOf(page);
  mark('lost');
  await whileLost();
  await page.evaluate(() => window.loseExt.restoreContext());
  await page.waitForFunction(() => document.getElementById('status').textContent.includes('WebGL context restored'),
    null, { timeout: 30000 });
  mark('restored');
  await settled();
  mark('settled');
  await page.evaluate(() => window.tessera.render());
  mark('rendered');
  const restored = await statusOf(page);
  return { lost, restored, pixels: await pixelsOf(page), ms: Date.now() - t };
}

// The checks every case makes: the frame after equals the one before, the
// state the case names is kept, the status line, no error, the view turns.
async function checkCase(page, what, before, after, kept, detail) {
  mark(`check ${what}`);
  const psnr = psnrOf(before, after.pixels);
  await page.evaluate(() => window.tessera.setCamera(80, 12, 1.25));
  const turned = changedFraction(after.pixels, await pixelsOf(page));
  const error = await page.evaluate(() => window.tessera.error());
  console.log(`${what}: ${dB(psnr)} after the loss; lost -> restored -> frame in ${after.ms} ms; ` +
              `status while lost "${after.lost}", after "${after.restored}"`);
  check(`${what}: the frame after the restore equals the frame before (>= 60 dB), the state is kept and the view still turns`,
    psnr >= 60 && kept && turned > 0.05 && error === '',
    `${dB(psnr)}; ${(100 * turned).toFixed(1)} % changed by a turn after; ${detail}; error "${error}"`);
  check(`${what}: the status line says "WebGL context lost — waiting", then "WebGL context restored"`,
    after.lost.includes('WebGL context lost — waiting') && after.restored.includes('WebGL context restored'),
    `"${after.lost}" / "${after.restored}"`);
}

function noScriptErrors(what, logs) {
  // A store's keys that are not there (.zattrs of a v2 array) answer 404 by design.
  const errors = logs.filter((l) => l.startsWith('pageerror') || (l.startsWith('error') && !/favicon|status of 404/.test(l)));
  check(`${what}: no script errors around the context losses`, errors.length === 0, errors.join(' | '));
}

// The head with settings away from their defaults (shading, window,
// camera), lost and restored; then a region of it shown at native
// resolution with the crop box on, lost and restored.
async function inCore(page, webgl, tmp, run) {
  // ch2 box-filtered by 2 (91x109x91, uncompressed): the head at an eighth
  // of the voxels, read and uploaded in a fraction of the time.
  const head = path.join(tmp, 'head.nii');
  if (!fs.existsSync(head)) run('convert', CH2, head, '--downsample', '2');
  const opened = await page.evaluate(() => window.tessera.openUrls(['/data/head.nii']));
  check(`WebGL ${webgl}: the head opens in the page after the store`, opened !== false, `${opened}`);
  // Controls set through their events (no pointer actions: they wait for
  // the element to settle on the emulated phone).
  await page.evaluate(async () => {
    const shade = document.getElementById('shade');
    shade.checked = true;
    shade.dispatchEvent(new Event('change'));
    const w = document.getElementById('winWidth');
    w.value = +w.max * 0.6;
    w.dispatchEvent(new Event('input'));
    await window.tessera.setCamera(35, 12, 1.25);
  });
  for (const region of [false, true]) {
    const what = `WebGL ${webgl}, head${region ? ', a region shown, crop box on' : ''}`;
    if (region) {
      await page.evaluate(() => window.tessera.slices.showRegion({ begin: [20, 45, 35], end: [70, 95, 85] }));
      await page.evaluate(() => {
        const crop = document.getElementById('cropShow');
        crop.checked = true;
        crop.dispatchEvent(new Event('change'));
      });
    }
    await page.evaluate(() => window.tessera.setCamera(35, 12, 1.25));
    const s0 = await page.evaluate(() => window.tessera.state());
    const e0 = await page.evaluate(() => window.tessera.slices.state());
    const before = await pixelsOf(page);
    // A camera change while lost must not throw or draw (its frame waits
    // for the restored context: not awaited).
    const after = await loseAndRestore(page, { whileLost: () => page.evaluate(() => { window.tessera.setCamera(35, 12, 1.25); }) });
    const s1 = await page.evaluate(() => window.tessera.state());
    const e1 = await page.evaluate(() => window.tessera.slices.state());
    const kept = s1.webgl === webgl && same(e0.explore.region, e1.explore.region) && e1.showing_region === region &&
      same(s0.dims, s1.dims) && same(s0.window, s1.window) && same(s0.camera, s1.camera) && s0.layout === s1.layout;
    await checkCase(page, what, before, after, kept,
      `${s1.description}; window ${s1.window.map((v) => v.toFixed(1)).join('..')}; ` +
      `region ${region ? JSON.stringify(e1.explore.region) : 'none'}, shown ${e1.showing_region}`);
  }
}

// ch2 as an OME-Zarr store (zlib chunks) under /data/, once per run.
function ch2Store(tmp, run) {
  const store = path.join(tmp, 'ch2.ome.zarr');
  if (!fs.existsSync(store)) run('convert', CH2, store, '--compressor', 'zlib');
  return '/data/ch2.ome.zarr';
}

// Until the store's frame is refined (every brick the view wants drawn)
// and nothing is being fetched; after a loss, also opened again.
function storeRefined(page, reopened = 0) {
  return page.waitForFunction((n) => {
    const z = window.tessera.zarr();
    return z && (z.reopened || 0) === n && (n === 0 || z.reopenMs !== null) && z.last && z.last.complete &&
      !z.last.pending && z.inFlight === 0 && z.queued === 0;
  }, reopened, { timeout: 60000 });
}

// The store refined at a turned view, lost and restored: its atlas, page
// table and ray caster are made again from the chunks the page holds.
// Then a region of its level 0 shown at native resolution (bounded reads),
// lost and restored: the region comes back, read from the chunks held.
async function storeThenFile(context, url, tmp, run, webgl) {
  if (!fs.existsSync(CH2)) { check(`store context loss test needs ${CH2} (mricron-data)`, false); return; }
  const { page, logs } = await phonePage(context, url, `url=${ch2Store(tmp, run)}`, webgl);
  await page.evaluate(() => window.tessera.setCamera(35, 12, 1.25));
  await storeRefined(page);
  mark('store refined');
  let what = `WebGL ${webgl}, store`;
  let s0 = await page.evaluate(() => window.tessera.state());
  let before = await pixelsOf(page);
  const z0 = await page.evaluate(() => window.tessera.zarr());
  let after = await loseAndRestore(page, { settled: () => storeRefined(page, 1) });
  const z1 = await page.evaluate(() => window.tessera.zarr());
  let s1 = await page.evaluate(() => window.tessera.state());
  console.log(`${what}: reopened in ${z1.reopenMs.toFixed(0)} ms with ${z1.reopenRequests} requests ` +
              `(${z1.requests - z0.requests} since the loss; ${z0.requests} before)`);
  await checkCase(page, what, before, after, s1.webgl === webgl && same(s0.camera, s1.camera),
    `store reopened ${z1.reopened} time(s); camera ${JSON.stringify(s1.camera)}`);

  what = `WebGL ${webgl}, store, a region of level 0 shown`;
  const overviewCamera = (await page.evaluate(() => window.tessera.state())).camera;
  await page.evaluate(() => window.tessera.zarrRegion([20, 30, 25], [70, 90, 75]));
  await page.evaluate(() => window.tessera.setCamera(35, 12, 1.25));
  s0 = await page.evaluate(() => window.tessera.state());
  const e0 = await page.evaluate(() => window.tessera.slices.state());
  before = await pixelsOf(page);
  after = await loseAndRestore(page, {
    settled: () => page.waitForFunction(() => { const z = window.tessera.zarr(); return z.reopened === 2 && z.reopenMs !== null; },
      null, { timeout: 60000 }),
  });
  s1 = await page.evaluate(() => window.tessera.state());
  const e1 = await page.evaluate(() => window.tessera.slices.state());
  const kept = s1.webgl === webgl && e0.showing_region && e1.showing_region && same(e0.explore.region, e1.explore.region) &&
    same(s0.dims, s1.dims) && same(s0.camera, s1.camera) && same(s0.window, s1.window);
  await checkCase(page, what, before, after, kept,
    `${s1.description}; region ${JSON.stringify(e1.explore.region)}, shown ${e0.showing_region} -> ${e1.showing_region}`);
  // Back to the store's overview: its own view again (the overview's camera kept over the losses).
  await page.evaluate(() => window.tessera.zarrOverview());
  const back = await page.evaluate(() => ({ shown: window.tessera.slices.state().showing_region, camera: window.tessera.state().camera }));
  check(`${what}: back to the store's overview after the restore, at the camera the overview had`,
    !back.shown && same(back.camera, overviewCamera), `showing region ${back.shown}; camera ${JSON.stringify(back.camera)}`);
  await inCore(page, webgl, tmp, run);
  noScriptErrors(`WebGL ${webgl}, store and head`, logs);
  await page.close();
}

// A three-channel u16 store shown with its channels together; the slab
// hidden, the sphere's colour and the rod's window edited in the panel;
// lost and restored: the same channels (state and frame).
async function channels(context, url, tmp, webgl) {
  const dir = path.join(tmp, 'three.ome.zarr');
  if (!fs.existsSync(dir)) writeChannelStore(dir, [48, 48, 24]);
  const { page, logs } = await phonePage(context, url, 'slices=0&url=/data/three.ome.zarr', webgl);
  await page.waitForFunction(() => window.tessera.channels() !== null || window.tessera.error() !== '', null, { timeout: 30000 });
  const what = `WebGL ${webgl}, three channels`;
  await page.$eval('[aria-label="show slab"]', (e) => { e.checked = false; e.dispatchEvent(new Event('change')); });
  await page.$eval('[aria-label="sphere colour"]', (e) => { e.value = '#ffff00'; e.dispatchEvent(new Event('input')); });
  await page.$eval('[aria-label="rod window high"]', (e) => { e.value = '2000'; e.dispatchEvent(new Event('change')); });
  await page.evaluate(() => window.tessera.setCamera(30, 20, 1));
  const c0 = await page.evaluate(() => window.tessera.channels());
  const before = await pixelsOf(page);
  const after = await loseAndRestore(page, {
    settled: () => page.waitForFunction(() => { const z = window.tessera.zarr(); return z.reopened === 1 && z.reopenMs !== null; },
      null, { timeout: 30000 }),
  });
  const c1 = await page.evaluate(() => window.tessera.channels());
  if (!near(c0, c1)) console.log(`channels before: ${JSON.stringify(c0)}\nchannels after: ${JSON.stringify(c1)}`);
  let lit = 0;
  for (let i = 0; i < before.length; i += 4) if (before[i] + before[i + 1] + before[i + 2] > 24) lit++;
  lit /= SIZE * SIZE;
  const kept = c0 && c0.open && c1 && c1.open && near(c0, c1) && lit > 0.02 &&
    same(c1.channels.map((c) => c.visible), [true, false, true]) && same(c1.channels[0].color, [1, 1, 0]) &&
    same(c1.channels[2].window, [100, 2000]);
  await checkCase(page, what, before, after, kept,
    `${(100 * lit).toFixed(1)} % of the frame lit; channels ${c1 ? c1.channels.map((c) => `${c.label} ${c.visible ? 'on' : 'off'} ` +
      `${c.color.map((v) => v.toFixed(2)).join(',')} ${c.window.join('..')}`).join('; ') : 'none'}`);
  noScriptErrors(what, logs);
  await page.close();
}
