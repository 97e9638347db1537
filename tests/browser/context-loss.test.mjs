// Browser test: the WebGL context lost and restored (WEBGL_lose_context, as
// a phone's browser does when the page goes to the background) in WebGL 2
// and WebGL 1, on a 390x844 phone at pixel ratio 3 (the canvas fixed at
// SIZE² pixels): the page rebuilds its GPU side by itself (the session's
// Session::loseContext / restoreContext, the store's view made again by
// frontends/web/src/WebSession.cpp recoverContext) and shows the same image
// as before the loss (>= 60 dB) for
//  - ch2 box-filtered by 2 as an OME-Zarr store, refined;
//  - then a region of its level 0 shown at native resolution, its chunks
//    held: the restore reads it again from them (none fetched) and shows
//    the region, not the store;
//  - then a grid block of the store (the grid view): the same block in the
//    grid view after, and the grid still moves;
//  - then, in the same page, the same head opened as a file (in core),
//    with its look away from the defaults, then with a
//    region of it shown at native resolution and the crop box on;
//  - a three-channel store shown with its channels together, with a
//    channel hidden, a colour and a window edited (the same channels after);
//  - a store's t axis played over bricks (?layout=bricks): lost while it
//    plays, it comes back at the time point it showed and plays on in
//    order; lost while paused, the same image, time slider and label, and
//    playing on works; a region of it shown at time point 3 comes back at
//    time point 3;
//  - (WebGL 2) a store whose chunk cache is small (?zarrcache=0.75, 24 of its 32³
//    chunks): a region of level 0 shown, then the slice views read level-0
//    slabs elsewhere and the cache's own limit lets the region's chunks go;
//    the restore fetches exactly the chunks it needs that were let go (the
//    server's log), each once, and shows the same region; (WebGL 1) a cache
//    size and a strip share out of range are refused naming their ranges.
// The status line says the context was lost, then restored; the view still
// turns after. WebGL 2 and WebGL 1 run side by side, each in a Chromium of
// its own (its pages in turn: the store and the head, then the channels),
// so that one version's work fills the other's waits for fetches and
// animation frames; each reads its own URL of the store, so that what it
// fetched is its own. Every wait is on a signal of the page (status line,
// frames, store statistics), never a fixed sleep, and only for what a check
// reads (a turned view's first frame, not its refinement). Every figure is
// printed.
import assert from 'node:assert/strict';
import { before, after, test } from 'node:test';
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import {
  CH2, changedFraction, chunkKeys, openPage, psnrOf, root, run, served, startBrowser, writeChannelStore,
} from './fixture.mjs';

// One Chromium per WebGL version: a page in a background tab gets no
// animation frames, so the versions' pages each have a browser of their own.
const VERSIONS = [2, 1];
let browsers = [];
before(async () => { browsers = await Promise.all(VERSIONS.map(() => startBrowser())); });
after(async () => { await Promise.all(browsers.map((b) => b.close())); });

test('the WebGL context lost and restored in WebGL 2 and WebGL 1 side by side: an OME-Zarr store, a region of it, ' +
     'a grid block of it, the head in core and a region of it, a store\'s channels, a store\'s t axis over bricks, ' +
     'a region whose chunks the cache\'s limit let go: the same images', { concurrency: VERSIONS.length }, async (t) => {
  if (!fs.existsSync(CH2)) assert.fail(`the context loss test needs ${CH2} (mricron-data)`);
  prepareFiles(browsers.map((b) => b.tmp));
  await Promise.all(VERSIONS.map((webgl, i) => t.test(`WebGL ${webgl}: the store, its region and grid block, the head ` +
    `and its region, the channels, a series over bricks${webgl === 2 ? ', a region evicted' : ''}`, async () => {
    const c = checker();
    const { context, url, tmp } = browsers[i];
    await storeThenFile(c, context, url, tmp, webgl);
    await channels(c, context, url, webgl);
    await brickedSeries(c, context, url, webgl);
    // The chunk cache is the same in both versions: in the shorter run only
    // (the other checks that a cache size and a strip share out of range
    // are refused).
    if (webgl === 2) await evictedRegion(c, context, url, tmp, webgl);
    else await cacheOutOfRange(c, context, url, webgl);
    assert.deepEqual(c.failed, [], `failed checks: ${c.failed.join('; ')}`);
  })));
});

