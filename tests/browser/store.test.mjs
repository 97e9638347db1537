// Browser test: OME-Zarr stores over fetch(): coarse to fine, regions, the
// grid view and slices read with bounded reads (fixture.mjs serves the site
// and launches Chromium). The tests run in order: the first writes the
// store the others read.
import { test } from 'node:test';
import fs from 'node:fs';
import path from 'node:path';
import {
  SIZE, PAGE_SAMPLING, CH2, check, served, decodePng, psnrAgainst, snapshot, changedFraction,
  differingPixels, openPage, withoutOverlays, chunkKeys, browserSuite,
} from './fixture.mjs';

// One Chromium for the file; checks(f) runs f (context, url, tmp, run) as a test.
const checks = browserSuite();

test('OME-Zarr ?url=: coarse first, refined to the native render; errors name the URL', checks(zarrStoreFromUrl));
test('OME-Zarr region: bounded reads, renders like `tessera render STORE --region`', checks(zarrRegionFromUrl));
test('OME-Zarr grid view: each block reads only its chunks', checks(zarrGridFromUrl));
test('OME-Zarr slices: level-0 slabs equal `tessera slice STORE`', checks(zarrSlicesFromUrl));
test('OME-Zarr f32 store: 16-bit bricks on WebGL 2 and 1 match the native render', checks(zarrF32Store));

