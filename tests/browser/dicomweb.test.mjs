// Browser test: a series read from a real PACS through the page (?dicomweb=,
// frontends/web/dicomweb.js). Debian's Orthanc with its DICOMweb plugin is
// started here (orthanc.mjs: loopback port, temporary storage, generated
// config) and holds a generated 64x64x40 CT series with a marker
// (dicomweb_series.py) uncompressed and re-encoded as JPEG lossless (DCMTK),
// JPEG 2000 lossless (OpenJPEG) and HTJ2K lossless (OpenJPH). The page is
// served from the same origin as the archive: this test's server forwards
// /dicom-web/… to Orthanc (docs/dicomweb.md, "In the web page").
//
// Checked: the table lists the four series and the search box filters it;
// each series opened from the table streams its 40 frames (progress, the
// preview filled slice by slice) and gives the volume of the folder opened
// natively: dims and affine equal `tessera info --json FOLDER`'s, every
// voxel equal to the stored values + Rescale Intercept, and the page's
// render equal to its render of the same folder picked as files. Errors: a
// series the archive does not hold (404), an answer with the wrong
// multipart boundary, the archive gone mid-series, a QIDO answer that is not
// JSON and the archive stopped each show one line naming the URL, the
// previous volume stays, and the page opens a series afterwards.
import { test } from 'node:test';
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { SIZE, check, snapshot, openPage, withoutOverlays, differingPixels, browserSuite, run, site, shots, root } from './fixture.mjs';
import { orthancMissing, startOrthanc, serveWithArchive, makeSeries } from './orthanc.mjs';

const checks = browserSuite();
test('a series from Orthanc through ?dicomweb= equals the folder read natively; errors name the URL', checks(dicomWeb));
test('Enhanced CT (native, RLE, JPEG-LS) dropped and from Orthanc equals the native read; a two-stack object offers its stacks', checks(enhanced));

const [COLS, ROWS, SLICES] = [64, 64, 40];
const KINDS = ['jpeg-lossless', 'j2k-lossless', 'htj2k-lossless'];