const SIZE = 128;
const PHONE = { width: 390, height: 844, deviceScaleFactor: 3, mobile: true };
const STORE = 'ch2.ome.zarr';

// Checks of one version's run: each logs one line; the failed ones are kept
// (the two versions run at once, each with its own list).
function checker() {
  const failed = [];
  const c = (name, ok, detail) => {
    console.log(`${ok ? 'ok  ' : 'FAIL'} ${name}${detail ? ` — ${detail}` : ''}`);
    if (!ok) failed.push(name);
  };
  c.failed = failed;
  return c;
}

// The test's files under /data/ of each version's browser, made once in the
// first's folder (linked from the others') before the pages open: ch2
// box-filtered by 2 (91x109x91, uncompressed: the head at an eighth of the
// voxels, read, refined and uploaded in a fraction of the time), the same as
// an OME-Zarr store (uncompressed chunks, two levels) with a URL of its own
// per version (so that what each fetched is its own), and the three-channel
// store.
function prepareFiles(tmps) {
  const made = tmps[0];
  const head = path.join(made, 'head.nii');
  if (!fs.existsSync(head)) run('convert', CH2, head, '--downsample', '2');
  const store = path.join(made, STORE);
  if (!fs.existsSync(store)) run('convert', head, store, '--compressor', 'none');
  const three = path.join(made, 'three.ome.zarr');
  if (!fs.existsSync(three)) writeChannelStore(three, [48, 48, 24]);
  // 6 time points of 64³ (tests/zarr/make_time_store.py): a bright cube
  // whose x moves with t in a dim shell.
  const cube = path.join(made, 'cube6.ome.zarr');
  if (!fs.existsSync(cube)) {
    execFileSync('/usr/bin/python3', [path.join(root, 'tests/zarr/make_time_store.py'), cube, '64', '6']);
  }
  // The head in 32³ chunks (uncompressed, 32 KiB each): 36 chunks at level 0.
  const small = path.join(made, SMALL);
  if (!fs.existsSync(small)) run('convert', head, small, '--compressor', 'none', '--chunk', '32,32,32');
  const link = (to, tmp, name) => { if (!fs.existsSync(path.join(tmp, name))) fs.symlinkSync(to, path.join(tmp, name)); };
  tmps.forEach((tmp, i) => {
    link(store, tmp, storeName(VERSIONS[i]));
    link(cube, tmp, `cube6-webgl${VERSIONS[i]}.ome.zarr`);
    link(small, tmp, smallName(VERSIONS[i]));
    if (tmp !== made) link(small, tmp, SMALL);
    if (tmp === made) return;
    link(store, tmp, STORE);
    link(head, tmp, 'head.nii');
    link(three, tmp, 'three.ome.zarr');
  });
}
const storeName = (webgl) => `ch2-webgl${webgl}.ome.zarr`;
const SMALL = 'head32.ome.zarr';
const smallName = (webgl) => `head32-webgl${webgl}.ome.zarr`;

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
const mark = (webgl, what) => console.log(`[${((Date.now() - T0) / 1000).toFixed(1)} s] WebGL ${webgl}: ${what}`);
async function phonePage(context, url, query, webgl) {
  mark(webgl, `open ${query}`);
  const opened = await openPage(context, url, `${/(^|&)size=/.test(query) ? '' : `size=${SIZE}&`}${query}${webgl === 1 ? '&webgl=1' : ''}`);
  const cdp = await context.newCDPSession(opened.page);
  await cdp.send('Emulation.setDeviceMetricsOverride', PHONE);
  mark(webgl, 'opened');
  return opened;
}