// ?url= of an OME-Zarr store (issue 14): ch2 written by `tessera convert
// --compressor zlib`, served as a folder tree and read key by key with
// fetch(). The finest level's chunks are served 0.75 s late, so the page must
// show the coarser levels first; it then refines to what the native CLI
// renders of the same store (bricks layout, same profile): the same
// page-table cells per level, exactly (a brick whose own range the TF
// makes transparent is never uploaded, whichever of the native render's
// reader threads finishes first), and the same image. A chunk that
// always fails and a store that is not there give errors naming the URL;
// blosc and zstd stores read the same.
async function zarrStoreFromUrl(context, url, tmp, run) {
  if (!fs.existsSync(CH2)) { check(`OME-Zarr test needs ${CH2} (mricron-data)`, false); return; }
  const store = path.join(tmp, 'ch2.ome.zarr');
  run('convert', CH2, store, '--compressor', 'zlib');
  const nativePng = path.join(tmp, 'native-ch2-zarr.png');
  const native = JSON.parse(run('render', store, '--layout', 'bricks', '--tf', 'mr-default', '--size', `${SIZE}x${SIZE}`,
                                '--profile', 'webgl2', ...PAGE_SAMPLING, '--json', '--out', nativePng));
  const bytesUnder = (dir) => fs.readdirSync(dir, { recursive: true }).map((f) => path.join(dir, f))
    .filter((f) => fs.statSync(f).isFile() && !path.basename(f).startsWith('.')).reduce((n, f) => n + fs.statSync(f).size, 0);
  const finestBytes = bytesUnder(path.join(store, '0'));
  const chunkBytes = bytesUnder(store);
  served.delayMs = (p) => (p.startsWith('/data/ch2.ome.zarr/0/') && !p.endsWith('.zarray') ? 750 : 0);
  const before = { requests: served.requests, bytes: served.bytes };
  const { page, logs } = await openPage(context, url, `size=${SIZE}&url=/data/ch2.ome.zarr`);
  const coarse = await snapshot(page);
  const first = await page.evaluate(() => window.tessera.zarr());
  await page.waitForFunction(() => window.tessera.zarr().completeMs !== null, null, { timeout: 60000 });
  served.delayMs = () => 0;
  await withoutOverlays(page);
  const z = await page.evaluate(() => window.tessera.zarr());
  const fine = await snapshot(page);
  const firstCells = z.timeline[0].cells;
  const lastCells = z.last.cells_per_level;
  const nativeCells = native.bricks.cells_per_level;
  check('OME-Zarr ?url=: the first image comes from coarser levels only',
        first && first.firstImageMs !== null && firstCells[0] === 0 && firstCells.slice(1, -1).some((n) => n > 0),
        first ? `first image after ${first.firstImageMs.toFixed(0)} ms, cells per level ${JSON.stringify(firstCells)}` : 'no store');
  check('OME-Zarr ?url=: refines to the levels the native render uses, and the image changes',
        z.last.complete && !z.last.pending && JSON.stringify(lastCells) === JSON.stringify(nativeCells) &&
        changedFraction(coarse.pixels, fine.pixels) > 0.02,
        `complete after ${z.completeMs.toFixed(0)} ms in ${z.timeline.length} frames; cells ${JSON.stringify(lastCells)} ` +
        `(native ${JSON.stringify(nativeCells)}); ${(100 * changedFraction(coarse.pixels, fine.pixels)).toFixed(1)} % of pixels changed`);
  const m = await psnrAgainst(page, nativePng);
  check('OME-Zarr ?url=: the refined image matches the native render of the store (PSNR >= 50 dB)', m.psnr >= 50,
        m.error || `${m.psnr.toFixed(2)} dB`);
  const metadata = fs.readdirSync(store, { recursive: true }).filter((f) => path.basename(f).startsWith('.'))
    .reduce((n, f) => n + fs.statSync(path.join(store, f)).size, 0);
  check('OME-Zarr ?url=: read key by key, no chunk fetched twice',
        z.requests > 0 && z.bytes <= chunkBytes + metadata && served.bytes - before.bytes >= z.bytes,
        `${z.requests} requests, ${(z.bytes / 1048576).toFixed(2)} MiB fetched; chunks of all levels ` +
        `${(chunkBytes / 1048576).toFixed(2)} MiB, of the finest ${(finestBytes / 1048576).toFixed(2)} MiB`);
  console.log(`zarr: ch2 ${SIZE}x${SIZE}: first image ${z.firstImageMs.toFixed(0)} ms, refined ${z.completeMs.toFixed(0)} ms ` +
              `(finest chunks served 0.75 s late), ${z.requests} requests, ${z.bytes} bytes fetched, finest level ${finestBytes} bytes`);
  // Chromium logs every 404 (the store's all-zero chunks, left out as Zarr allows).
  const errors = logs.filter((l) => (l.startsWith('pageerror') || l.startsWith('error')) && !/status of 404/.test(l));
  check('no script errors on the OME-Zarr page', errors.length === 0, errors.join(' | '));
  await page.close();

  // A chunk that always answers 500: the page retries it, then completes
  // with the bricks over it at the coarser level and says which URL fails;
  // a store that is not there: an error naming its URL.
  served.fails = (p) => p === '/data/ch2.ome.zarr/0/1/1/1';
  const f = await openPage(context, url, `size=${SIZE}&url=/data/ch2.ome.zarr`);
  await f.page.waitForFunction(() => window.tessera.zarr().completeMs !== null, null, { timeout: 60000 });
  const zf = await f.page.evaluate(() => window.tessera.zarr());
  const statusText = await f.page.locator('#status').textContent();
  served.fails = () => false;
  check('OME-Zarr ?url= with a chunk that always fails: completes at the coarser level there, naming the URL',
        zf.last.complete && zf.last.failing > 0 && zf.last.cells_per_level[1] > 0 &&
        zf.last.last_error.includes(`${url}/data/ch2.ome.zarr/0/1/1/1`) && statusText.includes('0/1/1/1'),
        `${zf.last.failing} bricks failing, cells ${JSON.stringify(zf.last.cells_per_level)}: "${zf.last.last_error}"`);
  await f.page.close();
  const gone = `${url}/data/not-there.ome.zarr`;
  const g = await openPage(context, url, `size=64&url=${encodeURIComponent(gone)}`);
  const goneMsg = await g.page.evaluate(() => window.tessera.error());
  check('OME-Zarr ?url= of a store that is not there: a visible error naming the URL',
        goneMsg.includes(gone) && await g.page.locator('#error').isVisible(), `"${goneMsg}"`);
  await g.page.close();

  // blosc and zstd chunks, decoded in the page by numcodecs (Debian's
  // libblosc and libzstd are native only): the same voxels, the same image.
  // At 128² (the page refines a store at 256² for 7-20 s on SwiftShader;
  // what is tested here is the decoding, of every level it reads).
  const codecSize = 128;
  const codecPng = path.join(tmp, 'native-ch2-zarr-128.png');
  run('render', store, '--layout', 'bricks', '--tf', 'mr-default', '--size', `${codecSize}x${codecSize}`,
      '--profile', 'webgl2', ...PAGE_SAMPLING, '--out', codecPng);
  for (const codec of ['blosc', 'zstd']) {
    run('convert', CH2, path.join(tmp, `ch2-${codec}.ome.zarr`), '--compressor', codec);
    const p = await openPage(context, url, `size=${codecSize}&url=/data/ch2-${codec}.ome.zarr`);
    await p.page.waitForFunction(() => window.tessera.zarr().completeMs !== null || window.tessera.error() !== '',
                                 null, { timeout: 60000 });
    await withoutOverlays(p.page);
    const zc = await p.page.evaluate(() => window.tessera.zarr());
    const mc = await psnrAgainst(p.page, codecPng);
    const error = await p.page.evaluate(() => window.tessera.error());
    check(`OME-Zarr ?url= of a ${codec} store (decoded by numcodecs in the page) matches the native render (PSNR >= 50 dB)`,
          !error && zc.last && zc.last.complete && mc.psnr >= 50,
          error || mc.error || `${mc.psnr.toFixed(2)} dB, refined in ${zc.completeMs.toFixed(0)} ms, ${zc.requests} requests`);
    await p.page.close();
  }
}