async function dicomWeb(context, url, tmp) {
  const missing = orthancMissing();
  if (missing) { console.log(`skipped: ${missing}`); return; }
  const t0 = Date.now();
  const manifest = makeSeries(path.join(tmp, 'series'), COLS, ROWS, SLICES, KINDS);
  check('every syntax could be encoded here', manifest.missing.length === 0, manifest.missing.join('; '));
  const orthanc = await startOrthanc(path.join(tmp, 'orthanc'));
  let archive = orthanc.root;
  let mangle = false;  // the frames' Content-Type names another boundary
  let answer = () => null;  // canned answers in the archive's stead
  const web = await serveWithArchive(site, () => archive, {
    answer: (p) => answer(p),
    contentType: (p, type) => (mangle && p.includes('/frames/') ? type.replace(/boundary=[^;]*/, 'boundary=tessera-wrong') : type),
  });
  try {
    for (const s of Object.values(manifest.series)) await orthanc.upload(s.folder);
    console.log(`  ${Object.keys(manifest.series).length} series generated and stored in ${Date.now() - t0} ms`);
    const native = JSON.parse(run('info', '--json', manifest.series.original.folder));
    const stored = new Uint16Array(fs.readFileSync(path.join(tmp, 'series', 'stored.raw')).buffer.slice(0));

    const { page, logs } = await openPage(context, web.url, `size=${SIZE}&dicomweb=/dicom-web`);
    await withoutOverlays(page);
    // The table.
    const rows = await page.evaluate(() => window.tessera.dicomweb.shownRows());
    const want = Object.entries(manifest.series).map(([k, s]) => [s.uid, k === 'original' ? 'marker' : `marker ${k}`]);
    check('the table lists the four series with their descriptions and 40 images each',
          rows.length === 4 && want.every(([uid, d]) => rows.some((r) => r.series === uid && r.cells[5] === d && r.cells[7] === String(SLICES))),
          rows.map((r) => r.cells.join(' | ')).join(' ;; '));
    await page.fill('#dicomweb .dw-search', 'htj2k');
    const filtered = await page.evaluate(() => window.tessera.dicomweb.shownRows());
    check('the search box filters the table (htj2k: one series)',
          filtered.length === 1 && filtered[0].series === manifest.series['htj2k-lossless'].uid, `${filtered.length} rows`);
    await page.fill('#dicomweb .dw-search', '');

    // The reference: the uncompressed folder picked as files, rendered by the page.
    await page.setInputFiles('#folder', manifest.series.original.folder);
    await page.waitForFunction(() => window.tessera.state().dims && window.tessera.state().dims[2] === 40 && !window.tessera.state().name.includes('dicom-web'), null, { timeout: 30000 });
    await page.evaluate(() => window.tessera.render());
    const folderPixels = (await snapshot(page)).pixels;

    const voxels = () => page.evaluate(([nx, ny, nz]) => {
      const value = window.tessera.viewer().module.cwrap('tessera_voxel_value', 'number', ['number', 'number', 'number']);
      const out = new Float64Array(nx * ny * nz);
      for (let z = 0, i = 0; z < nz; z++) for (let y = 0; y < ny; y++) for (let x = 0; x < nx; x++, i++) out[i] = value(x, y, z);
      return Array.from(out);
    }, [COLS, ROWS, SLICES]);
    const affineEqual = (a, b) => a.every((row, r) => row.every((v, c) => Math.abs(v - b[r][c]) < 1e-9));
    for (const [kind, s] of Object.entries(manifest.series)) {
      // Chosen in the table, as a user would; the progress bar shows while it streams.
      let progressSeen = false;
      const watch = setInterval(async () => { try { if (await page.isVisible('#progress')) progressSeen = true; } catch { /* closed */ } }, 20);
      await page.click(`#dicomweb tr[data-series="${s.uid}"] .dw-open`);
      await page.waitForFunction((uid) => {
        const l = window.tessera.dicomweb.last();
        return l && l.url.endsWith(uid) && (l.error || (l.openMs > 0 && window.tessera.state().name.includes(uid)));
      }, s.uid, { timeout: 30000 });
      clearInterval(watch);
      await page.evaluate(() => window.tessera.render());
      const stats = await page.evaluate(() => window.tessera.dicomweb.last());
      const state = await page.evaluate(() => window.tessera.state());
      const v = await voxels();
      let bad = 0;
      for (let i = 0; i < v.length; i++) if (v[i] !== stored[i] + manifest.intercept) bad++;
      const pixels = (await snapshot(page)).pixels;
      const stackFilled = await page.evaluate(() => {
        const c = document.querySelector('#dicomweb .dw-stack');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let unfilled = 0;
        for (let y = 0; y < c.height; y++) if (d[4 * y * c.width] === 0x22 && d[4 * y * c.width + 2] === 0x33) unfilled++;
        return { rows: c.height, unfilled, red: Array.from(d.filter((_, i) => i % 4 === 0)) };
      });
      // The preview's cut: the middle row of every slice, superior at the
      // top, through the series' window (40/400).
      let previewWrong = 0;
      for (let z = 0; z < SLICES; z++) {
        for (let x = 0; x < COLS; x++) {
          const hu = stored[(z * ROWS + ROWS / 2) * COLS + x] + manifest.intercept;
          const grey = Math.max(0, Math.min(255, Math.round(255 * (hu - (40 - 200)) / 400)));
          if (Math.abs(stackFilled.red[(SLICES - 1 - z) * COLS + x] - grey) > 1) previewWrong++;
        }
      }
      stackFilled.wrong = previewWrong;
      check(`${kind} (${s.syntax}) from Orthanc: dims and affine as \`tessera info\` of the folder, every voxel equal, the render identical`,
            !stats.error && state.dims.join('x') === native.dims.join('x') && affineEqual(state.affine, native.affine) &&
            bad === 0 && differingPixels(pixels, folderPixels, 0) === 0 && stats.syntaxes.join() === s.syntax,
            stats.error || `${stats.frames} frames, ${stats.syntaxes.join()}, ${(stats.bytes / 1024).toFixed(0)} KiB in ${stats.requests} requests, ` +
            `${stats.ms.toFixed(0)} ms (first frame ${stats.firstFrameMs.toFixed(0)} ms); voxels differing ${bad}; ` +
            `pixels differing ${differingPixels(pixels, folderPixels, 0)}; affine ${JSON.stringify(state.affine[0])}`);
      check(`${kind}: the progress bar showed, and the preview's cut filled in all 40 slices with the stored values as frames arrived`,
            progressSeen && stackFilled.rows === SLICES && stackFilled.unfilled === 0 && stackFilled.wrong === 0 && stats.shown.length === SLICES &&
            !(await page.isVisible('#progress')),
            `progress seen ${progressSeen}, preview rows ${stackFilled.rows}, unfilled ${stackFilled.unfilled}, ` +
            `pixels unlike the stored values' ${stackFilled.wrong}, shown ${stats.shown.length}`);
      if (shots && kind === 'j2k-lossless') await page.screenshot({ path: path.join(shots, 'web-dicomweb.jpg'), type: 'jpeg', quality: 85 });
    }

    // Errors: each names the URL, the last volume stays, the page goes on.
    const lastName = (await page.evaluate(() => window.tessera.state())).name;
    const failing = async (series, what) => {
      const message = await page.evaluate(([study, series]) => window.tessera.dicomweb.open(study, series).then(() => '', (e) => e.message),
        [manifest.study, series]);
      const shown = await page.evaluate(() => window.tessera.error());
      const state = await page.evaluate(() => window.tessera.state());
      check(`${what}: one line naming the URL, shown; the previous volume stays`,
            message !== '' && shown.startsWith(message) && !shown.includes('\n') && state.name === lastName && !(await page.isVisible('#progress')),
            `"${shown}"`);
      return shown;
    };
    const m404 = await failing('1.2.3.404', 'a series the archive does not hold');
    check('… its message is the metadata URL and HTTP 404', m404.includes(`${web.url}/dicom-web/studies/${manifest.study}/series/1.2.3.404/metadata: HTTP 404`), m404);
    mangle = true;
    const mBoundary = await failing(manifest.series['j2k-lossless'].uid, 'frames whose Content-Type names another boundary');
    check('… its message names the frame URL and the boundary', /\/frames\/1: multipart body: the boundary 'tessera-wrong' of its Content-Type never occurs/.test(mBoundary), mBoundary);
    mangle = false;
    // The archive gone mid-series: after 10 frames, connections close unanswered.
    let frames = 0;
    answer = (p) => (p.includes('/frames/') && ++frames > 10 ? 'hang up' : null);
    const mHangUp = await failing(manifest.series['jpeg-lossless'].uid, 'the archive gone after 10 frames');
    check('… its message names a frame URL', /\/instances\/[0-9.]+\/frames\/1: (no answer|the answer stopped)/.test(mHangUp), mHangUp);
    // A QIDO answer that is not JSON (a login page, a wrong root): the table keeps its rows.
    answer = (p) => (p.endsWith('/studies') ? { status: 200, type: 'text/html', body: '<html><body>Please log in</body></html>' } : null);
    await page.click('#dicomweb .dw-reload');
    await page.waitForFunction(() => window.tessera.error().includes('/studies?'), null, { timeout: 10000 });
    const mJson = await page.evaluate(() => window.tessera.error());
    const kept = await page.evaluate(() => window.tessera.dicomweb.shownRows().length);
    check('a QIDO answer that is not JSON: one line naming the URL, the table keeps its 4 rows',
          mJson.startsWith(`${web.url}/dicom-web/studies?`) && mJson.includes("the answer is not JSON (Content-Type 'text/html', starts '<html><body>Please log in") && kept === 4,
          `"${mJson}", ${kept} rows`);
    answer = () => null;
    await orthanc.stop();
    const mStopped = await failing(manifest.series.original.uid, 'the archive stopped');
    check('… its message names the URL and the proxy\'s 502', mStopped.includes(`${web.url}/dicom-web/studies/${manifest.study}/series/${manifest.series.original.uid}/metadata: HTTP 502`), mStopped);
    // Usable afterwards: the archive back (a new Orthanc, the same series), a series opens.
    const again = await startOrthanc(path.join(tmp, 'orthanc2'));
    archive = again.root;
    await again.upload(manifest.series['jpeg-lossless'].folder);
    const after = await page.evaluate((a) => window.tessera.dicomweb.open(a[0], a[1]).then((s) => ({ frames: s.frames, error: window.tessera.error() }), (e) => ({ error: e.message })),
      [manifest.study, manifest.series['jpeg-lossless'].uid]);
    check('after the errors the page opens a series again, and the error is cleared', after.frames === SLICES && after.error === '', JSON.stringify(after));
    await again.stop();
    const errors = logs.filter((l) => l.startsWith('pageerror'));
    check('no uncaught script errors on the page', errors.length === 0, errors.join(' | '));
    console.log(`  forwarded to Orthanc: ${web.counts.requests} requests, ${(web.counts.bytes / 1024).toFixed(0)} KiB; ${Date.now() - t0} ms in all`);
    await page.close();
  } finally {
    web.server.close();
    await orthanc.stop();
  }
}

