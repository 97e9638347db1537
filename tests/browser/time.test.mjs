// Browser test: a 4-D NIfTI dropped on the page plays back (time.test.mjs of
// tests/browser; fixture.mjs serves the site and launches Chromium). Each
// time point the page shows equals `tessera render --time T` of the same
// file; playback shows every time point in order (none skipped, a late one
// shown late), reading one time point ahead per animation frame (the page
// has no threads: session/TimeSeries.h, Reading::OnPump).
// With TESSERA_BENCH=1 it also plays a 20-time-point 256^3 series at
// 512x512 and prints the rate reached.
import { test } from 'node:test';
import fs from 'node:fs';
import path from 'node:path';
import { bench, check, psnrAgainst, openPage, openThroughPicker, withoutOverlays, browserSuite } from './fixture.mjs';

const checks = browserSuite();

test('a 4-D NIfTI: every time point as the CLI renders it, playback in order', checks(timeSeries));
test('benchmark: 20 time points of 256^3 at 512x512 (TESSERA_BENCH=1)', { skip: !bench }, checks(benchmark));

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
