// Browser test: compressed DICOM series dropped on the page (the decoders of
// frontends/web/dicom-codecs.js). dicom_codec_series.py makes the series from
// ch2 with Debian's encoders (DCMTK dcmcjpeg/dcmcjpls, opj_compress,
// ojph_compress) and reads each with the native CLI; here each is dropped as
// a folder and the page's decoded stored values are compared with the
// uncompressed original (lossless: every voxel equal; lossy: PSNR) and with
// the command-line decoders of the CLI's own libraries, and its render with
// the uncompressed series' render. Corrupt streams must give an error naming
// the file and the frame and leave the page usable; no decoder is loaded for
// an uncompressed series. Prints the acceptance table and the open times.
import { test } from 'node:test';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { SIZE, CH2, cli, check, snapshot, openPage, withoutOverlays, psnrOf, browserSuite } from './fixture.mjs';

const checks = browserSuite();
const here = path.dirname(fileURLToPath(import.meta.url));

test('compressed DICOM series decode in the page like the CLI; corrupt frames are named', checks(codecs));

// Drops the files under /data/<folder>/ as a dropped folder (the walk of
// dicom-drop.js: webkitGetAsEntry, createReader, readEntries); resolves once
// the page shows the series or an error, with the time from drop to shown.
async function dropServed(page, folder, files, { render = true } = {}) {
  await page.evaluate(async ({ folder, files }) => {
    const list = [];
    for (const f of files) list.push(new File([await (await fetch(`/data/${folder}/${f}`)).arrayBuffer()], f));
    window.__drop = () => {
      const fileEntry = (f) => ({ isFile: true, isDirectory: false, name: f.name, file: (ok) => ok(f) });
      const dir = { isFile: false, isDirectory: true, name: folder, createReader() {
        let given = false;
        return { readEntries: (ok) => { const b = given ? [] : list.map(fileEntry); given = true; ok(b); } };
      } };
      const e = new Event('drop', { bubbles: true, cancelable: true });
      Object.defineProperty(e, 'dataTransfer', { value: { types: ['Files'], files: [], items: [{ kind: 'file', webkitGetAsEntry: () => dir }] } });
      document.getElementById('error').hidden = true;
      document.getElementById('view').dispatchEvent(e);
    };
  }, { folder, files });
  const t = Date.now();
  await page.evaluate(() => window.__drop());
  const name = `${folder}/${files[0]}`;
  await page.waitForFunction((n) => window.tessera.state().name === n || window.tessera.error() !== '', name, { timeout: 60000 });
  const ms = Date.now() - t;
  const error = await page.evaluate(() => window.tessera.error());
  // A render only where it is compared (SwiftShader frames are the slow part).
  if (error || !render) return { ms, error, pixels: null };
  await page.evaluate(() => window.tessera.render());
  return { ms, error, pixels: (await snapshot(page)).pixels };
}

// The page's last decode against raw stored values served under /data/.
function compareDecoded(page, raws, bits) {
  return page.evaluate(async ({ raws, bits }) => {
    const { last } = await import('./dicom-codecs.js');
    const { stats, pixels } = last();
    const total = pixels.reduce((n, p) => n + p.pixels.length, 0);
    const got = new Uint8Array(total);
    let o = 0;
    for (const p of pixels) { got.set(p.pixels, o); o += p.pixels.length; }
    const wide = bits > 8;
    const value = (a, i) => (wide ? a[2 * i] | (a[2 * i + 1] << 8) : a[i]);
    const out = { stats };
    for (const [key, url] of Object.entries(raws)) {
      if (!url) continue;
      const want = new Uint8Array(await (await fetch(url)).arrayBuffer());
      if (want.length !== got.length) { out[key] = { error: `${got.length} bytes decoded, ${want.length} expected` }; continue; }
      const n = got.length / (wide ? 2 : 1);
      let differing = 0, sq = 0, max = 0;
      for (let i = 0; i < n; i++) {
        const d = value(got, i) - value(want, i);
        if (d !== 0) { differing++; sq += d * d; max = Math.max(max, Math.abs(d)); }
      }
      const peak = (1 << (bits > 8 ? 12 : 8)) - 1;
      out[key] = { differing, voxels: n, max, psnr: sq === 0 ? Infinity : 10 * Math.log10(peak * peak / (sq / n)) };
    }
    return out;
  }, { raws, bits });
}

const db = (x) => (x === undefined ? '-' : x === null || x === Infinity || x >= 999 ? 'identical' : `${x.toFixed(1)} dB`);  // psnrOf gives 999 for equal images