// Multi-frame objects in the page (tests/io/make_multiframe.py): the marked
// head (90x108x90) as one Enhanced CT object, native, RLE Lossless (two
// fragments per frame, a Basic Offset Table) and JPEG-LS lossless (DCMTK's
// dcmcjpls; decoded by dicom-codecs.js), its frames stored in reverse
// z order and placed by their functional groups; and an Enhanced MR object
// of two stacks (axial "1", 24 frames, 100 + z; sagittal "2", 20 frames,
// 200 + z). Each is dropped on the page as a folder and opened from Orthanc
// through ?dicomweb=; the page's module reads them with the native reader's
// functional-group code (io/DicomMultiFrame.cpp). Checked against the CLI's
// read of the same file: dims and affine equal `tessera info --json`'s,
// every voxel equal to `tessera convert FILE x.nii`'s (hashed), the renders
// of the dropped and DICOMweb Enhanced CT (native, JPEG-LS) identical; the two-stack object
// lists both stacks (dropped and from the archive) and the other is chosen
// from the list, equal to `--series UID:2`.
async function enhanced(context, url, tmp) {
  const missing = orthancMissing();
  if (missing) { console.log(`skipped: ${missing}`); return; }
  const t0 = Date.now();
  const mf = path.join(tmp, 'mf');
  execFileSync('/usr/bin/python3', [path.join(root, 'tests/io/make_multiframe.py'), mf], { stdio: 'ignore' });
  // The same object JPEG-LS lossless (DCMTK's dcmcjpls, one fragment per
  // frame) as a series of its own: its frames take the page's codec path
  // (dicom-codecs.js) dropped and from the archive.
  execFileSync('dcmcjpls', ['+ua', path.join(mf, 'enhanced.dcm'), path.join(mf, 'enhanced-jls.dcm')], { stdio: 'ignore' });
  execFileSync('dcmodify', ['-nb', '-m', '(0020,000e)=1.2.826.0.1.3680043.10.543.77.29', path.join(mf, 'enhanced-jls.dcm')], { stdio: 'ignore' });
  const objects = ['enhanced.dcm', 'enhanced-rle.dcm', 'enhanced-jls.dcm', 'twostack.dcm'];
  const RENDERED = ['enhanced.dcm', 'enhanced-jls.dcm'];
  const folders = {};
  for (const name of objects) {
    folders[name] = path.join(tmp, 'upload', name.replace('.dcm', ''));
    fs.mkdirSync(folders[name], { recursive: true });
    fs.copyFileSync(path.join(mf, name), path.join(folders[name], name));
  }
  // The native reads: geometry, and every voxel through a NIfTI.
  const native = {};
  for (const name of objects) {
    const file = path.join(folders[name], name);
    const info = JSON.parse(run('info', '--json', file));
    const stacks = info.dicom_series.map((s) => s.select);
    native[name] = { info, stacks, ...niftiVoxels(file, path.join(tmp, `${name}.nii`)) };
    if (name === 'twostack.dcm') {
      native.stack2 = { info: JSON.parse(run('info', '--json', '--series', stacks[1], file)),
        ...niftiVoxels(file, path.join(tmp, 'stack2.nii'), stacks[1]) };
    }
  }
  const tNative = Date.now();
  const orthanc = await startOrthanc(path.join(tmp, 'orthanc-mf'));
  const web = await serveWithArchive(site, () => orthanc.root);
  try {
    for (const name of objects) await orthanc.upload(folders[name]);
    const tStored = Date.now();
    const { page, logs } = await openPage(context, web.url, 'size=128&dicomweb=/dicom-web');
    await withoutOverlays(page);
    const rows = await page.evaluate(() => window.tessera.dicomweb.list());
    const compare = async (label, want, name, render = false) => {
      const tc = Date.now();
      const state = await page.evaluate(() => window.tessera.state());
      // Every voxel, hashed in the page (FNV-1a over the doubles' bytes, as
      // niftiVoxels hashes the CLI's): a transfer of 0.9 M numbers would
      // take longer than the read.
      const [nx, ny, nz] = want.info.dims;
      const v = await page.evaluate(([nx, ny, nz, hashText]) => {
        const value = window.tessera.viewer().module.cwrap('tessera_voxel_value', 'number', ['number', 'number', 'number']);
        const out = new Float64Array(nx * ny * nz);
        for (let z = 0, i = 0; z < nz; z++) for (let y = 0; y < ny; y++) for (let x = 0; x < nx; x++, i++) out[i] = value(x, y, z);
        // eslint-disable-next-line no-new-func
        return { hash: new Function(`return ${hashText}`)()(out), count: out.length };
      }, [nx, ny, nz, fnv1a.toString()]);
      const affine = state.affine.every((row, r) => row.every((x, c) => Math.abs(x - want.info.affine[r][c]) < 1e-9));
      const tv = Date.now();
      let pixels = null;
      if (render) {
        await page.evaluate(() => window.tessera.render());
        pixels = (await snapshot(page)).pixels;
      }
      check(`${label}: dims and affine as \`tessera info --json\`, every voxel as the CLI's read`,
            state.dims.join('x') === want.info.dims.join('x') && affine && v.hash === want.hash && v.count === want.count,
            `${name}: dims ${state.dims.join('x')} (CLI ${want.info.dims.join('x')}), affine ${affine ? 'equal' : JSON.stringify(state.affine)}, ` +
            `${v.count} voxels hashed ${v.hash} (CLI ${want.count}: ${want.hash}); read in ${tv - tc} ms${render ? `, rendered in ${Date.now() - tv} ms` : ''}`);
      return pixels;
    };
    const dropped = {};
    for (const name of objects) {
      const t = Date.now();
      await dropFolder(page, folders[name]);
      await page.waitForFunction((n) => window.tessera.state().name.endsWith(n) || window.tessera.error() !== '', name, { timeout: 30000 });
      const error = await page.evaluate(() => window.tessera.error());
      check(`${name} dropped as a folder opens`, error === '', error);
      const ms = Date.now() - t;
      // Rendered (small, SwiftShader is slow) for the native and the
      // decoded-in-the-page objects: the DICOMweb read must look the same.
      dropped[name] = await compare(`${name} dropped (${ms} ms)`, native[name], name, RENDERED.includes(name));
      if (name === 'twostack.dcm') {
        const found = await page.evaluate(() => window.tessera.dicomStacks.state());
        check('the dropped two-stack object lists its two stacks (as `tessera info`), the larger shown, the list visible',
              JSON.stringify(found.series.map((s) => s.select)) === JSON.stringify(native[name].stacks) &&
              found.read === native[name].stacks[0] && (await page.isVisible('#dicom-stacks')),
              JSON.stringify(found));
        await page.selectOption('#dicom-stacks select', native[name].stacks[1]);
        await page.waitForFunction((s) => window.tessera.dicomStacks.state().read === s || window.tessera.error() !== '', native[name].stacks[1], { timeout: 30000 });
        await compare('stack 2 chosen from the list (dropped)', native.stack2, `${name} ${native[name].stacks[1]}`);
      }
    }
    for (const name of objects) {
      const uid = native[name].info.dicom_series[0].series_instance_uid;
      const row = rows.find((r) => r.series === uid);
      check(`${name} is listed by the DICOMweb table`, !!row, rows.map((r) => r.series).join());
      if (!row) continue;
      const stats = await page.evaluate((a) => window.tessera.dicomweb.open(a[0], a[1]).then((s) => s, (e) => ({ error: e.message })), [row.study, uid]);
      const nz = native[name].info.dims[2];
      const frames = name === 'twostack.dcm' ? 44 : nz;
      check(`${name} from Orthanc: the metadata and its ${frames} frames 64 to a request, ${stats.syntaxes} as stored`,
            !stats.error && stats.frames === frames && stats.requests === 1 + Math.ceil(frames / 64) && stats.multiFrame === 1,
            stats.error || `${stats.frames} frames, ${(stats.bytes / 1024).toFixed(0)} KiB in ${stats.requests} requests, ${stats.ms.toFixed(0)} ms ` +
            `(metadata ${stats.metadataMs.toFixed(0)} ms, frames ${stats.framesMs.toFixed(0)} ms, open ${stats.openMs.toFixed(0)} ms)`);
      if (stats.error) continue;
      const pixels = await compare(`${name} from Orthanc`, native[name], name, !!dropped[name]);
      if (pixels) {
        const differing = differingPixels(pixels, dropped[name], 0);
        check(`${name}: the render from Orthanc is identical to the render of the dropped file`, differing === 0, `${differing} pixels differ`);
      }
      if (name === 'twostack.dcm') {
        const found = await page.evaluate(() => window.tessera.dicomStacks.state());
        check('the two-stack series from Orthanc lists its two stacks', JSON.stringify(found.series.map((s) => s.select)) === JSON.stringify(native[name].stacks),
              JSON.stringify(found));
        await page.selectOption('#dicom-stacks select', native[name].stacks[1]);
        await page.waitForFunction((s) => window.tessera.dicomStacks.state().read === s || window.tessera.error() !== '', native[name].stacks[1], { timeout: 30000 });
        await compare('stack 2 chosen from the list (from Orthanc)', native.stack2, `${name} ${native[name].stacks[1]}`);
      }
    }
    const errors = logs.filter((l) => l.startsWith('pageerror'));
    check('no uncaught script errors on the page', errors.length === 0, errors.join(' | '));
    console.log(`  multi-frame: forwarded to Orthanc ${web.counts.requests} requests, ${(web.counts.bytes / 1024).toFixed(0)} KiB; ` +
      `${Date.now() - t0} ms in all (objects and CLI reads ${tNative - t0} ms, Orthanc ${tStored - tNative} ms, page ${Date.now() - tStored} ms)`);
    await page.close();
  } finally {
    web.server.close();
    await orthanc.stop();
  }
}