// Loses the canvas's context (WEBGL_lose_context) and waits for the page to
// say so; `whileLost` runs then (input that must not throw or draw); then
// restores it, waits for the page to say so and for `settled` (a store
// opened again and refined), and reads the frame the page then shows.
// `servedSince`: what the server sent from the loss on; `timeLost`: the
// time series (tessera.time()) once the page said the context was lost
// (nothing is drawn or played while it is).
async function loseAndRestore(page, webgl, { whileLost = async () => {}, settled = async () => {} } = {}) {
  mark(webgl, 'lose');
  const t = Date.now();
  const servedBefore = served.paths.length;
  await page.evaluate(() => {
    const c = document.getElementById('canvas');
    const gl = c.getContext('webgl2') || c.getContext('webgl');
    window.loseExt = gl.getExtension('WEBGL_lose_context');
    window.loseExt.loseContext();
  });
  await page.waitForFunction(() => document.getElementById('status').textContent.includes('WebGL context lost'),
    null, { timeout: 10000 });
  const lost = await statusOf(page);
  const timeLost = await page.evaluate(() => window.tessera.time());
  await whileLost();
  await page.evaluate(() => window.loseExt.restoreContext());
  await page.waitForFunction(() => document.getElementById('status').textContent.includes('WebGL context restored'),
    null, { timeout: 30000 });
  mark(webgl, 'restored');
  await settled();
  await page.evaluate(() => window.tessera.render());
  mark(webgl, 'settled and rendered');
  const restored = await statusOf(page);
  return { lost, restored, pixels: await pixelsOf(page), ms: Date.now() - t, timeLost,
    servedSince: served.paths.slice(servedBefore) };
}

// The checks every case makes: the frame after equals the one before, the
// state the case names is kept, the status line, no error, the view turns.
async function checkCase(c, page, what, before, after, kept, detail) {
  const psnr = psnrOf(before, after.pixels);
  // The next frame shown at a turned camera (a preview will do: a store's
  // refinement at the new view is not waited for).
  const frames = await page.evaluate(() => window.tessera.frames());
  await page.evaluate(() => { window.tessera.setCamera(80, 12, 1.25); });
  await page.waitForFunction((n) => window.tessera.frames() > n, frames, { timeout: 30000 });
  const turned = changedFraction(after.pixels, await pixelsOf(page));
  const error = await page.evaluate(() => window.tessera.error());
  console.log(`${what}: ${dB(psnr)} after the loss; lost -> restored -> frame in ${after.ms} ms; ` +
              `status while lost "${after.lost}", after "${after.restored}"`);
  c(`${what}: the frame after the restore equals the frame before (>= 60 dB), the state is kept and the view still turns`,
    psnr >= 60 && kept && turned > 0.05 && error === '',
    `${dB(psnr)}; ${(100 * turned).toFixed(1)} % changed by a turn after; ${detail}; error "${error}"`);
  c(`${what}: the status line says "WebGL context lost — waiting", then "WebGL context restored"`,
    after.lost.includes('WebGL context lost — waiting') && after.restored.includes('WebGL context restored'),
    `"${after.lost}" / "${after.restored}"`);
}

function noScriptErrors(c, what, logs) {
  // A store's keys that are not there (.zattrs of a v2 array) answer 404 by design.
  const errors = logs.filter((l) => l.startsWith('pageerror') || (l.startsWith('error') && !/favicon|status of 404/.test(l)));
  c(`${what}: no script errors around the context losses`, errors.length === 0, errors.join(' | '));
}

// The head with settings away from their defaults (shading, window,
// camera), lost and restored; then a region of it shown at native
// resolution with the crop box on, lost and restored.
async function inCore(c, page, webgl) {
  const opened = await page.evaluate(() => window.tessera.openUrls(['/data/head.nii']));
  c(`WebGL ${webgl}: the head opens in the page after the store`, opened !== false, `${opened}`);
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
    const after = await loseAndRestore(page, webgl, {
      whileLost: () => page.evaluate(() => { window.tessera.setCamera(35, 12, 1.25); }),
    });
    const s1 = await page.evaluate(() => window.tessera.state());
    const e1 = await page.evaluate(() => window.tessera.slices.state());
    const kept = s1.webgl === webgl && same(e0.explore.region, e1.explore.region) && e1.showing_region === region &&
      same(s0.dims, s1.dims) && same(s0.window, s1.window) && same(s0.camera, s1.camera) && s0.layout === s1.layout;
    await checkCase(c, page, what, before, after, kept,
      `${s1.description}; window ${s1.window.map((v) => v.toFixed(1)).join('..')}; ` +
      `region ${region ? JSON.stringify(e1.explore.region) : 'none'}, shown ${e1.showing_region}`);
  }
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
// Until the store is open again after its n-th loss (a region or grid
// block it showed is then shown again).
function storeReopened(page, n) {
  return page.waitForFunction((k) => { const z = window.tessera.zarr(); return z.reopened === k && z.reopenMs !== null; },
    n, { timeout: 60000 });
}