// The bread-slice region of a served store (issue 15): the slice views show
// the store's coarsest level; a box picked there (slices.js's showRegion,
// what a drag calls) straddles chunk boundaries at level 0 and is read there
// with bounded reads. At 64 px the page
// refines the store only to level 2, so every level-0 request comes from the
// region: the requests while it is picked are exactly the level-0 chunks
// overlapping it (a 404 for an all-zero chunk counts), and its render
// matches `tessera render STORE --region` of the box (>= 45 dB).
async function zarrRegionFromUrl(context, url, tmp, run) {
  const store = path.join(tmp, 'ch2.ome.zarr');
  if (!fs.existsSync(store)) return;  // zarrStoreFromUrl said why
  const t = Date.now();
  const opened = served.paths.length;  // this page's requests from here
  const { page, logs } = await openPage(context, url, 'size=64&url=/data/ch2.ome.zarr');
  await page.waitForFunction(() => window.tessera.zarr().completeMs !== null, null, { timeout: 60000 });
  await withoutOverlays(page);
  // The slice views read level-0 slabs too (their chunks fetched before).
  await page.waitForFunction(() => Object.values(window.tessera.slices.state().panels).every((p) => p.frame && !p.frame.pending),
                             null, { timeout: 30000 }).catch(() => {});
  const fetchedBefore = new Set(served.paths.slice(opened).filter((p) => /^\/data\/ch2\.ome\.zarr\/0\/\d/.test(p)));
  const level0Before = fetchedBefore.size;
  const from = served.paths.length;
  const picked = await page.evaluate(() => window.tessera.slices.showRegion({ begin: [39, 98, 51], end: [99, 150, 79] }));
  const ex = await page.evaluate(() => window.tessera.slices.state().explore);
  if (!picked || !ex.region_level0) throw new Error(`picking a region of the store: ${await page.evaluate(() => window.tessera.error())}`);
  const { begin, end } = ex.region_level0;
  const expected = chunkKeys(store, begin, end);
  const keys = (await page.evaluate(() => window.tessera.zarr())).region.keys;
  const requested = served.paths.slice(from).filter((p) => p.startsWith('/data/ch2.ome.zarr/'));
  const s = await page.evaluate(() => window.tessera.state());
  const same = (a, b) => JSON.stringify([...new Set(a)].sort()) === JSON.stringify([...new Set(b)].sort());
  const missing = expected.filter((p) => !fetchedBefore.has(p));
  check('OME-Zarr region: only the level-0 chunks overlapping the box are fetched (those the slices had not), each once',
        same(requested, missing) && requested.length === missing.length &&
        s.dims.join('x') === [0, 1, 2].map((a) => end[a] - begin[a]).join('x'),
        `${requested.length} requests (${requested.map((p) => p.slice(19)).join(' ')}), expected ` +
        `${expected.length} (${expected.map((p) => p.slice(19)).join(' ')}); ${keys.length} keys asked; ` +
        `${level0Before} level-0 chunks fetched before (slices), ${missing.length} of the box's not; slices in the ${ex.dims.join('x')} voxels of level 0, ` +
        `picked ${JSON.stringify(ex.region)} -> level 0 ${JSON.stringify(ex.region_level0)}; 3D view ${s.dims.join('x')}`);
  const spec = [0, 1, 2].map((a) => `${begin[a]}:${end[a]}`).join(',');
  const refPng = path.join(tmp, 'native-zarr-region.png');
  // Oblique: from the front (elevation 0) the top face is seen edge-on and
  // one row of grazing rays differs between SwiftShader and llvmpipe.
  await page.evaluate(() => window.tessera.setCamera(30, 20, 1));
  run('render', store, '--region', spec, '--tf', 'mr-default', '--size', '64x64', '--profile', 'webgl2',
      '--azimuth', '30', '--elevation', '20', ...PAGE_SAMPLING, '--out', refPng);
  const m = await psnrAgainst(page, refPng);
  check(`OME-Zarr region: renders like \`tessera render STORE --region ${spec}\` (PSNR >= 45 dB)`, m.psnr >= 45,
        m.error || `${m.psnr.toFixed(2)} dB`);
  await page.evaluate(() => window.tessera.slices.overview());
  await page.evaluate(() => window.tessera.render());
  const back = await page.evaluate(() => window.tessera.zarr());
  const errors = logs.filter((l) => (l.startsWith('pageerror') || l.startsWith('error')) && !/status of 404/.test(l));
  const after = await page.evaluate(() => window.tessera.slices.state());
  // The region's red box over the store, by depth: seen through a clear TF.
  await page.evaluate(() => window.tessera.setTfJson(JSON.stringify({ name: 'clear', opacity_unit_length: 1,
    color: [{ x: 0, rgb: [0.2, 0.3, 0.9] }, { x: 1, rgb: [0.9, 0.9, 0.2] }], opacity: [{ x: 0, alpha: 0 }, { x: 1, alpha: 0 }] })));
  await page.evaluate(() => window.tessera.render());
  const red = await page.evaluate(() => {
    const p = window.tessera.pixels();
    let n = 0;
    for (let i = 0; i < p.length; i += 4) if (p[i] > 200 && p[i + 1] < 70 && p[i + 2] < 70) n++;
    return n;
  });
  check('OME-Zarr region: Overview returns to the store with the region as a red box, still picked in the slices; no script errors',
        back.last && back.last.complete && !after.showing_region && after.region && red > 20 && errors.length === 0,
        errors.join(' | ') || `region ${JSON.stringify(after.region)}, ${red} red pixels over the store (clear TF)`);
  await page.close();
  console.log(`     (OME-Zarr region: ${((Date.now() - t) / 1000).toFixed(1)} s)`);
}