// FNV-1a (32-bit) over the bytes of a Float64Array: the voxels' identity.
function fnv1a(values) {
  const bytes = new Uint8Array(values.buffer, values.byteOffset, values.byteLength);
  let h = 0x811c9dc5;
  for (let i = 0; i < bytes.length; i++) h = Math.imul(h ^ bytes[i], 0x01000193) >>> 0;
  return h.toString(16);
}

// The voxels of the CLI's read of `file` (`tessera convert` to an
// uncompressed NIfTI-1: index order, x fastest): {hash, count} of their
// values as doubles.
function niftiVoxels(file, out, series = '') {
  run('convert', ...(series ? ['--series', series] : []), file, out);
  const b = fs.readFileSync(out);
  const dv = new DataView(b.buffer, b.byteOffset, b.byteLength);
  const n = [1, 2, 3].map((k) => dv.getInt16(40 + 2 * k, true)).reduce((a, c) => a * c, 1);
  const type = dv.getInt16(70, true);
  const at = Math.round(dv.getFloat32(108, true));
  const slope = dv.getFloat32(112, true), inter = dv.getFloat32(116, true);
  const read = { 2: [1, 'getUint8'], 4: [2, 'getInt16'], 8: [4, 'getInt32'], 16: [4, 'getFloat32'], 64: [8, 'getFloat64'], 256: [1, 'getInt8'], 512: [2, 'getUint16'] }[type];
  if (!read) throw new Error(`${out}: NIfTI datatype ${type} not read here`);
  const scaled = slope !== 0 && !(slope === 1 && inter === 0);
  const values = Float64Array.from({ length: n }, (_, i) => { const x = dv[read[1]](at + i * read[0], true); return scaled ? x * slope + inter : x; });
  return { hash: fnv1a(values), count: n };
}