// The store refined at a turned view, lost and restored: its atlas, page
// table and ray caster are made again from the chunks the page holds.
// Then a region of its level 0 shown at native resolution (bounded reads)
// whose chunks are let go, lost and restored: the region comes back, its
// chunks fetched again. Then a grid block, lost and restored. Then the head.
async function storeThenFile(c, context, url, tmp, webgl) {
  const storeUrl = `/data/${storeName(webgl)}`;
  const { page, logs } = await phonePage(context, url, `url=${storeUrl}`, webgl);
  await page.evaluate(() => window.tessera.setCamera(35, 12, 1.25));
  await storeRefined(page);
  mark(webgl, 'store refined');
  let what = `WebGL ${webgl}, store`;
  let s0 = await page.evaluate(() => window.tessera.state());
  let before = await pixelsOf(page);
  const z0 = await page.evaluate(() => window.tessera.zarr());
  let after = await loseAndRestore(page, webgl, { settled: () => storeRefined(page, 1) });
  const z1 = await page.evaluate(() => window.tessera.zarr());
  let s1 = await page.evaluate(() => window.tessera.state());
  console.log(`${what}: reopened in ${z1.reopenMs.toFixed(0)} ms with ${z1.reopenRequests} requests ` +
              `(${z1.requests - z0.requests} since the loss; ${z0.requests} before)`);
  await checkCase(c, page, what, before, after, s1.webgl === webgl && same(s0.camera, s1.camera),
    `store reopened ${z1.reopened} time(s); camera ${JSON.stringify(s1.camera)}`);

  // A region of level 0, its chunks held (the cache's limit letting them
  // go is evictedRegion's): the restore reads it again from them, fetching
  // none, and shows the same region.
  what = `WebGL ${webgl}, store, a region of level 0 shown`;
  const overviewCamera = (await page.evaluate(() => window.tessera.state())).camera;
  const [rb, re] = [[20, 30, 25], [70, 90, 75]];
  await page.evaluate(([b, e]) => window.tessera.zarrRegion(b, e), [rb, re]);
  await page.evaluate(() => window.tessera.setCamera(35, 12, 1.25));
  s0 = await page.evaluate(() => window.tessera.state());
  const e0 = await page.evaluate(() => window.tessera.slices.state());
  before = await pixelsOf(page);
  // Level-0 keys relative to the store's root, and as this version's URL serves them.
  const keys = chunkKeys(path.join(tmp, STORE), rb, re).map((k) => k.slice(`/data/${STORE}/`.length));
  const urls = keys.map((k) => `${storeUrl}/${k}`);
  const held = await page.evaluate((ks) => ks.filter((k) => window.tessera.zarrHolds(k)).length, keys);
  after = await loseAndRestore(page, webgl, { settled: () => storeReopened(page, 2) });
  s1 = await page.evaluate(() => window.tessera.state());
  const e1 = await page.evaluate(() => window.tessera.slices.state());
  const fetchedAgain = urls.filter((u) => after.servedSince.includes(u)).length;
  const z2 = await page.evaluate(() => window.tessera.zarr());
  const kept = s1.webgl === webgl && e0.showing_region && e1.showing_region && same(e0.explore.region, e1.explore.region) &&
    same(s0.dims, s1.dims) && same(s0.camera, s1.camera) && same(s0.window, s1.window) &&
    keys.length > 0 && held === keys.length && fetchedAgain === 0;
  console.log(`${what}: ${held} of its ${keys.length} chunks held, ${fetchedAgain} fetched again; ` +
              `reopened in ${z2.reopenMs.toFixed(0)} ms with ${z2.reopenRequests} requests`);
  await checkCase(c, page, what, before, after, kept,
    `${s1.description}; region ${JSON.stringify(e1.explore.region)}, shown ${e0.showing_region} -> ${e1.showing_region}; ` +
    `${held}/${keys.length} chunks held, ${fetchedAgain} fetched again`);
  // Back to the store's overview: its own view again at the overview's
  // camera, kept over the losses, not the region's (turned away first); the
  // first frame shown then is read, its refinement not waited for.
  const shownBefore = await page.evaluate(() => {
    window.tessera.setCamera(10, -20, 1.6);  // (one task: no frame of the region at it)
    const n = window.tessera.frames();
    window.tessera.zarrOverview();
    return n;
  });
  await page.waitForFunction((n) => window.tessera.frames() > n, shownBefore, { timeout: 30000 });
  const back = await page.evaluate(() => ({ shown: window.tessera.slices.state().showing_region, camera: window.tessera.state().camera }));
  c(`${what}: back to the store's overview after the restore, at the camera the overview had`,
    !back.shown && same(back.camera, overviewCamera), `showing region ${back.shown}; camera ${JSON.stringify(back.camera)}`);

  // A grid block of the store (the grid view), lost and restored: the same
  // block in the grid view, and the grid still moves after.
  what = `WebGL ${webgl}, store, a grid block shown`;
  const entered = await page.evaluate(() => window.tessera.slices.grid.enter(32));
  await page.evaluate(() => window.tessera.setCamera(35, 12, 1.25));
  const g0 = await page.evaluate(() => window.tessera.slices.grid.state());
  s0 = await page.evaluate(() => window.tessera.state());
  before = await pixelsOf(page);
  after = await loseAndRestore(page, webgl, { settled: () => storeReopened(page, 3) });
  const g1 = await page.evaluate(() => window.tessera.slices.grid.state());
  s1 = await page.evaluate(() => window.tessera.state());
  const gridKept = entered === true && g0.store && g0.active && g1.active && same(g0.block, g1.block) &&
    same(g0.point, g1.point) && same(g0.cell_size, g1.cell_size) && same(s0.camera, s1.camera) && same(s0.window, s1.window);
  await checkCase(c, page, what, before, after, gridKept,
    `${s1.description}; block ${g1.block_text} (${g1.describe}), cells of ${g1.cell_size.join('×')}, ` +
    `in the grid view ${g0.active} -> ${g1.active}`);
  const legal = g1.moves.findIndex((m) => m.legal);
  const moved = legal >= 0 ? await page.evaluate((i) => window.tessera.slices.grid.move(i), legal) : -1;
  const g2 = await page.evaluate(() => window.tessera.slices.grid.state());
  c(`${what}: the grid still moves after the restore`, moved === 1 && g2.active && !same(g2.block, g1.block),
    `move ${legal >= 0 ? g1.moves[legal].view : '(none legal)'}: ${moved}; block ${g1.block_text} -> ${g2.block_text}`);

  await inCore(c, page, webgl);
  noScriptErrors(c, `WebGL ${webgl}, store and head`, logs);
  await page.close();
}