// Grid view on a store (issue 15): each 2x2x2 block is read at level 0 with
// only its chunks fetched, and renders like `tessera render STORE --region`.
async function zarrGridFromUrl(context, url, tmp, run) {
  const store = path.join(tmp, 'ch2.ome.zarr');
  if (!fs.existsSync(store)) return;
  const t = Date.now();
  const { page, logs } = await openPage(context, url, 'size=64&url=/data/ch2.ome.zarr');
  await page.waitForFunction(() => window.tessera.zarr().completeMs !== null, null, { timeout: 60000 });
  await withoutOverlays(page);
  await page.evaluate(() => window.tessera.setCamera(30, 20, 1));
  // A frame of the store once its bricks for this view are all in, with
  // the volume transparent (opacity x 0): only lines drawn by depth show.
  const opacity = (x) => page.evaluate((v) => {
    const e = document.getElementById('opacity');
    e.value = v;
    e.dispatchEvent(new Event('input'));
  }, x);
  const settledStoreFrame = async () => {
    await page.waitForFunction(() => {
      const z = window.tessera.zarr();
      return z.last && z.last.complete && z.inFlight === 0 && z.queued === 0;
    }, null, { timeout: 30000 });
    await opacity(0);
    await page.evaluate(() => window.tessera.render());
    const pixels = await page.evaluate(() => window.tessera.slices.grid.framePixels());
    await opacity(1);
    await page.evaluate(() => window.tessera.render());
    return pixels;
  };
  const storeFrame = await settledStoreFrame();  // no block yet
  const same = (a, b) => JSON.stringify([...new Set(a)].sort()) === JSON.stringify([...new Set(b)].sort());
  const blockCheck = async (what, act) => {
    const from = served.paths.length;
    const ok = await page.evaluate(act);
    const g = await page.evaluate(() => window.tessera.slices.grid.state());
    if (!ok || !g.active || !g.block) {
      check(`OME-Zarr grid view: ${what}`, false, `${await page.evaluate(() => window.tessera.error())} ${JSON.stringify(g)}`);
      return;
    }
    const { begin, end } = g.block;
    const expected = chunkKeys(store, begin, end);
    const requested = served.paths.slice(from).filter((p) => /^\/data\/ch2\.ome\.zarr\/0\/\d/.test(p));
    const spec = [0, 1, 2].map((a) => `${begin[a]}:${end[a]}`).join(',');
    const refPng = path.join(tmp, 'native-zarr-grid.png');
    const cam = await page.evaluate(() => window.tessera.state().camera);
    run('render', store, '--region', spec, '--tf', 'mr-default', '--size', '64x64', '--profile', 'webgl2',
        '--azimuth', String(cam ? cam.azimuth : 30), '--elevation', String(cam ? cam.elevation : 20),
        '--zoom', String(cam ? cam.zoom : 1), ...PAGE_SAMPLING, '--out', refPng);
    const m = await psnrAgainst(page, refPng);
    check(`OME-Zarr grid view: ${what}: only the block's level-0 chunks fetched; renders like \`tessera render STORE --region ${spec}\` (>= 45 dB)`,
          requested.length <= expected.length && requested.every((p) => expected.includes(p)) && m.psnr >= 45,
          `${requested.length} chunk requests, ${expected.length} chunks overlap the block ` +
          `(${same(requested, expected) ? 'same set' : 'subset: others already fetched'}); ${m.error || `${m.psnr.toFixed(2)} dB`}`);
  };
  await blockCheck('enter', () => window.tessera.slices.grid.enter());
  await blockCheck('one move', async () => {
    const g = window.tessera.slices.grid.state();
    const i = g.moves.findIndex((mv) => mv.legal);
    return i >= 0 && (await window.tessera.slices.grid.move(i)) === 1;
  });
  // A move whose chunks keep failing (500 on every new level-0 request)
  // leaves the grid point and the block where they were. Moves that need no
  // new chunk (already fetched) succeed; the first that does fail is checked.
  served.fails = (p) => /^\/data\/ch2\.ome\.zarr\/0\/\d/.test(p);
  let failed = null;
  for (let attempt = 0; attempt < 6 && !failed; attempt++) {
    const before = await page.evaluate(() => window.tessera.slices.grid.state());
    const from = served.paths.length;
    const i = before.moves.findIndex((mv, k) => mv.legal && k !== 1);  // not Back: that block is fetched
    if (i < 0) break;
    const r = await page.evaluate((k) => window.tessera.slices.grid.move(k), i);
    const after = await page.evaluate(() => window.tessera.slices.grid.state());
    const tried = served.paths.slice(from).filter((p) => served.fails(p)).length;
    if (r !== 1) failed = { r, before, after, tried, error: await page.evaluate(() => window.tessera.error()) };
  }
  served.fails = () => false;
  const boxText = (b) => (b ? [0, 1, 2].map((a) => `${b.begin[a]}:${b.end[a]}`).join(',') : 'none');
  check('OME-Zarr grid view: a move whose chunks keep failing is undone: the grid point and block stay, the error names the chunk\'s URL',
        !!failed && failed.r === -1 && failed.tried > 0 && failed.after.active && failed.after.point.join() === failed.before.point.join() &&
        boxText(failed.after.block) === boxText(failed.before.block) && !failed.after.store_wanted &&
        /could not be read/.test(failed.after.note) && /ch2\.ome\.zarr\/0\//.test(failed.error),
        failed ? `${failed.tried} failing requests; point (${failed.before.point.join(', ')}) -> (${failed.after.point.join(', ')}), ` +
          `block ${boxText(failed.before.block)} -> ${boxText(failed.after.block)}; "${failed.after.note}"; error "${failed.error.slice(0, 120)}"`
          : 'no move needed a new chunk');

  // Back at the store's overview: the block's cyan box and the crosshair
  // are drawn over the store's frames too.
  await page.evaluate(() => window.tessera.slices.grid.leave());
  await page.evaluate(() => window.tessera.render());
  const frameBack = await settledStoreFrame();
  const overStore = await page.evaluate(() => {
    const o = window.tessera.slices.overlayPixels();  // the crosshair marker's canvas
    let marked = 0;
    for (let i = 3; i < o.length; i += 4) if (o[i] > 0) marked++;
    return { marked, active: window.tessera.slices.grid.state().active, camera: window.tessera.state().camera };
  });
  // The same view as before entering (the store's camera is restored), so
  // the frames differ by the block's lines only.
  const boxed = differingPixels(storeFrame, frameBack, 8);
  let cyan = 0;
  for (let i = 0; i < frameBack.length; i += 4) if (frameBack[i] < 110 && frameBack[i + 1] > 170 && frameBack[i + 2] > 190) cyan++;
  const cam = overStore.camera;
  check('OME-Zarr grid view: back over the store at its own camera, the last block is a cyan box in its frames and the crosshair is projected into them',
        !overStore.active && cam.azimuth === 30 && cam.elevation === 20 && cam.zoom === 1 && boxed > 32 && cyan > 32 && overStore.marked > 8,
        `camera ${cam.azimuth}/${cam.elevation}/${cam.zoom}; ${boxed} pixels drawn by the block's box (${cyan} cyan), ${overStore.marked} crosshair pixels over the frame`);
  const errors = logs.filter((l) => (l.startsWith('pageerror') || l.startsWith('error')) && !/status of (404|500)/.test(l));
  check('OME-Zarr grid view: leaving returns to the store; no script errors', errors.length === 0, errors.join(' | '));
  await page.close();
  console.log(`     (OME-Zarr grid view: ${((Date.now() - t) / 1000).toFixed(1)} s)`);
}

