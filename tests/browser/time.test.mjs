// Browser test: a 4-D NIfTI dropped on the page plays back (time.test.mjs of
// tests/browser; fixture.mjs serves the site and launches Chromium). Each
// time point the page shows equals `tessera render --time T` of the same
// file; playback shows every time point in order (none skipped, a late one
// shown late), reading one time point ahead per animation frame (the page
// has no threads: session/TimeSeries.h, Reading::OnPump).
// A store's t axis over bricks (?layout=bricks, or a level 0 too large for
// in-core) plays the same way, each time point drawn whole from its own
// bricks before the next is shown (a late one counted), and a store's
// channels with a t axis play together. A store's slice views show the
// time point the 3D view shows: at every frame of a playback over bricks,
// and after it, they equal `tessera slice STORE --time T` of that time
// point (the store opened at T), pixel for pixel; in core too. A region
// and a grid block picked at a time point are that time point's (as
// `tessera render STORE --time T --region BOX`) and follow the time point
// shown, by the slider and in playback, over bricks and in core.
// With TESSERA_BENCH=1 it also plays a 20-time-point 256^3 series at
// 512x512 (a 4-D NIfTI, a store in core and a store over bricks) and
// prints the rate reached.
import { test } from 'node:test';
import { execFile, execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import {
  bench, check, cli, root, served, psnrAgainst, openPage, openThroughPicker, withoutOverlays, browserSuite,
} from './fixture.mjs';

const checks = browserSuite();

test('a 4-D NIfTI: every time point as the CLI renders it, playback in order', checks(timeSeries));
test('an OME-Zarr store with a t axis (?url=): every time point drawn as the CLI renders it, in order', checks(storeSeries));
test('an OME-Zarr store with a t axis over bricks (?layout=bricks): each time point drawn whole from its own bricks, in order',
  checks(bricksSeries));
test('an OME-Zarr store with channels and a t axis: the channels play together, each frame as the CLI renders it',
  checks(channelSeries));
test('an OME-Zarr store with a t axis, over bricks and in core: a region and a grid block picked at time point 3 are time point 3\'s, ' +
     'and follow the time point shown (slider and playback)', checks(storeRegions));
test('benchmark: 20 time points of 256^3 at 512x512 (TESSERA_BENCH=1)', { skip: !bench }, checks(benchmark));
test('benchmark: an OME-Zarr store of 20 time points of 256^3 at 512x512 (TESSERA_BENCH=1)', { skip: !bench },
  checks((...a) => storeBenchmark(...a, 'in core')));
test('benchmark: an OME-Zarr store of 20 time points of 256^3 at 512x512 over bricks (TESSERA_BENCH=1)', { skip: !bench },
  checks((...a) => storeBenchmark(...a, 'bricks')));

// A 4-D NIfTI of `count` time points made from the 3-D file `from` (as
// `tessera convert` writes it): time point t is its voxels shifted by
// `shift * t` along x (wrapping), so every time point has the same values
// (and window) in another place.
function writeSeries(from, to, count, shift) {
  const bytes = fs.readFileSync(from);
  const offset = Math.round(bytes.readFloatLE(108));
  const [nx, ny, nz] = [1, 2, 3].map((i) => bytes.readInt16LE(40 + 2 * i));
  if (bytes.readInt16LE(70) !== 2) throw new Error(`${from}: expected u8 voxels`);
  const first = bytes.subarray(offset, offset + nx * ny * nz);
  const header = Buffer.from(bytes.subarray(0, offset));
  header.writeInt16LE(4, 40);  // dim[0]
  header.writeInt16LE(count, 48);  // dim[4]
  const parts = [header];
  for (let t = 0; t < count; t++) {
    const v = Buffer.alloc(first.length);
    const s = (shift * t) % nx;
    for (let row = 0; row < ny * nz; row++) {
      for (let x = 0; x < nx; x++) v[row * nx + ((x + s) % nx)] = first[row * nx + x];
    }
    parts.push(v);
  }
  fs.writeFileSync(to, Buffer.concat(parts));
}

// Plays until `advances` time points were shown (or `limitMs`), then pauses:
// the sequence drawn, the rate reached and the late frames.
async function play(page, fps, advances, limitMs) {
  return page.evaluate(async ({ fps, advances, limitMs }) => {
    const t = window.tessera;
    const start = performance.now();
    const before = t.time().log.length;
    const { advances: advancesBefore, late: lateBefore } = t.time();
    t.play(fps);
    while (t.time().log.length - before < advances && performance.now() - start < limitMs) {
      await new Promise((r) => setTimeout(r, 20));
    }
    const seconds = (performance.now() - start) / 1000;
    t.pause();
    const s = t.time();
    return { log: s.log.slice(before - 1), late: s.late - lateBefore, advances: s.advances - advancesBefore,
      seconds, error: t.error() };
  }, { fps, advances, limitMs });
}

function inOrder(log, count) {
  for (let i = 1; i < log.length; i++) if (log[i] !== (log[i - 1] + 1) % count) return `skipped at ${i}: ${log[i - 1]} then ${log[i]}`;
  return '';
}

async function timeSeries(context, url, tmp, run) {
  const SIZE = 256;
  const count = 6;
  run('convert', 'gen:sphere:40', path.join(tmp, 'sphere.nii'));
  const series = path.join(tmp, 'series.nii');
  writeSeries(path.join(tmp, 'sphere.nii'), series, count, 5);
  for (const t of [0, 3, 5]) {
    run('render', series, '--time', String(t), '--tf', 'mr-default', '--size', `${SIZE}x${SIZE}`,
        '--profile', 'webgl2', '--preintegrate', 'off', '--out', path.join(tmp, `t${t}.png`));
  }

  const { page, logs } = await openPage(context, url, `size=${SIZE}`);
  await withoutOverlays(page);
  const opened = await openThroughPicker(page, [series], 'series.nii');
  const s = await page.evaluate(() => window.tessera.time());
  const panel = await page.evaluate(() => !document.getElementById('time-controls').hidden);
  check('a 4-D NIfTI opens as a time series of 6 with the Time panel shown',
        !opened.error && s.count === count && s.shown === 0 && panel, opened.error || JSON.stringify(s));

  // Every time point asked for is drawn as the CLI draws it, and not as another.
  for (const t of [3, 5, 0]) {
    const shown = await page.evaluate((t) => window.tessera.showTime(t), t);
    const own = await psnrAgainst(page, path.join(tmp, `t${t}.png`));
    const other = await psnrAgainst(page, path.join(tmp, `t${t === 3 ? 5 : 3}.png`));
    check(`time point ${t} equals \`tessera render --time ${t}\` (PSNR >= 50 dB) and not another time point`,
          shown === t && own.psnr >= 50 && other.psnr < own.psnr - 10,
          own.error || `${own.psnr.toFixed(2)} dB (another: ${other.psnr.toFixed(2)} dB)`);
  }

  // Playback: two loops and more, every time point in order.
  const p = await play(page, 30, 2 * count + 1, 60000);
  const order = inOrder(p.log, count);
  check('playback shows every time point in order, none skipped (2 loops)',
        p.log.length >= 2 * count + 2 && !order,
        `${order || p.log.join(',')}; ${(p.advances / p.seconds).toFixed(1)} time points/s of 30, ${p.late} late frames`);
  const after = await page.evaluate(() => window.tessera.time());
  check('paused: the time point stays', !after.playing &&
        (await page.evaluate(() => new Promise((r) => setTimeout(() => r(window.tessera.time().shown), 300)))) === after.shown,
        JSON.stringify(after));
  // A time point out of range is refused with the count, the page still usable.
  const refused = await page.evaluate(() => {
    try {
      window.tessera.viewer().showTimePoint(6);
      return '';
    } catch (e) {
      return e.message;
    }
  });
  check('a time point past the last is refused naming the range', /0\.\.5/.test(refused), refused);
  check('no page errors', !logs.some((l) => l.startsWith('pageerror')), logs.filter((l) => l.startsWith('pageerror')).join('; '));
  await page.close();
}

async function benchmark(context, url, tmp, run) {
  const count = 20;
  run('convert', 'gen:shepp-logan:256', path.join(tmp, 'phantom.nii'));
  const series = path.join(tmp, 'series256.nii');
  writeSeries(path.join(tmp, 'phantom.nii'), series, count, 7);
  const { page } = await openPage(context, url, 'size=512');
  const opened = await openThroughPicker(page, [series], 'series256.nii');
  check('the 20 x 256^3 series opens', !opened.error, opened.error);
  for (const fps of [2, 10]) {
    const p = await play(page, fps, count, 120000);
    const order = inOrder(p.log, count);
    const rate = p.advances / p.seconds;
    console.log(`bench: web page, 20 x 256^3 u8 at 512x512, asked ${fps}/s: ${rate.toFixed(2)} time points/s, ` +
                `${p.advances} shown in ${p.seconds.toFixed(1)} s, ${p.late} late frames, ${order || 'none skipped'}` +
                (p.error ? `; error: ${p.error}` : ''));
    check(`asked ${fps}/s: every time point shown in order`, !order && p.advances >= Math.min(count, 2), order);
  }
  await page.close();
}

// An OME-NGFF store of `count` time points of n^3 written by zarr-python
// (tests/zarr/make_time_store.py): a dim shell and a bright cube whose x
// position moves with t.
function writeStore(store, n, count, channels = 1) {
  execFileSync('/usr/bin/python3', [path.join(root, 'tests/zarr/make_time_store.py'), store, String(n), String(count),
    String(channels)]);
}

// `tessera render STORE --time T` for each T, two at a time (`look`: the
// options, the TF mr-default unless it names one; `tag`: the PNGs' prefix).
async function renderTimes(store, times, size, tmp, look = ['--tf', 'mr-default'], tag = 'store') {
  const one = (t) => new Promise((resolve, reject) => execFile(cli, ['render', store, '--time', String(t), ...look,
    '--size', `${size}x${size}`, '--profile', 'webgl2', '--preintegrate', 'off', '--out', path.join(tmp, `${tag}-t${t}.png`)],
  (e) => (e ? reject(e) : resolve())));
  for (let i = 0; i < times.length; i += 2) await Promise.all(times.slice(i, i + 2).map(one));
}

// The cube's x on screen: the mean column of the pixels brighter than the
// shell (R+G+B > 500), in the page; -1 when there are none.
const MARKER = 500;

// Plays `advances` time points at `fps` with whole frames (no progressive
// previews) and samples every frame the page draws, right after it is
// drawn (an animation-frame callback after the page's own): the time point
// it says it shows, the cube's column, and its PSNR against the reference
// render of that time point when the test has one (window.__refs).
async function playSampled(page, fps, advances, limitMs) {
  return page.evaluate(async ({ fps, advances, limitMs, MARKER }) => {
    const T = window.tessera;
    T.setProgressive(false);
    const frames = [];
    const start = performance.now();
    const before = T.time().log.length;
    const { advances: advancesBefore, late: lateBefore } = T.time();
    const framesBefore = T.frames();
    let drawn = T.frames();
    T.play(fps);
    await new Promise((resolve) => {
      const tick = () => {
        if (T.frames() !== drawn) {
          drawn = T.frames();
          const t = T.time().shown;
          const px = T.pixels();
          const w = Math.round(Math.sqrt(px.length / 4));
          let n = 0;
          let sx = 0;
          for (let i = 0; i < px.length; i += 4) {
            if (px[i] + px[i + 1] + px[i + 2] > MARKER) { n++; sx += (i / 4) % w; }
          }
          const z = T.zarr();
          // A store drawn over bricks: whether this frame has every brick
          // its view wants (else it shows coarser ones while they come).
          const f = { t, x: n ? sx / n : -1, complete: !(z && z.last) || !!z.last.complete };
          // The slice views (when the test loaded their references,
          // window.__sliceRefs[t] of window.__slicePlane): the pixels that
          // differ from time point t's, and whether the slice is pending.
          const sliceRef = window.__sliceRefs && window.__sliceRefs[t];
          if (sliceRef) {
            const plane = window.__slicePlane;
            const shown = T.slices.imagePixels(plane);
            let differ = shown.length === sliceRef.length ? 0 : -1;
            for (let i = 0; differ >= 0 && i < shown.length; i += 4) {
              if (shown[i] !== sliceRef[i] || shown[i + 1] !== sliceRef[i + 1] || shown[i + 2] !== sliceRef[i + 2]) differ++;
            }
            f.sliceDiffer = differ;
            f.slicePending = !!T.slices.state().panels[plane].frame.pending;
          }
          const ref = window.__refs && window.__refs[t];
          if (ref && ref.length === px.length) {
            let sum = 0;
            for (let i = 0; i < px.length; i += 4) for (let k = 0; k < 3; k++) { const d = px[i + k] - ref[i + k]; sum += d * d; }
            const mse = sum / (px.length / 4 * 3);
            f.psnr = mse === 0 ? 999 : 10 * Math.log10(255 * 255 / mse);
          }
          frames.push(f);
        }
        if (T.time().log.length - before >= advances || performance.now() - start >= limitMs) resolve();
        else requestAnimationFrame(tick);
      };
      requestAnimationFrame(tick);
    });
    const seconds = (performance.now() - start) / 1000;
    T.pause();
    T.setProgressive(true);
    const s = T.time();
    return { frames, log: s.log.slice(before - 1), late: s.late - lateBefore, advances: s.advances - advancesBefore,
      drawn: T.frames() - framesBefore, seconds, error: T.error() };
  }, { fps, advances, limitMs, MARKER });
}

// The references' PNGs decoded in the page, as window.__refs[t].
async function loadRefs(page, files) {
  await page.evaluate(async ({ pngs, decode }) => {
    window.__refs = await (new Function(`return ${decode}`)())(pngs);
  }, { pngs: base64Of(files), decode: decodeInPage.toString() });
}

// The cube's column in a reference PNG (decoded in the page).
async function markerOf(page, t) {
  return page.evaluate(({ t, MARKER }) => {
    const px = window.__refs[t];
    const w = Math.round(Math.sqrt(px.length / 4));
    let n = 0;
    let sx = 0;
    for (let i = 0; i < px.length; i += 4) if (px[i] + px[i + 1] + px[i + 2] > MARKER) { n++; sx += (i / 4) % w; }
    return n ? sx / n : -1;
  }, { t, MARKER });
}

// `tessera slice STORE --time T` through the page's crosshair for each
// [t, plane] asked (PNG paths by `${t}-${plane}`), two at a time.
async function sliceRefs(store, st, wanted, tmp, tag) {
  const out = {};
  const one = ([t, plane]) => new Promise((resolve, reject) => {
    const p = st.panels[plane];
    const png = path.join(tmp, `${tag}-slice-t${t}-${plane}.png`);
    out[`${t}-${plane}`] = png;
    execFile(cli, ['slice', store, '--time', String(t), '--axis', 'xyz'[p.axis], '--index', String(p.index), '--out', png],
      (e) => (e ? reject(e) : resolve()));
  });
  for (let i = 0; i < wanted.length; i += 2) await Promise.all(wanted.slice(i, i + 2).map(one));
  return out;
}

// In the page: each of `pngs` ({key: base64}) decoded to RGBA pixels.
async function decodeInPage(pngs) {
  const out = {};
  for (const [key, b64] of Object.entries(pngs)) {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width;
    c.height = img.height;
    const ctx = c.getContext('2d');
    ctx.drawImage(img, 0, 0);
    out[key] = ctx.getImageData(0, 0, c.width, c.height).data;
  }
  return out;
}
const base64Of = (files) => Object.fromEntries(Object.entries(files).map(([k, f]) => [k, fs.readFileSync(f).toString('base64')]));

// The page's slice views (`planes`) against `tessera slice STORE --time t`
// (refs[`${t}-${plane}`]) once none is pending, compared in the page: whether
// each is read at level 0 and identical, and how many of its pixels differ
// from time point `other`'s (where the data differ, it must not be that
// one's).
async function slicesAgainst(page, refs, t, other, planes = ['axial', 'coronal', 'sagittal']) {
  await page.waitForFunction(() => Object.values(window.tessera.slices.state().panels).every((p) => p.frame && !p.frame.pending),
    null, { timeout: 30000 }).catch(() => {});
  const files = {};
  for (const q of planes) {
    files[`${t}-${q}`] = refs[`${t}-${q}`];
    if (refs[`${other}-${q}`]) files[`${other}-${q}`] = refs[`${other}-${q}`];
  }
  const r = await page.evaluate(async ({ pngs, t, other, planes, decode }) => {
    const images = await (new Function(`return ${decode}`)())(pngs);
    const differ = (a, b) => {
      if (a.length !== b.length) return -1;
      let n = 0;
      for (let i = 0; i < a.length; i += 4) if (a[i] !== b[i] || a[i + 1] !== b[i + 1] || a[i + 2] !== b[i + 2]) n++;
      return n;
    };
    const st = window.tessera.slices.state();
    return { time: st.explore.time, planes: planes.map((q) => {
      const shown = window.tessera.slices.imagePixels(q);
      const ref = images[`${t}-${q}`];
      const o = images[`${other}-${q}`];
      return { plane: q, axis: st.panels[q].axis, index: st.panels[q].index, level: st.panels[q].frame.level,
        pending: !!st.panels[q].frame.pending, differ: differ(shown, ref),
        fromOther: o ? { shown: differ(shown, o), refs: differ(ref, o) } : null };
    }) };
  }, { pngs: base64Of(files), t, other, planes, decode: decodeInPage.toString() });
  let ok = r.time === t;
  const rows = r.planes.map((p) => {
    ok = ok && p.level === 0 && !p.pending && p.differ === 0 && (!p.fromOther || p.fromOther.shown === p.fromOther.refs);
    return `${p.plane} ${'xyz'[p.axis]}=${p.index}: level ${p.level}${p.pending ? ' (pending)' : ''}, ` +
      `${p.differ} pixels differ from time point ${t}'s` +
      (p.fromOther ? `, ${p.fromOther.shown} from time point ${other}'s (the references differ in ${p.fromOther.refs})` : '');
  });
  return { ok, text: `slices at time point ${r.time}: ${rows.join('; ')}` };
}

// Reference PNGs decoded in the page as window.__sliceRefs[t] (`plane`'s).
async function loadSliceRefs(page, refs, times, plane) {
  const files = Object.fromEntries(times.map((t) => [t, refs[`${t}-${plane}`]]));
  await page.evaluate(async ({ pngs, plane, decode }) => {
    window.__sliceRefs = await (new Function(`return ${decode}`)())(pngs);
    window.__slicePlane = plane;
  }, { pngs: base64Of(files), plane, decode: decodeInPage.toString() });
}

// Every frame drawn checked: the cube where the time point it is labelled
// with puts it (within a third of the step between time points, the
// expected column interpolated between the references'), so no frame
// shows another time point's (stale) volume; the frames of referenced time
// points equal the CLI's render (PSNR >= 40 dB).
function checkFrames(p, count, expectedX, step) {
  const wrong = p.frames.filter((f) => Math.abs(f.x - expectedX(f.t)) > step / 3);
  const referenced = p.frames.filter((f) => f.psnr !== undefined);
  const low = referenced.filter((f) => f.psnr < 40);
  const shown = new Set(p.frames.map((f) => f.t));
  return { wrong, referenced, low, shown,
    minPsnr: referenced.length ? Math.min(...referenced.map((f) => f.psnr)) : NaN, all: shown.size === count };
}

async function storeSeries(context, url, tmp, run) {
  const SIZE = 128;
  const count = 20;
  const store = path.join(tmp, 'cube.ome.zarr');
  const started = Date.now();
  writeStore(store, 64, count);
  const refTimes = [0, 10, 19];
  await renderTimes(store, refTimes, SIZE, tmp);
  const servedBefore = served.paths.length;
  const { page, logs } = await openPage(context, url, `size=${SIZE}&url=/data/cube.ome.zarr`);
  await withoutOverlays(page);
  const s = await page.evaluate(() => window.tessera.time());
  const panel = await page.evaluate(() => !document.getElementById('time-controls').hidden);
  check('a store with a t axis of 20 opens as a time series (level 0 fits: read in core) with the Time panel shown',
        s.count === count && s.shown === 0 && panel, JSON.stringify(s) + (await page.evaluate(() => window.tessera.error())));
  await loadRefs(page, Object.fromEntries(refTimes.map((t) => [t, path.join(tmp, `store-t${t}.png`)])));
  const refX = {};
  for (const t of refTimes) refX[t] = await markerOf(page, t);
  const expectedX = (t) => {
    let i = 0;
    while (i < refTimes.length - 2 && t > refTimes[i + 1]) i++;
    const [a, b] = [refTimes[i], refTimes[i + 1]];
    return refX[a] + (refX[b] - refX[a]) * (t - a) / (b - a);
  };
  const step = Math.abs(refX[19] - refX[0]) / (count - 1);
  check('the cube is seen in every reference, a column per time point apart',
        refTimes.every((t) => refX[t] >= 0) && step > 1, JSON.stringify(refX));

  // The slider's path: a time point asked for is drawn as the CLI draws it.
  const shown = await page.evaluate(() => window.tessera.showTime(10));
  const own = await psnrAgainst(page, path.join(tmp, 'store-t10.png'));
  const other = await psnrAgainst(page, path.join(tmp, 'store-t19.png'));
  check('store time point 10 equals `tessera render STORE --time 10` (PSNR >= 40 dB) and not time point 19',
        shown === 10 && own.psnr >= 40 && other.psnr < own.psnr - 10,
        own.error || `${own.psnr.toFixed(2)} dB (time point 19: ${other.psnr.toFixed(2)} dB)`);
  // Its axial slice view (read at level 0): time point 10's, not the first
  // one's (all three over bricks, below).
  await page.evaluate(() => window.tessera.slices.setPanelPixels(512 * 512));
  const st = await page.evaluate(() => window.tessera.slices.state());
  const refs = await sliceRefs(store, st, [[10, 'axial'], [0, 'axial']], tmp, 'store');
  const sl = await slicesAgainst(page, refs, 10, 0, ['axial']);
  check('in core, the axial slice view at time point 10 equals `tessera slice STORE --time 10` (identical), not time point 0\'s',
        sl.ok, sl.text);

  // Playback: a loop and more, every frame drawn sampled.
  const p = await playSampled(page, 20, count + 1, 60000);
  const order = inOrder(p.log, count);
  const c = checkFrames(p, count, expectedX, step);
  const rate = p.advances / p.seconds;
  console.log(`store playback: ${p.advances} time points in ${p.seconds.toFixed(2)} s = ${rate.toFixed(1)} time points/s of 20, ` +
              `${p.drawn} frames drawn (${(p.drawn / p.seconds).toFixed(1)}/s), ${p.late} late frames; ` +
              `${c.referenced.length} frames against references, min ${c.minPsnr.toFixed(2)} dB; cube column per step ${step.toFixed(2)} px`);
  check('store playback shows every time point in order, none skipped (a loop and one more)',
        p.log.length >= count + 2 && !order && c.all, `${order || ''} log ${p.log.join(',')}`);
  check('every frame drawn shows the time point it is labelled with (the cube within a third of a step: no stale frame)',
        p.frames.length >= count && c.wrong.length === 0,
        `${p.frames.length} frames; wrong: ${JSON.stringify(c.wrong.slice(0, 5).map((f) => ({ t: f.t, x: +f.x.toFixed(1), want: +expectedX(f.t).toFixed(1) })))}`);
  check('the frames of referenced time points equal the CLI render (PSNR >= 40 dB)',
        c.referenced.length >= refTimes.length && c.low.length === 0, `${c.referenced.length} frames, min ${c.minPsnr.toFixed(2)} dB`);
  // Prefetch within the host budget: 20 x 256 KiB are all kept, so each
  // time point's chunk of level 0 was fetched once (at open, for the
  // slider, ahead of playback), never again.
  const keys = served.paths.slice(servedBefore).filter((k) => /\/cube\.ome\.zarr\/0\/\d/.test(k));
  check('each time point\'s level-0 chunk fetched exactly once over the page\'s life (the series kept in the host budget)',
        new Set(keys).size === count && keys.length === count, `${keys.length} fetches of ${new Set(keys).size} chunks`);
  check('no page errors', !logs.some((l) => l.startsWith('pageerror')) && !p.error,
        p.error || logs.filter((l) => l.startsWith('pageerror')).join('; '));
  console.log(`store series test: ${((Date.now() - started) / 1000).toFixed(1)} s`);
  await page.close();
}

// Resolves once the store's frame on the canvas has every brick its view
// wants (or `limitMs`); whether it has.
function storeComplete(page, limitMs) {
  return page.evaluate(async (limitMs) => {
    const start = performance.now();
    const done = () => { const z = window.tessera.zarr(); return z && z.last && z.last.complete; };
    while (!done() && performance.now() - start < limitMs) await new Promise((r) => setTimeout(r, 20));
    return !!done();
  }, limitMs);
}

// Each time point a run of frames: whether the last frame of every run
// (the one the next time point replaced) was whole.
function runsEndWhole(frames) {
  const ends = frames.filter((f, i) => i + 1 < frames.length && frames[i + 1].t !== f.t);
  return { ends: ends.length, partial: ends.filter((f) => !f.complete).map((f) => f.t) };
}

async function bricksSeries(context, url, tmp) {
  const SIZE = 128;
  const count = 6;
  const store = path.join(tmp, 'cube6.ome.zarr');
  const started = Date.now();
  writeStore(store, 64, count);
  const refTimes = [0, 3, 5];
  await renderTimes(store, refTimes, SIZE, tmp, undefined, 'bricks');
  const servedBefore = served.paths.length;
  const { page, logs } = await openPage(context, url, `size=${SIZE}&progressive=0&layout=bricks&url=/data/cube6.ome.zarr`);
  await withoutOverlays(page);
  const s = await page.evaluate(() => window.tessera.time());
  check('a store with a t axis of 6 opens as a time series over bricks (?layout=bricks) with the Time panel shown',
        s.count === count && s.bricks === true && s.shown === 0 &&
        await page.evaluate(() => !document.getElementById('time-controls').hidden),
        JSON.stringify(s) + (await page.evaluate(() => window.tessera.error())));
  await loadRefs(page, Object.fromEntries(refTimes.map((t) => [t, path.join(tmp, `bricks-t${t}.png`)])));
  const refX = {};
  for (const t of refTimes) refX[t] = await markerOf(page, t);
  const expectedX = (t) => (t <= 3 ? refX[0] + (refX[3] - refX[0]) * t / 3 : refX[3] + (refX[5] - refX[3]) * (t - 3) / 2);
  const step = Math.abs(refX[5] - refX[0]) / (count - 1);
  check('the cube is seen in every reference, a column per time point apart',
        refTimes.every((t) => refX[t] >= 0) && step > 1, JSON.stringify(refX));

  // The slice views read at level 0 (as panels of 512² pixels), their
  // references: the axial slice of every time point (checked at every frame
  // of the playback), all three of time points 0 and 3.
  await page.evaluate(() => window.tessera.slices.setPanelPixels(512 * 512));
  const st = await page.evaluate(() => window.tessera.slices.state());
  const planes = ['axial', 'coronal', 'sagittal'];
  const refs = await sliceRefs(store, st, [...[0, 3].flatMap((t) => planes.map((q) => [t, q])),
    ...[1, 2, 4, 5].map((t) => [t, 'axial'])], tmp, 'bricks');

  // The slider's path: a time point asked for is drawn from its own bricks.
  const shown = await page.evaluate(() => window.tessera.showTime(3));
  const whole = await storeComplete(page, 20000);
  const own = await psnrAgainst(page, path.join(tmp, 'bricks-t3.png'));
  const other = await psnrAgainst(page, path.join(tmp, 'bricks-t5.png'));
  check('over bricks, time point 3 equals `tessera render STORE --time 3` (PSNR >= 40 dB) and not time point 5',
        shown === 3 && whole && own.psnr >= 40 && other.psnr < own.psnr - 10,
        own.error || `shown ${shown}, whole ${whole}: ${own.psnr.toFixed(2)} dB (time point 5: ${other.psnr.toFixed(2)} dB)`);
  const at3 = await slicesAgainst(page, refs, 3, 0);
  check('over bricks, the slice views at time point 3 equal `tessera slice STORE --time 3` (identical), not time point 0\'s',
        at3.ok, at3.text);

  // Playback: a loop and more, every frame drawn sampled (its axial slice too).
  await loadSliceRefs(page, refs, [0, 1, 2, 3, 4, 5], 'axial');
  const p = await playSampled(page, 20, count + 1, 60000);
  const order = inOrder(p.log, count);
  const c = checkFrames(p, count, expectedX, step);
  const runs = runsEndWhole(p.frames);
  const complete = c.referenced.filter((f) => f.complete);
  const lowWhole = complete.filter((f) => f.psnr < 40);
  const rate = p.advances / p.seconds;
  console.log(`store playback over bricks: ${p.advances} time points in ${p.seconds.toFixed(2)} s = ${rate.toFixed(1)} time points/s of 20, ` +
              `${p.drawn} frames drawn (${p.frames.filter((f) => !f.complete).length} with bricks still coming), ${p.late} late frames; ` +
              `${complete.length} whole frames against references, min ${complete.length ? Math.min(...complete.map((f) => f.psnr)).toFixed(2) : 'n/a'} dB`);
  check('over bricks, playback shows every time point in order, none skipped (a loop and one more)',
        p.log.length >= count + 2 && !order && c.all, `${order || ''} log ${p.log.join(',')}`);
  check('over bricks, every frame drawn shows the time point it is labelled with (no stale brick moves the cube)',
        p.frames.length >= count && c.wrong.length === 0,
        `${p.frames.length} frames; wrong: ${JSON.stringify(c.wrong.slice(0, 5).map((f) => ({ t: f.t, x: +f.x.toFixed(1), want: +expectedX(f.t).toFixed(1) })))}`);
  check('over bricks, each time point was drawn whole before the next was shown',
        runs.ends >= count && runs.partial.length === 0, JSON.stringify(runs));
  check('over bricks, the whole frames of referenced time points equal the CLI render (PSNR >= 40 dB)',
        complete.length >= refTimes.length && lowWhole.length === 0,
        `${complete.length} frames, ${lowWhole.length} below 40 dB`);
  // The slice views in step: at every frame drawn, the axial slice is the
  // time point's the 3D view shows, none stale, none pending.
  const sliced = p.frames.filter((f) => f.sliceDiffer !== undefined);
  const stale = sliced.filter((f) => f.sliceDiffer !== 0 || f.slicePending);
  check('over bricks, at every frame drawn the axial slice equals `tessera slice STORE --time T` of the time point shown (no stale slice)',
        sliced.length === p.frames.length && sliced.length >= count && stale.length === 0,
        `${sliced.length} of ${p.frames.length} frames checked, ${new Set(sliced.map((f) => f.t)).size} time points; ` +
        `off: ${JSON.stringify(stale.slice(0, 5).map((f) => ({ t: f.t, differ: f.sliceDiffer, pending: f.slicePending })))}`);
  // After it: paused at time point k, the three slice views are k's.
  const k = await page.evaluate(() => window.tessera.time().shown);
  const more = await sliceRefs(store, st, planes.filter((q) => !refs[`${k}-${q}`]).map((q) => [k, q]), tmp, 'bricks');
  const after = await slicesAgainst(page, { ...refs, ...more }, k, k === 0 ? 3 : 0);
  check(`over bricks, paused after playback at time point ${k}: the slice views equal \`tessera slice STORE --time ${k}\``,
        after.ok, after.text);
  // Prefetch within the storage's budget: each time point's level-0 chunk
  // fetched once over the page's life (read ahead, kept until drawn).
  const keys = served.paths.slice(servedBefore).filter((k) => /\/cube6\.ome\.zarr\/0\/\d/.test(k));
  check('over bricks, each time point\'s level-0 chunk fetched exactly once',
        new Set(keys).size === count && keys.length === count, `${keys.length} fetches of ${new Set(keys).size} chunks`);
  check('over bricks, no page errors', !logs.some((l) => l.startsWith('pageerror')) && !p.error,
        p.error || logs.filter((l) => l.startsWith('pageerror')).join('; '));
  console.log(`store series over bricks test: ${((Date.now() - started) / 1000).toFixed(1)} s`);
  await page.close();
}

// Time point t asked for by the slider (tessera.showTime) once drawn, or
// -1 when it is not within `ms` (the check then fails instead of waiting).
function showTimeWithin(page, t, ms = 30000) {
  return page.evaluate(({ t, ms }) => Promise.race([window.tessera.showTime(t),
    new Promise((resolve) => setTimeout(() => resolve(-1), ms))]), { t, ms });
}

// A region (the slice views' "view region") and a grid block of a store
// with a t axis, over bricks (?layout=bricks) and in core: picked while
// paused at time point 3, each is read from time point 3's level 0 (its
// frame equals `tessera render STORE --time 3 --region BOX`, and differs
// from time point 0's), and it follows the time point shown, by the slider
// and at every frame of a playback (each frame equals its time point's
// region), as Session::showTimePoint carries the exploration over.
async function storeRegions(context, url, tmp) {
  const SIZE = 128;
  const count = 6;
  const store = path.join(tmp, 'cuber.ome.zarr');
  const started = Date.now();
  writeStore(store, 64, count);
  // The cube (x from 6 + 8.64 t, y and z 28..36) lies in the box at every
  // time point, so that each time point's region frame is its own.
  const box = { begin: [4, 20, 20], end: [64, 44, 44] };
  const specOf = (b) => [0, 1, 2].map((a) => `${b.begin[a]}:${b.end[a]}`).join(',');
  const spec = specOf(box);
  const cam = ['--azimuth', '30', '--elevation', '20'];
  const times = [...Array(count).keys()];
  await renderTimes(store, times, SIZE, tmp, ['--tf', 'mr-default', '--region', spec, ...cam], 'region');
  const refOf = (t) => path.join(tmp, `region-t${t}.png`);
  const blockRefs = new Map();  // the grid block's references by box, made once
  const dBs = (m) => (m.error ? m.error : m.psnr >= 999 ? 'identical' : `${m.psnr.toFixed(2)} dB`);
  // The page's region frames (SwiftShader) measured 60.0 to 73 dB against
  // the CLI's (llvmpipe); time points apart are 15 to 18 dB.
  const MIN_DB = 55;

  // Without the slice views (?slices=0) the region is picked through
  // tessera.zarrRegion, and nothing explored the store before it.
  for (const [bricks, slices] of [[true, true], [false, true], [false, false]]) {
    const how = `${bricks ? 'over bricks' : 'in core'}${slices ? '' : ', no slice views'}`;
    const { page, logs } = await openPage(context, url,
      `size=${SIZE}&progressive=0${bricks ? '&layout=bricks' : ''}${slices ? '' : '&slices=0'}&url=/data/cuber.ome.zarr`);
    // What the 3D view shows: {showing (a region), time, region}.
    const shownNow = () => page.evaluate(({ slices, box }) => {
      if (slices) {
        const ex = window.tessera.slices.state().explore;
        return { showing: ex.showing_region, time: ex.time, region: JSON.stringify(ex.region) };
      }
      const dims = window.tessera.state().dims;
      const showing = [0, 1, 2].every((a) => dims[a] === box.end[a] - box.begin[a]);
      return { showing, time: window.tessera.time().shown, region: showing ? JSON.stringify(box) : null };
    }, { slices, box });
    await withoutOverlays(page);
    const s = await page.evaluate(() => window.tessera.time());
    check(`${how}: the store opens as a series of ${count}`, s.count === count && !!s.bricks === bricks, JSON.stringify(s));

    // Paused at time point 3, a region picked: time point 3's.
    await showTimeWithin(page, 3);
    if (bricks) await storeComplete(page, 20000);
    const picked = await page.evaluate(async ({ b, slices }) => {
      if (slices) return window.tessera.slices.showRegion(b);
      return window.tessera.zarrRegion(b.begin, b.end).then(() => true, () => false);
    }, { b: box, slices });
    await page.evaluate(() => window.tessera.setCamera(30, 20, 1));
    const ex = await shownNow();
    const at3 = await psnrAgainst(page, refOf(3));
    const as0 = await psnrAgainst(page, refOf(0));
    check(`${how}: a region picked at time point 3 equals \`tessera render STORE --time 3 --region ${spec}\` ` +
          `(>= ${MIN_DB} dB), not time point 0's`,
          picked && ex.showing && ex.time === 3 && at3.psnr >= MIN_DB && as0.psnr < at3.psnr - 10,
          `${dBs(at3)} (time point 0's region: ${dBs(as0)}); shown ${ex.showing}, time ${ex.time}, ` +
          `region ${ex.region}${picked ? '' : `; ${await page.evaluate(() => window.tessera.error())}`}`);

    // The slider: time point 4, the region follows (the same box).
    const shown4 = await showTimeWithin(page, 4);
    const ex4 = await shownNow();
    const at4 = await psnrAgainst(page, refOf(4));
    const as3 = await psnrAgainst(page, refOf(3));
    check(`${how}: the slider to time point 4 with the region shown: it equals \`--time 4 --region ${spec}\` ` +
          `(>= ${MIN_DB} dB), not time point 3's`,
          shown4 === 4 && ex4.showing && ex4.time === 4 && ex4.region === ex.region &&
          at4.psnr >= MIN_DB && as3.psnr < at4.psnr - 10,
          `${dBs(at4)} (time point 3's: ${dBs(as3)}); shown ${ex4.showing}, time ${ex4.time}, region ${ex4.region}`);

    // Playback with the region shown: every frame drawn is its time
    // point's region, each time point in order.
    await loadRefs(page, Object.fromEntries(times.map((t) => [t, refOf(t)])));
    const p = await playSampled(page, 20, count + 1, 60000);
    await page.evaluate(() => window.tessera.setProgressive(false));
    const order = inOrder(p.log, count);
    const scored = p.frames.filter((f) => f.psnr !== undefined);
    const low = scored.filter((f) => f.psnr < MIN_DB);
    const min = scored.length ? Math.min(...scored.map((f) => f.psnr)) : NaN;
    console.log(`${how}, a region shown: ${p.advances} time points in ${p.seconds.toFixed(2)} s, ${p.drawn} frames drawn, ` +
                `${p.late} late frames; every frame against its time point's region: min ${min.toFixed(2)} dB`);
    check(`${how}: playback with a region shown plays every time point in order, each frame its time point's region ` +
          `(>= ${MIN_DB} dB)`,
          p.log.length >= count + 2 && !order && new Set(p.frames.map((f) => f.t)).size === count &&
          scored.length >= count && low.length === 0 && !p.error,
          `${order || `log ${p.log.join(',')}`}; ${scored.length} frames, ` +
          `low: ${JSON.stringify(low.slice(0, 5).map((f) => ({ t: f.t, db: +f.psnr.toFixed(1) })))}${p.error ? `; ${p.error}` : ''}`);

    if (!slices) {
      check(`${how}: no page errors`, !logs.some((l) => l.startsWith('pageerror')) && !(await page.evaluate(() => window.tessera.error())),
            `${logs.filter((l) => l.startsWith('pageerror')).join('; ')} ${await page.evaluate(() => window.tessera.error())}`);
      await page.close();
      continue;  // the grid view is the slice views'
    }
    // A grid block entered at time point 3 (cells of 16 around the
    // crosshair): time point 3's; the slider to 4: time point 4's.
    await showTimeWithin(page, 3);
    await page.evaluate(() => window.tessera.slices.overview());
    await page.evaluate(() => window.tessera.slices.setCross(34, 32, 32));
    const entered = await page.evaluate(() => window.tessera.slices.grid.enter(16));
    await page.evaluate(() => window.tessera.setCamera(30, 20, 1));
    const g = await page.evaluate(() => window.tessera.slices.grid.state());
    if (!entered || !g.active || !g.block) {
      check(`${how}: the grid view entered at time point 3`, false,
            `${await page.evaluate(() => window.tessera.error())} ${JSON.stringify(g)}`);
      await page.close();
      continue;
    }
    const blockSpec = specOf(g.block);
    if (!blockRefs.has(blockSpec)) {
      const tag = `block${blockRefs.size}`;
      await renderTimes(store, [0, 3, 4], SIZE, tmp, ['--tf', 'mr-default', '--region', blockSpec, ...cam], tag);
      blockRefs.set(blockSpec, (t) => path.join(tmp, `${tag}-t${t}.png`));
    }
    const blockRef = blockRefs.get(blockSpec);
    const b3 = await psnrAgainst(page, blockRef(3));
    const b0 = await psnrAgainst(page, blockRef(0));
    const gt = await page.evaluate(() => window.tessera.time().shown);
    check(`${how}: a grid block entered at time point 3 equals \`tessera render STORE --time 3 --region ${blockSpec}\` ` +
          `(>= ${MIN_DB} dB), not time point 0's`,
          gt === 3 && b3.psnr >= MIN_DB && b0.psnr < b3.psnr - 10,
          `time point ${gt}; ${dBs(b3)} (time point 0's block: ${dBs(b0)}); block ${blockSpec}, point ${g.point.join(',')}`);
    const gshown = await showTimeWithin(page, 4);
    const g4 = await page.evaluate(() => window.tessera.slices.grid.state());
    const b4 = await psnrAgainst(page, blockRef(4));
    const b43 = await psnrAgainst(page, blockRef(3));
    check(`${how}: the slider to time point 4 in the grid view: the same block, time point 4's (>= ${MIN_DB} dB), not 3's`,
          gshown === 4 && g4.active && specOf(g4.block) === blockSpec && b4.psnr >= MIN_DB && b43.psnr < b4.psnr - 10,
          `${dBs(b4)} (time point 3's: ${dBs(b43)}); active ${g4.active}, block ${g4.block ? specOf(g4.block) : 'none'}`);
    check(`${how}: no page errors`, !logs.some((l) => l.startsWith('pageerror')) && !(await page.evaluate(() => window.tessera.error())),
          `${logs.filter((l) => l.startsWith('pageerror')).join('; ')} ${await page.evaluate(() => window.tessera.error())}`);
    await page.close();
  }
  console.log(`store regions over time test: ${((Date.now() - started) / 1000).toFixed(1)} s`);
}

async function channelSeries(context, url, tmp) {
  const SIZE = 96;
  const count = 4;
  const store = path.join(tmp, 'tc.ome.zarr');
  const started = Date.now();
  writeStore(store, 32, count, 2);
  const { page, logs } = await openPage(context, url, `size=${SIZE}&slices=0&url=/data/tc.ome.zarr`);
  await page.waitForFunction(() => window.tessera.channels() !== null, null, { timeout: 30000 }).catch(() => {});
  const listed = await page.evaluate(() => window.tessera.channels());
  const s = await page.evaluate(() => window.tessera.time());
  check('a store with 2 channels and a t axis of 4 lists its channels and opens as a time series',
        listed && listed.open && listed.channels.length === 2 && s.count === count && s.shown === 0,
        JSON.stringify({ listed, s }) + (await page.evaluate(() => window.tessera.error())));
  const tfPath = path.join(tmp, 'tc-tf.json');
  fs.writeFileSync(tfPath, JSON.stringify(await page.evaluate(() => window.tessera.tf())));
  const times = [0, 1, 2, 3];
  await renderTimes(store, times, SIZE, tmp, ['--tf', tfPath, '--channels', '0,1'], 'tc');
  await loadRefs(page, Object.fromEntries(times.map((t) => [t, path.join(tmp, `tc-t${t}.png`)])));

  const shown = await page.evaluate(() => window.tessera.showTime(2));
  await page.evaluate(() => window.tessera.render());
  const own = await psnrAgainst(page, path.join(tmp, 'tc-t2.png'));
  const other = await psnrAgainst(page, path.join(tmp, 'tc-t0.png'));
  check('channels at time point 2 equal `tessera render STORE --channels 0,1 --time 2` (PSNR >= 40 dB), not time point 0',
        shown === 2 && own.psnr >= 40 && other.psnr < own.psnr - 10,
        own.error || `${own.psnr.toFixed(2)} dB (time point 0: ${other.psnr.toFixed(2)} dB)`);

  const p = await playSampled(page, 20, count + 1, 60000);
  const order = inOrder(p.log, count);
  const scored = p.frames.filter((f) => f.psnr !== undefined);
  const low = scored.filter((f) => f.psnr < 40);
  const min = scored.length ? Math.min(...scored.map((f) => f.psnr)) : NaN;
  console.log(`channels playback: ${p.advances} time points in ${p.seconds.toFixed(2)} s = ${(p.advances / p.seconds).toFixed(1)} ` +
              `time points/s of 20, ${p.drawn} frames drawn, ${p.late} late frames; every frame against its time point's ` +
              `CLI render: min ${min.toFixed(2)} dB`);
  check('channels play every time point in order, none skipped (a loop and one more)',
        p.log.length >= count + 2 && !order && new Set(p.frames.map((f) => f.t)).size === count, `${order} log ${p.log.join(',')}`);
  check('every channel frame drawn equals the CLI render of the time point it is labelled with (PSNR >= 40 dB: none stale)',
        scored.length >= count && low.length === 0,
        `${scored.length} frames, low: ${JSON.stringify(low.slice(0, 5).map((f) => ({ t: f.t, db: +f.psnr.toFixed(1) })))}`);
  check('channels: no page errors', !logs.some((l) => l.startsWith('pageerror')) && !p.error,
        p.error || logs.filter((l) => l.startsWith('pageerror')).join('; '));
  console.log(`channels series test: ${((Date.now() - started) / 1000).toFixed(1)} s`);
  await page.close();
}

async function storeBenchmark(context, url, tmp, run, layout) {
  const count = 20;
  const bricks = layout === 'bricks';
  const store = path.join(tmp, 'cube256.ome.zarr');
  if (!fs.existsSync(store)) {  // the in-core and bricks runs share it
    const t0 = Date.now();
    writeStore(store, 256, count);
    console.log(`bench: wrote 20 x 256^3 u8 store in ${((Date.now() - t0) / 1000).toFixed(1)} s`);
    await renderTimes(store, [0, count - 1], 512, tmp, undefined, 'bench256');
  }
  const { page } = await openPage(context, url, `size=512&slices=0${bricks ? '&layout=bricks' : ''}&url=/data/cube256.ome.zarr`);
  await withoutOverlays(page);  // the store view's white box lines would pass for the cube
  const s = await page.evaluate(() => window.tessera.time());
  check(`the 20 x 256^3 store opens as a time series ${layout}`, s.count === count && !!s.bricks === bricks, JSON.stringify(s));
  await loadRefs(page, { 0: path.join(tmp, 'bench256-t0.png'), [count - 1]: path.join(tmp, `bench256-t${count - 1}.png`) });
  const [x0, x1] = [await markerOf(page, 0), await markerOf(page, count - 1)];
  const step = Math.abs(x1 - x0) / (count - 1);
  check('the cube is seen in the references at 512x512', x0 >= 0 && x1 >= 0 && step > 1, `${x0} ${x1}`);
  for (const fps of [10, 30]) {
    const p = await playSampled(page, fps, count + 1, 180000);
    const order = inOrder(p.log, count);
    const c = checkFrames(p, count, (t) => x0 + (x1 - x0) * t / (count - 1), step);
    const rate = p.advances / p.seconds;
    const runs = runsEndWhole(p.frames);
    console.log(`bench: web page, OME-Zarr 20 x 256^3 u8 at 512x512 ${layout}, asked ${fps}/s: ${rate.toFixed(2)} time points/s, ` +
                `${p.advances} shown in ${p.seconds.toFixed(1)} s, ${p.drawn} frames drawn, ${p.late} late frames, ` +
                (bricks ? `${runs.partial.length} time points left before drawn whole, ` : '') +
                `${order || 'none skipped'}, ${c.shown.size} of ${count} time points shown, ${c.wrong.length} frames off their time point, ` +
                `references min ${c.minPsnr.toFixed(2)} dB` + (p.error ? `; error: ${p.error}` : '') +
                (c.wrong.length ? `; off: ${JSON.stringify(c.wrong.slice(0, 8).map((f) => ({ t: f.t, x: +f.x.toFixed(1),
                  want: +(x0 + (x1 - x0) * f.t / (count - 1)).toFixed(1), complete: f.complete })))}` : ''));
    check(`store ${layout} asked ${fps}/s: every time point shown in order, no stale frame`,
          !order && c.all && c.wrong.length === 0 && runs.partial.length === 0, order);
  }
  await page.close();
}