// A three-channel u16 store shown with its channels together; the slab
// hidden, the sphere's colour and the rod's window edited in the panel;
// lost and restored: the same channels (state and frame).
async function channels(c, context, url, webgl) {
  const { page, logs } = await phonePage(context, url, 'slices=0&url=/data/three.ome.zarr', webgl);
  await page.waitForFunction(() => window.tessera.channels() !== null || window.tessera.error() !== '', null, { timeout: 30000 });
  const what = `WebGL ${webgl}, three channels`;
  await page.$eval('[aria-label="show slab"]', (e) => { e.checked = false; e.dispatchEvent(new Event('change')); });
  await page.$eval('[aria-label="sphere colour"]', (e) => { e.value = '#ffff00'; e.dispatchEvent(new Event('input')); });
  await page.$eval('[aria-label="rod window high"]', (e) => { e.value = '2000'; e.dispatchEvent(new Event('change')); });
  await page.evaluate(() => window.tessera.setCamera(30, 20, 1));
  const c0 = await page.evaluate(() => window.tessera.channels());
  const before = await pixelsOf(page);
  const after = await loseAndRestore(page, webgl, { settled: () => storeReopened(page, 1) });
  const c1 = await page.evaluate(() => window.tessera.channels());
  if (!near(c0, c1)) console.log(`channels before: ${JSON.stringify(c0)}\nchannels after: ${JSON.stringify(c1)}`);
  let lit = 0;
  for (let i = 0; i < before.length; i += 4) if (before[i] + before[i + 1] + before[i + 2] > 24) lit++;
  lit /= SIZE * SIZE;
  const kept = c0 && c0.open && c1 && c1.open && near(c0, c1) && lit > 0.02 &&
    same(c1.channels.map((ch) => ch.visible), [true, false, true]) && same(c1.channels[0].color, [1, 1, 0]) &&
    same(c1.channels[2].window, [100, 2000]);
  await checkCase(c, page, what, before, after, kept,
    `${(100 * lit).toFixed(1)} % of the frame lit; channels ${c1 ? c1.channels.map((ch) => `${ch.label} ${ch.visible ? 'on' : 'off'} ` +
      `${ch.color.map((v) => v.toFixed(2)).join(',')} ${ch.window.join('..')}`).join('; ') : 'none'}`);
  noScriptErrors(c, what, logs);
  await page.close();
}