// An OME-Zarr store's slice views at native resolution: with panels large
// enough for level 0 the three slices through the crosshair are read as
// level-0 slabs (only the chunks they cut are fetched; the coarsest level
// stands in meanwhile) and equal `tessera slice STORE`; moving the
// crosshair reads the new slab.
async function zarrSlicesFromUrl(context, url, tmp, run) {
  const store = path.join(tmp, 'ch2.ome.zarr');
  if (!fs.existsSync(store)) return;
  const t = Date.now();
  const opened = served.paths.length;
  // A 64 px 3D view refines only to level 2: every level-0 request is the
  // slices', read at level 0 as for panels of 512² pixels.
  const { page, logs } = await openPage(context, url, 'size=64&url=/data/ch2.ome.zarr');
  await page.waitForFunction(() => window.tessera.zarr().completeMs !== null, null, { timeout: 60000 });
  await page.evaluate(() => window.tessera.slices.setPanelPixels(512 * 512));
  const meta = JSON.parse(fs.readFileSync(path.join(store, '0', '.zarray'), 'utf8'));
  const chunk = [...meta.chunks].reverse();  // x, y, z
  const dims = [...meta.shape].reverse();
  const slabChunks = (axis, index) => {
    const keys = [];
    const n = dims.map((d, a) => Math.ceil(d / chunk[a]));
    for (let cz = 0; cz < n[2]; cz++) for (let cy = 0; cy < n[1]; cy++) for (let cx = 0; cx < n[0]; cx++) {
      if ([cx, cy, cz][axis] === Math.floor(index / chunk[axis])) keys.push(`/data/ch2.ome.zarr/0/${cz}/${cy}/${cx}`);
    }
    return keys;
  };
  const decode = (png) => decodePng(page, png);
  const compare = async (what) => {
    await page.waitForFunction(() => Object.values(window.tessera.slices.state().panels).every((p) => p.frame && !p.frame.pending),
                               null, { timeout: 30000 }).catch(() => {});
    const st = await page.evaluate(() => window.tessera.slices.state());
    const rows = [];
    let ok = true;
    for (const [plane, p] of Object.entries(st.panels)) {
      const png = path.join(tmp, `zarr-slice-${plane}.png`);
      run('slice', store, '--axis', 'xyz'[p.axis], '--index', String(p.index), '--out', png);
      const ref = await decode(png);
      const shown = await page.evaluate((q) => window.tessera.slices.imagePixels(q), plane);
      const f = p.frame;
      const same = f.image_width === ref.width && f.image_height === ref.height && shown.length === ref.data.length;
      const differing = same ? differingPixels(shown, ref.data, 0) : -1;
      ok = ok && f.level === 0 && !f.pending && differing === 0;
      rows.push(`${plane} ${'xyz'[p.axis]}=${p.index}: level ${f.level}${f.pending ? ' (pending)' : ''}, ${f.image_width}x${f.image_height}, ${differing} pixels differ`);
    }
    return { ok, text: rows.join('; '), st };
  };
  const first = await compare('open');
  const level0 = served.paths.slice(opened).filter((p) => /^\/data\/ch2\.ome\.zarr\/0\/\d/.test(p));
  const cross = first.st.cross;
  const allowed = new Set([0, 1, 2].flatMap((a) => slabChunks(a, cross[a])));
  check('OME-Zarr slices: the three slices through the crosshair are level-0 slabs, identical to `tessera slice STORE`; only the chunks they cut are fetched, each once',
        first.ok && level0.length > 0 && level0.every((p) => allowed.has(p)) && new Set(level0).size === level0.length,
        `${first.text}; ${level0.length} level-0 requests (${new Set(level0).size} distinct), all among the ${allowed.size} chunks the slabs cut: ${level0.every((p) => allowed.has(p))}`);
  // Another axial slice, in another chunk layer: its slab is read.
  const z = Math.min(dims[2] - 1, cross[2] + chunk[2]);
  const from = served.paths.length;
  await page.evaluate((v) => window.tessera.slices.setCross(...v), [cross[0], cross[1], z]);
  const moved = await compare('moved');
  const asked = served.paths.slice(from).filter((p) => /^\/data\/ch2\.ome\.zarr\/0\/\d/.test(p));
  const axialAxis = 2;
  check('OME-Zarr slices: moving the crosshair to another chunk layer reads that slab (only its chunks), identical to `tessera slice STORE`',
        moved.ok && asked.length > 0 && asked.every((p) => slabChunks(axialAxis, z).includes(p) && !level0.includes(p)),
        `${moved.text}; ${asked.length} new level-0 requests, none fetched before`);
  const value = await page.evaluate(() => document.getElementById('crosshairInfo').textContent);
  const errors = logs.filter((l) => (l.startsWith('pageerror') || l.startsWith('error')) && !/status of 404/.test(l));
  check('OME-Zarr slices: no script errors', errors.length === 0, errors.join(' | ') || value);
  await page.close();
  console.log(`     (OME-Zarr slices: ${((Date.now() - t) / 1000).toFixed(1)} s)`);
}