// `folder` dropped on the view as a dropped directory is (webkitGetAsEntry,
// createReader, readEntries), as dicom.test.mjs does.
async function dropFolder(page, folder) {
  const names = fs.readdirSync(folder).sort();
  await page.evaluate(() => {
    if (document.getElementById('drop-files')) return;
    const input = Object.assign(document.createElement('input'), { type: 'file', multiple: true, id: 'drop-files' });
    input.hidden = true;
    document.body.appendChild(input);
  });
  await page.setInputFiles('#drop-files', names.map((n) => path.join(folder, n)));
  await page.evaluate((folderName) => {
    const files = Array.from(document.getElementById('drop-files').files);
    const fileEntry = (f) => ({ isFile: true, isDirectory: false, name: f.name, file: (ok) => ok(f) });
    const dir = { isFile: false, isDirectory: true, name: folderName, createReader() {
      let given = false;
      return { readEntries: (ok) => { const b = given ? [] : files.map(fileEntry); given = true; ok(b); } };
    } };
    const e = new Event('drop', { bubbles: true, cancelable: true });
    Object.defineProperty(e, 'dataTransfer', { value: { types: ['Files'], files: [], items: [{ kind: 'file', webkitGetAsEntry: () => dir }] } });
    document.getElementById('error').hidden = true;
    document.getElementById('view').dispatchEvent(e);
  }, path.basename(folder));
}