// What the page's Time panel shows: the slider's value and label, the Play
// button, whether the panel is shown.
const timePanel = (page) => page.evaluate(() => ({
  slider: document.getElementById('timePoint').value,
  label: document.getElementById('timeText').textContent,
  button: document.getElementById('timePlay').textContent,
  shown: !document.getElementById('time-controls').hidden,
}));
// Until the time series has shown `n` time points since its log began.
const logReaches = (page, n) => page.waitForFunction((k) => window.tessera.time().log.length >= k, n, { timeout: 60000 });
// The first place where `log` does not step by one (mod count), or ''.
function outOfOrder(log, count) {
  for (let i = 1; i < log.length; i++) if (log[i] !== (log[i - 1] + 1) % count) return `${log[i - 1]} then ${log[i]}`;
  return '';
}

// A store's t axis played over bricks (6 time points of 64³). Lost while
// playing: the restore comes back at the time point shown when the loss was
// seen, and playback goes on from it in order (none skipped). Then paused,
// refined, lost and restored: the same frame (>= 60 dB), the same time
// point, slider and label; played on from it in order.
async function brickedSeries(c, context, url, webgl) {
  const count = 6;
  const { page, logs } = await phonePage(context, url, `slices=0&layout=bricks&url=/data/cube6-webgl${webgl}.ome.zarr`, webgl);
  await page.waitForFunction(() => window.tessera.time().count === 6 && window.tessera.time().bricks === true,
    null, { timeout: 30000 }).catch(() => {});
  const what = `WebGL ${webgl}, a store's t axis over bricks`;
  const opened = await page.evaluate(() => window.tessera.time());
  c(`${what}: opens as a series of 6 over bricks`, opened.count === count && opened.bricks === true, JSON.stringify(opened));

  // Lost while playing.
  await page.evaluate(() => window.tessera.play(20));
  await logReaches(page, 3);
  const playing = await loseAndRestore(page, webgl, { settled: () => storeReopened(page, 1) });
  await logReaches(page, 4);  // three time points played since the restore
  const on = await page.evaluate(() => window.tessera.time());
  const panelPlaying = await timePanel(page);
  const order = outOfOrder(on.log, count);
  console.log(`${what}: lost while playing at time point ${playing.timeLost.shown} (played ${playing.timeLost.log.join(',')}); ` +
              `after the restore ${on.log.join(',')}; lost -> restored -> frame in ${playing.ms} ms`);
  c(`${what}: lost while playing, it comes back at the time point it showed and plays on in order`,
    playing.timeLost.playing && on.log[0] === playing.timeLost.shown && !order && on.playing && on.bricks === true &&
      on.count === count && panelPlaying.button === 'Pause',
    `lost at ${playing.timeLost.shown}, back at ${on.log[0]}, then ${on.log.slice(1).join(',')}${order ? ` (out of order: ${order})` : ''}; ` +
    `playing ${on.playing}, button "${panelPlaying.button}"`);

  // Lost while paused: the same frame, time point, slider and label.
  await page.evaluate(() => window.tessera.pause());
  await storeRefined(page, 1);
  const t0 = await page.evaluate(() => window.tessera.time());
  const p0 = await timePanel(page);
  const before = await pixelsOf(page);
  const after = await loseAndRestore(page, webgl, { settled: () => storeRefined(page, 2) });
  const t1 = await page.evaluate(() => window.tessera.time());
  const p1 = await timePanel(page);
  const kept = t1.shown === t0.shown && t1.count === count && t1.bricks === true && !t1.playing && same(p0, p1) &&
    p1.shown && p1.label === `${t0.shown} of ${count}` && p1.slider === String(t0.shown);
  await checkCase(c, page, `${what}, paused`, before, after, kept,
    `time point ${t0.shown} -> ${t1.shown}; panel ${JSON.stringify(p0)} -> ${JSON.stringify(p1)}`);
  // Played on from it.
  const from = t1.shown;
  await page.evaluate(() => window.tessera.play(20));
  await page.waitForFunction((k) => window.tessera.time().log.length >= k, 4, { timeout: 60000 }).catch(() => {});
  await page.evaluate(() => window.tessera.pause());
  const t2 = await page.evaluate(() => window.tessera.time());
  const error = await page.evaluate(() => window.tessera.error());
  const order2 = outOfOrder(t2.log, count);
  c(`${what}, paused: playing on after the restore goes on from time point ${from} in order`,
    t2.log[0] === from && t2.log.length >= 4 && !order2 && error === '',
    `${t2.log.join(',')}${order2 ? ` (out of order: ${order2})` : ''}; error "${error}"`);

  // A region of level 0 shown at time point 3, lost and restored: it comes
  // back at time point 3 (the same frame), not the first time point's; the
  // slider to time point 0 then shows another frame (the cube elsewhere).
  await page.evaluate(() => window.tessera.showTime(3));
  await page.evaluate(() => window.tessera.zarrRegion([4, 20, 20], [64, 44, 44]));
  await page.evaluate(() => window.tessera.setCamera(30, 20, 1));
  const r0 = await page.evaluate(() => ({ time: window.tessera.time().shown, dims: window.tessera.state().dims }));
  const regionBefore = await pixelsOf(page);
  const regionAfter = await loseAndRestore(page, webgl, { settled: () => storeReopened(page, 3) });
  const r1 = await page.evaluate(() => ({ time: window.tessera.time().shown, dims: window.tessera.state().dims }));
  await checkCase(c, page, `${what}, a region at time point 3`, regionBefore, regionAfter,
    r0.time === 3 && r1.time === 3 && same(r0.dims, [60, 24, 24]) && same(r1.dims, r0.dims),
    `time point ${r0.time} -> ${r1.time}, the view's volume ${r0.dims.join('x')} -> ${r1.dims.join('x')}`);
  await page.evaluate(() => window.tessera.setCamera(30, 20, 1));
  await page.evaluate(() => Promise.race([window.tessera.showTime(0), new Promise((r) => setTimeout(r, 30000))]));
  const at0 = await pixelsOf(page);
  const r2 = await page.evaluate(() => ({ time: window.tessera.time().shown, dims: window.tessera.state().dims }));
  const apart = psnrOf(regionBefore, at0);
  c(`${what}, a region at time point 3: time point 0's region differs from it (the restore was time point 3's)`,
    r2.time === 0 && same(r2.dims, r0.dims) && apart < 40,
    `time point ${r2.time}, ${r2.dims.join('x')}; time points 3 and 0 of the region: ${dB(apart)} apart`);
  noScriptErrors(c, what, logs);
  await page.close();
}