// An f32 store (inia19, 0..383) streams in 16-bit bricks: R16 or two bytes
// (RG8) on WebGL 2, two bytes (LUMINANCE_ALPHA) on WebGL 1, recombined in the
// shader. The page refines to what the native CLI renders of the store with
// the same profile.
async function zarrF32Store(context, url, tmp, run) {
  const inia = path.join(path.dirname(CH2), 'inia19-t1-brain.nii.gz');
  if (!fs.existsSync(inia)) { check(`f32 store test needs ${inia} (mricron-data)`, false); return; }
  const store = path.join(tmp, 'inia.ome.zarr');
  run('convert', inia, store, '--chunk', '64');
  for (const [gl, profile] of [[2, 'webgl2'], [1, 'webgl1']]) {
    const nativePng = path.join(tmp, `native-inia-${profile}.png`);
    const native = JSON.parse(run('render', store, '--layout', 'bricks', '--tf', 'mr-default', '--size', `${SIZE}x${SIZE}`,
                                  '--profile', profile, ...PAGE_SAMPLING, '--json', '--out', nativePng));
    const { page, logs } = await openPage(context, url, `size=${SIZE}&url=/data/inia.ome.zarr${gl === 1 ? '&webgl=1' : ''}`);
    await page.waitForFunction(() => window.tessera.zarr() && window.tessera.zarr().completeMs !== null, null, { timeout: 60000 });
    await withoutOverlays(page);
    const m = await psnrAgainst(page, nativePng);
    const atlas = (native.plan_reason.match(/brick (\S+)/) || [])[1] || native.plan_reason;
    check(`OME-Zarr f32 store on WebGL ${gl}: the refined image matches the native render (PSNR >= 50 dB)`, m.psnr >= 50,
          m.error || `${m.psnr.toFixed(2)} dB; native plan: ${atlas}`);
    const errors = logs.filter((l) => (l.startsWith('pageerror') || l.startsWith('error')) && !/status of 404/.test(l));
    check(`no script errors on the f32 store page (WebGL ${gl})`, errors.length === 0, errors.join(' | '));
    await page.close();
  }
}