async function codecs(context, url, tmp) {
  if (!fs.existsSync(CH2)) { check(`the codec test needs ${CH2} (mricron-data)`, false); return; }
  const made = Date.now();
  const out = path.join(tmp, 'codecs');
  execFileSync('/usr/bin/python3', [path.join(here, 'dicom_codec_series.py'), out, cli], { stdio: ['ignore', 'inherit', 'inherit'] });
  const manifest = JSON.parse(fs.readFileSync(path.join(out, 'manifest.json')));
  const served = (p) => (p ? `/data/${path.relative(tmp, p)}` : null);
  const folderOf = (e) => path.relative(tmp, e.folder);
  console.log(`series made and read by the CLI in ${((Date.now() - made) / 1000).toFixed(1)} s`);

  const { page, logs } = await openPage(context, url, `size=${SIZE}`);
  await withoutOverlays(page);
  const codecRequests = () => page.evaluate(() => performance.getEntriesByType('resource').map((r) => r.name).filter((n) => !n.includes('/data/') && (n.includes('/codecs/') || n.includes('dicom-codecs'))));

  // The uncompressed originals: their renders are the lossless references,
  // and nothing of the decoders is loaded for them.
  const originals = {};
  for (const bits of [8, 12]) {
    const folder = `codecs/original-${bits}bit`;
    const files = fs.readdirSync(path.join(tmp, folder)).sort();
    originals[bits] = await dropServed(page, folder, files);
    check(`the uncompressed ${bits}-bit series opens`, !originals[bits].error, originals[bits].error || `${originals[bits].ms} ms`);
  }
  const early = await codecRequests();
  check('no decoder is loaded for uncompressed series', early.length === 0, early.join(' '));

  const rows = [];
  const times = [];
  for (const e of manifest.series) {
    const shown = await dropServed(page, folderOf(e), e.files);
    const c = shown.error ? null : await compareDecoded(page, { original: served(e.original), native: served(e.native) }, e.bits);
    const render = shown.error ? null : psnrOf(shown.pixels, originals[e.bits].pixels);
    const cliText = !e.cli.ok ? `refused: ${e.cli.error.replace(/^tessera: error: \S+: /, '').slice(0, 60)}…` : e.lossless
      ? (e.cli.differing === 0 ? 'identical' : `${e.cli.differing} voxels differ`) : db(e.cli.psnr);
    const browserText = shown.error ? `refused: ${shown.error.split(' (')[0]}` : e.kind === 'jpeg-extended-12bit'
      ? 'stored values re-offset by dcmcjpeg (render)' : e.lossless
      ? (c.original.differing === 0 ? 'identical' : `${c.original.differing} voxels differ`) : db(c.original.psnr);
    rows.push(`| ${e.kind} | ${e.syntax} | ${cliText} | ${browserText} | ${c ? (c.native.differing === 0 ? 'equal' : `${c.native.differing} differ (max ${c.native.max})`) : '-'} | ${render === null ? '-' : db(render)} |`);
    if (shown.error) { check(`${e.kind}: opens in the page`, false, shown.error); continue; }
    times.push({ kind: e.kind, ms: shown.ms, decodeMs: c.stats.ms, bits: e.bits, bytes: e.bytes });
    if (e.lossless) {
      const cliOk = e.cli.ok && e.cli.differing === 0;  // HTJ2K natively: OpenJPH (io/Htj2kFrame)
      check(`${e.kind} (${e.syntax}): the page's voxels equal the uncompressed original, and so do the CLI's`,
        c.original.differing === 0 && cliOk && c.stats.frames === e.files.length,
        `page ${c.original.differing}/${c.original.voxels} differ, CLI ${e.cli.differing ?? e.cli.error}, ${c.stats.frames} frames in ${c.stats.ms.toFixed(0)} ms`);
      check(`${e.kind}: renders exactly like the uncompressed series`, render >= 999, db(render));
    } else {
      // dcmcjpeg's 12-bit lossy encoder stores the series with a new Rescale
      // Intercept (-2047 for the original's -1024), so its stored values are
      // the original's shifted by 1023: that one is compared through the
      // render, which applies the rescale.
      const shifted = e.kind === 'jpeg-extended-12bit';
      const page = shifted ? render : c.original.psnr;
      check(`${e.kind} (${e.syntax}): lossy within 35 dB of the original in the page${shifted ? ' (its render)' : ''} and the CLI, and equal to the command-line decoders' values (±1)`,
        page > 35 && e.cli.ok && e.cli.psnr > 35 && c.native.max <= 1,
        `page ${db(page)}, CLI ${db(e.cli.psnr)}, page vs native: ${c.native.differing} differ, max ${c.native.max}`);
    }
  }

  // pydicom's greyscale compressed test files, each alone.
  const pyRows = [];
  for (const e of manifest.pydicom) {
    const shown = await dropServed(page, folderOf(e), e.files, { render: false });
    const c = shown.error ? null : await compareDecoded(page, { native: served(e.native) }, e.bits);
    const cliText = e.cli.ok ? (e.cli.differing === 0 ? 'equal' : `${e.cli.differing} differ`) : `refused: ${e.cli.error.replace(/^tessera: error: \S+: /, '').slice(0, 80)}`;
    const pageText = shown.error ? `refused: ${shown.error}` : c.native ? (c.native.differing === 0 ? 'equal' : `${c.native.differing} differ (max ${c.native.max})`) : 'read (no command-line decode)';
    pyRows.push(`| ${e.file} | ${e.syntax} | ${cliText} | ${pageText} |`);
    if (e.syntax === '1.2.840.10008.1.2.4.51') {
      // 12-bit JPEG extended through the page's JavaScript decoder, its
      // level shift mended at build time (cmake/Web.cmake): dcmdjpeg's
      // values within one grey level.
      check(`${e.file} (12-bit JPEG extended): the page's values are dcmdjpeg's within 1`,
        !shown.error && c.native && c.native.max <= 1, shown.error || `${c.native.differing} differ, max ${c.native.max}`);
    }
  }

  // One file of three frames in each encapsulation layout (basic offset
  // table, none with several or one fragment per frame, extended offset
  // table): the decoded frames equal the first three original slices. (The
  // page's reader takes single-frame series, so the decode is called here.)
  const mf = manifest.multiframe;
  const layouts = await page.evaluate(async ({ folder, files, original, n }) => {
    const { decodeEntries, last } = await import('./dicom-codecs.js');
    const want = new Uint8Array(await (await fetch(original)).arrayBuffer()).subarray(0, n);
    const out = {};
    for (const f of files) {
      try {
        await decodeEntries([{ name: f, bytes: new Uint8Array(await (await fetch(`/data/${folder}/${f}`)).arrayBuffer()) }]);
        const got = last().pixels[0].pixels;
        out[f] = got.length === want.length && got.every((b, i) => b === want[i]) ? `${last().stats.frames} frames equal` : 'differ';
      } catch (e) { out[f] = e.message; }
    }
    return out;
  }, { folder: path.relative(tmp, mf.folder), files: mf.files, original: served(mf.original), n: 3 * 181 * 217 * 2 });
  check('three frames in one file, in every fragment layout, decode to the original slices',
    Object.values(layouts).every((v) => v === '3 frames equal'), JSON.stringify(layouts));

  // Codestreams cut in half (their fragments' lengths right) and frames of
  // another size than Rows: each an error naming the file and its frame;
  // then a good series opens again.
  const ht = manifest.series.find((e) => e.kind === 'htj2k-lossless');
  for (const b of manifest.bad) {
    const shown = await dropServed(page, 'codecs/bad', [b.file], { render: false });
    const want = b.how === 'truncated' ? 'truncated' : 'but the file declares 181x201';
    check(`a ${b.how} ${b.kind} frame: an error naming the file and the frame`,
      shown.error.startsWith(`codecs/bad/${b.file}: its frame (`) && shown.error.includes(want), `"${shown.error}"`);
  }
  const again = await dropServed(page, folderOf(ht), ht.files);
  check('after those errors the page opens a good series again', !again.error && psnrOf(again.pixels, originals[12].pixels) >= 999, again.error || 'identical render');
  const loaded = (await codecRequests()).map((n) => n.split('/').pop());
  check('the decoders are fetched from the site once each',
    ['libjpegturbowasm_decode.wasm', 'charlswasm_decode.wasm', 'openjpegwasm_decode.wasm', 'openjphjs.wasm', 'lossless-min.js'].every((f) => loaded.includes(f)),
    loaded.join(' '));

  console.log('\n| series | syntax | CLI vs original | browser vs original | browser vs native decode | browser render vs original |');
  console.log('| --- | --- | --- | --- | --- | --- |');
  for (const r of rows) console.log(r);
  console.log('\n| pydicom file | syntax | CLI vs command-line decode | browser vs command-line decode |');
  console.log('| --- | --- | --- | --- |');
  for (const r of pyRows) console.log(r);
  const same = times.filter((t) => t.bits === 12).sort((a, b) => a.ms - b.ms);
  console.log(`\nopen times in the page, the same 12-bit series (${ht.files.length} slices; drop to shown, one run): ` +
    same.map((t) => `${t.kind} ${t.ms} ms (decode ${t.decodeMs.toFixed(0)} ms, ${(t.bytes / 1024).toFixed(0)} KiB)`).join(', ') +
    `; fastest: ${same[0].kind}`);
  const errors = logs.filter((l) => l.startsWith('pageerror'));
  check('no uncaught script errors', errors.length === 0, errors.join(' | '));
  await page.close();
}