// A store with a small chunk cache (?zarrcache=0.75: 24 of its 32 KiB
// chunks), the head in 32³ chunks at a 64² view (its levels 1 and 2 fit the
// cache). A region of level 0 (8 chunks) is shown; then the slice views,
// read at level 0 through a crosshair away from it, fetch the 24 chunks of
// their slabs, and the cache's limit lets the oldest go: the region's. The
// restore then fetches exactly the chunks it needs that the cache let go
// (the region's, the coarsest level's if it went too), each once (the
// server's log), and shows the same region (>= 60 dB).
async function evictedRegion(c, context, url, tmp, webgl) {
  const name = smallName(webgl);
  const storeUrl = `/data/${name}`;
  const { page, logs } = await phonePage(context, url, `size=64&zarrcache=0.75&url=${storeUrl}`, webgl);
  const what = `WebGL ${webgl}, a store with a 0.75 MiB chunk cache, a region evicted by its limit`;
  await storeRefined(page);
  await page.evaluate(() => window.tessera.slices.setPanelPixels(1));  // the slices from the coarsest level
  const [rb, re] = [[16, 16, 16], [62, 62, 62]];
  await page.evaluate(([b, e]) => window.tessera.zarrRegion(b, e), [rb, re]);
  await page.evaluate(() => window.tessera.setCamera(35, 12, 1.25));
  const s0 = await page.evaluate(() => window.tessera.state());
  const e0 = await page.evaluate(() => window.tessera.slices.state());
  const before = await pixelsOf(page);
  // The slices at level 0 through (80, 100, 80): slabs in other chunks.
  await page.evaluate(() => window.tessera.slices.setCross(80, 100, 80));
  const servedBefore = served.paths.length;
  await page.evaluate(() => window.tessera.slices.setPanelPixels(512 * 512));
  await page.waitForFunction(() => Object.values(window.tessera.slices.state().panels).every((p) => p.frame && !p.frame.pending),
    null, { timeout: 30000 }).catch(() => {});
  await page.evaluate(() => window.tessera.slices.setPanelPixels(1));  // no more reads of them
  await page.waitForFunction(() => { const z = window.tessera.zarr(); return z.inFlight === 0 && z.queued === 0; },
    null, { timeout: 30000 });
  const slabFetches = served.paths.slice(servedBefore).filter((p) => p.startsWith(`${storeUrl}/0/`)).length;
  // The chunks the restore reads: the region's (level 0) and the coarsest
  // level's (the store's view opened again); which of them the cache holds.
  const storeDir = path.join(tmp, SMALL);
  const prefix = `/data/${STORE}/`;
  const regionKeys = chunkKeys(storeDir, rb, re).map((k) => k.slice(prefix.length));
  const levels = fs.readdirSync(storeDir).filter((d) => /^\d+$/.test(d)).map(Number);
  const top = Math.max(...levels);
  const topKeys = [];
  const walk = (rel) => {
    const full = path.join(storeDir, rel);
    if (fs.statSync(full).isDirectory()) fs.readdirSync(full).filter((f) => !f.startsWith('.')).forEach((f) => walk(`${rel}/${f}`));
    else topKeys.push(rel);
  };
  walk(String(top));
  const needed = [...regionKeys, ...topKeys];
  const heldKeys = await page.evaluate((ks) => ks.filter((k) => window.tessera.zarrHolds(k)), needed);
  const evicted = needed.filter((k) => !heldKeys.includes(k));
  const after = await loseAndRestore(page, webgl, { settled: () => storeReopened(page, 1) });
  const fetched = after.servedSince.filter((p) => p.startsWith(`${storeUrl}/`)).map((p) => p.slice(storeUrl.length + 1));
  const s1 = await page.evaluate(() => window.tessera.state());
  const e1 = await page.evaluate(() => window.tessera.slices.state());
  const exactly = same([...fetched].sort(), [...evicted].sort());
  const regionEvicted = regionKeys.filter((k) => evicted.includes(k)).length;
  console.log(`${what}: the slabs fetched ${slabFetches} level-0 chunks; of the ${needed.length} chunks the restore needs ` +
              `(region ${regionKeys.length}, level ${top} ${topKeys.length}) the cache had let ${evicted.length} go ` +
              `(${regionEvicted} of the region's); fetched after the loss: ${fetched.length} (${fetched.join(' ')})`);
  const kept = s1.webgl === webgl && e0.showing_region && e1.showing_region && same(e0.explore.region, e1.explore.region) &&
    same(s0.camera, s1.camera) && same(s0.window, s1.window);
  c(`${what}: the cache's limit let the region's chunks go, and the restore fetched exactly the chunks it needs that were let go, each once`,
    regionEvicted > 0 && exactly,
    `${regionEvicted}/${regionKeys.length} of the region's chunks let go, ${evicted.length} needed chunks in all; ` +
    `fetched ${fetched.length}: ${exactly ? 'exactly those' : `[${fetched.join(' ')}] vs let go [${evicted.join(' ')}]`}`);
  await checkCase(c, page, what, before, after, kept,
    `region ${JSON.stringify(e1.explore.region)}, shown ${e0.showing_region} -> ${e1.showing_region}`);
  noScriptErrors(c, what, logs);
  await page.close();
}

// ?zarrcache and ?stripshare out of range: each refused with its range, the
// store opened with the defaults.
async function cacheOutOfRange(c, context, url, webgl) {
  const { page } = await phonePage(context, url,
    `size=32&slices=0&zarrcache=100&stripshare=2&url=/data/cube6-webgl${webgl}.ome.zarr`, webgl);
  await page.waitForFunction(() => window.tessera.time().count === 6, null, { timeout: 30000 }).catch(() => {});
  const error = await page.evaluate(() => window.tessera.error());
  const count = await page.evaluate(() => window.tessera.time().count);
  c(`WebGL ${webgl}: ?zarrcache=100 and ?stripshare=2 are refused naming their ranges, the store opens with the defaults`,
    error === 'zarrcache 100 MiB: a store\'s chunk cache takes 0.0625 to 48 MiB (default 48); ' +
      'stripshare 2: a store\'s strips take 0.05 to 1 of the frame budget (default 0.25)' && count === 6,
    `error "${error}"; the store's series of ${count}`);
  await page.close();
}
