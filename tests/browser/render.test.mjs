// Browser test: the page's 3D view on WebGL 2 and WebGL 1 (render.test.mjs
// of tests/browser; fixture.mjs serves the site and launches Chromium).
import { test } from 'node:test';
import fs from 'node:fs';
import path from 'node:path';
import zlib from 'node:zlib';
import {
  SIZE, VOLUME, CH2, shots, bench, check, psnrAgainst, snapshot, changedFraction, differingPixels,
  meanAbsDiff, openPage, writePilNifti, openThroughPicker, withoutOverlays, setCheckboxes, browserSuite,
} from './fixture.mjs';

// One Chromium for the file; checks(f) runs f (context, url, tmp, run) as a test.
const checks = browserSuite();

test('WebGL 2 and WebGL 1 pages match the native renderer; controls, formats and errors', checks(webglPages));
test('benchmark: ch2 at 512x512 (TESSERA_BENCH=1 or scripts/browser-test.sh --bench)', { skip: !bench }, checks(benchmark));

// The default view on WebGL 2 and WebGL 1 against the native renderer, the
// controls (sampling, lines by depth, drag, pinch, TF editor and its file),
// and every file format through the picker and drops (the shared io
// readers), with errors for unreadable files.
async function webglPages(context, url, tmp, run) {
  // Reference images of the page's default view, and files to open.
  // The page samples as `tessera render` does by default, post-classified
  // (WebSession.cpp: webDefaultSampling()); the CLI pre-integrates lit frames
  // by default, and every frame with --preintegrate on.
  run('render', VOLUME, '--tf', 'mr-default', '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl2',
      '--preintegrate', 'off', '--out', path.join(tmp, 'native-webgl2.png'));
  run('render', VOLUME, '--tf', 'mr-default', '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl1',
      '--preintegrate', 'off', '--out', path.join(tmp, 'native-webgl1.png'));
  run('render', VOLUME, '--tf', 'mr-default', '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl2',
      '--preintegrate', 'on', '--out', path.join(tmp, 'native-webgl2-preint.png'));
  run('convert', 'gen:shepp-logan:64', path.join(tmp, 'phantom64.nrrd'));
  run('convert', 'gen:sphere:48', path.join(tmp, 'sphere48.nii.gz'));
  const goodNii = path.join(tmp, 'sphere40.nii');
  run('convert', 'gen:sphere:40', goodNii);
  // Unreadable files: a NIfTI cut short, and bytes that claim to be gzip.
  fs.writeFileSync(path.join(tmp, 'truncated.nii'), fs.readFileSync(goodNii).subarray(0, 20000));
  fs.writeFileSync(path.join(tmp, 'broken.nii.gz'), Buffer.from([0x1f, 0x8b, 8, 0, 1, 2, 3, 4, 5, 6, 7]));
  const dicom = Buffer.alloc(200);
  dicom.write('DICM', 128, 'latin1');
  fs.writeFileSync(path.join(tmp, 'slice.dcm'), dicom);

  // One volume with a PIL affine in every format the page reads through the
  // shared io readers: as `tessera convert` writes them (NRRD gzip,
  // MetaImage zlib, VTI zlib appended, raw + JSON sidecar), and NRRD and
  // MetaImage with their data uncompressed.
  const pil = path.join(tmp, 'pil.nii');
  writePilNifti(pil);
  for (const out of ['pil.nii.gz', 'pil.nrrd', 'pil.mha', 'pil.vti', 'pil.raw']) run('convert', pil, path.join(tmp, out));
  const unpack = (from, to, edit, inflate) => {
    const bytes = fs.readFileSync(path.join(tmp, from));
    const end = bytes.indexOf(edit.end) + edit.end.length;
    let header = bytes.subarray(0, end).toString('latin1');
    for (const [a, b] of edit.replace) header = header.replace(a, b);
    fs.writeFileSync(path.join(tmp, to), Buffer.concat([Buffer.from(header, 'latin1'), inflate(bytes.subarray(end))]));
  };
  unpack('pil.nrrd', 'pil-raw.nrrd', { end: '\n\n', replace: [['encoding: gzip', 'encoding: raw']] }, zlib.gunzipSync);
  unpack('pil.mha', 'pil-raw.mha', { end: 'ElementDataFile = LOCAL\n',
    replace: [['CompressedData = True', 'CompressedData = False'], [/CompressedDataSize = \d+\n/, '']] }, zlib.inflateSync);
  const formats = [
    { what: '.nii', files: ['pil.nii'] },
    { what: '.nii.gz', files: ['pil.nii.gz'] },
    { what: '.nrrd (raw)', files: ['pil-raw.nrrd'] },
    { what: '.nrrd (gzip)', files: ['pil.nrrd'] },
    { what: '.mha', files: ['pil-raw.mha'] },
    { what: '.mha (zlib)', files: ['pil.mha'] },
    { what: '.vti (zlib appended)', files: ['pil.vti'] },
    { what: 'raw + JSON sidecar (two files)', files: ['pil.raw', 'pil.raw.json'], name: 'pil.raw.json' },
  ];
  for (const f of formats) {
    f.name = f.name || f.files[0];
    f.info = JSON.parse(run('info', '--json', path.join(tmp, f.name)));
  }


  // ---- WebGL 2 page
  const { page, logs } = await openPage(context, url, `size=${SIZE}`);
  let s = await page.evaluate(() => window.tessera.state());
  check('page loads with WebGL 2 (ES 3 path)', s.webgl === 2 && s.api === 'gles3',
        `${s.renderer}; ${s.gl_version}`);
  check('default volume is loaded', s.has_volume && s.dims.join('x') === '96x96x96', s.description);
  let shot = await snapshot(page);
  check('default volume renders (non-black pixels)', shot.lit > 0.1, `${(100 * shot.lit).toFixed(1)} % lit`);

  await withoutOverlays(page);
  const m2 = await psnrAgainst(page, path.join(tmp, 'native-webgl2.png'));
  check('canvas matches the native renderer with the same sampling (adaptive, post-classified; PSNR >= 50 dB)',
        m2.psnr >= 50 && !s.sampling.preintegrate && s.sampling.adaptive,
        m2.error || `${m2.psnr.toFixed(2)} dB; page ${JSON.stringify(s.sampling)}`);
  // The page's "pre-integrated" control on: `tessera render --preintegrate
  // on`'s image, and no longer the post-classified one.
  const setSampling = (preint, adaptive) => setCheckboxes(page, { preint, adaptive });
  await setSampling(true, true);
  const preOwn = await psnrAgainst(page, path.join(tmp, 'native-webgl2-preint.png'));
  const prePost = await psnrAgainst(page, path.join(tmp, 'native-webgl2.png'));
  const preState = (await page.evaluate(() => window.tessera.state())).sampling;
  check('"pre-integrated" on: the canvas matches `tessera render --preintegrate on` (PSNR >= 50 dB), ' +
        'at least 3 dB closer than to the post-classified one',
        preOwn.psnr >= 50 && preOwn.psnr >= prePost.psnr + 3 && preState.preintegrate && preState.adaptive,
        preOwn.error || prePost.error ||
        `${preOwn.psnr.toFixed(2)} dB vs the CLI default, ${prePost.psnr.toFixed(2)} dB vs post-classified`);
  await setSampling(false, true);

  // Lines composed with the volume by depth: an opaque volume seen from
  // the (+x, +y, +z) corner (azimuth 45, elevation 30) hides the axes,
  // which run along the edges at the far, minimum corner; the box's near
  // edges show. Compared with the same frame without lines.
  const setLines = (box, axes) => setCheckboxes(page, { box, axes });
  const uniformTf = (alpha) => JSON.stringify({ name: 'uniform', opacity_unit_length: 1,
    color: [{ x: 0, rgb: [0.2, 0.3, 0.9] }, { x: 1, rgb: [0.9, 0.9, 0.2] }],
    opacity: [{ x: 0, alpha }, { x: 1, alpha }] });
  const tfBeforeLines = await page.evaluate(() => JSON.stringify(window.tessera.tf()));
  await page.evaluate((tf) => window.tessera.setTfJson(tf), uniformTf(1));
  await page.evaluate(() => window.tessera.setCamera(45, 30, 1));
  const linesAt = async (box, axes) => { await setLines(box, axes); return (await snapshot(page)).pixels; };
  const noLines = await linesAt(false, false);
  const axesBehind = await linesAt(false, true);
  const boxLines = await linesAt(true, false);
  if (shots) await page.screenshot({ path: path.join(shots, 'web-lines-depth.png') });
  await page.evaluate((tf) => window.tessera.setTfJson(tf), uniformTf(0));
  const clearNoLines = await linesAt(false, false);
  const clearAxes = await linesAt(false, true);
  const hidden = differingPixels(noLines, axesBehind, 2);
  const near = differingPixels(noLines, boxLines, 8);
  const seen = differingPixels(clearNoLines, clearAxes, 8);
  check('lines by depth: axes behind an opaque volume are hidden, near box edges drawn',
        hidden === 0 && near > 1.5 * SIZE && seen > SIZE / 4,
        `${hidden} pixels changed by the hidden axes (${seen} when the volume is clear), ${near} by the box`);
  await page.evaluate((tf) => window.tessera.setTfJson(tf), tfBeforeLines);
  await page.evaluate(() => window.tessera.setCamera(0, 0, 1));
  await page.check('#box');
  await page.check('#axes');
  await page.evaluate(() => window.tessera.render());

  // Drag on the canvas rotates.
  const before = await snapshot(page);
  const box = await page.locator('#canvas').boundingBox();
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await page.mouse.down();
  await page.mouse.move(box.x + box.width / 2 + 60, box.y + box.height / 2 + 10, { steps: 4 });
  await page.mouse.up();
  await page.evaluate(() => window.tessera.render());
  s = await page.evaluate(() => window.tessera.state());
  const afterDrag = await snapshot(page);
  const dDrag = changedFraction(before.pixels, afterDrag.pixels);
  check('dragging rotates the view', Math.abs(s.camera.azimuth) > 5 && dDrag > 0.02,
        `azimuth ${s.camera.azimuth.toFixed(1)} deg, ${(100 * dDrag).toFixed(1)} % of pixels changed`);

  // Two fingers spreading apart zoom in (pinch), through real touch events.
  const cdp = await context.newCDPSession(page);
  const cx = Math.round(box.x + box.width / 2), cy = Math.round(box.y + box.height / 2);
  const zoomBefore = (await page.evaluate(() => window.tessera.state())).camera.zoom;
  const touch = (type, d) => cdp.send('Input.dispatchTouchEvent', {
    type, touchPoints: type === 'touchEnd' ? [] : [{ x: cx - d, y: cy, id: 1 }, { x: cx + d, y: cy, id: 2 }] });
  await touch('touchStart', 30);
  await touch('touchMove', 45);
  await touch('touchMove', 60);
  await touch('touchEnd', 0);
  await page.evaluate(() => window.tessera.render());
  const zoomAfter = (await page.evaluate(() => window.tessera.state())).camera.zoom;
  check('pinching with two fingers zooms', Math.abs(zoomAfter / zoomBefore - 2) < 0.05,
        `zoom ${zoomBefore.toFixed(2)} -> ${zoomAfter.toFixed(2)}`);
  await page.evaluate(() => window.tessera.setCamera(-24, 4, 1));
  const beforeTf = await snapshot(page);

  // Tap in the TF editor adds an opacity point; the image changes.
  const tfBefore = await page.evaluate(() => window.tessera.tf());
  const tfBox = await page.locator('#tf').boundingBox();
  await page.mouse.click(tfBox.x + 10 + 0.55 * (tfBox.width - 20), tfBox.y + 10 + 0.2 * (tfBox.height - 58));
  await page.evaluate(() => window.tessera.render());
  const tfAfter = await page.evaluate(() => window.tessera.tf());
  const afterTf = await snapshot(page);
  const dTf = changedFraction(beforeTf.pixels, afterTf.pixels);
  check('editing a TF point changes the image',
        tfAfter.opacity.length === tfBefore.opacity.length + 1 && dTf > 0.02,
        `${tfBefore.opacity.length} -> ${tfAfter.opacity.length} opacity points, ` +
        `${(100 * dTf).toFixed(1)} % of pixels changed`);
  // Dragging that point below the box deletes it again.
  const px = tfBox.x + 10 + 0.55 * (tfBox.width - 20), py = tfBox.y + 10 + 0.2 * (tfBox.height - 58);
  await page.mouse.move(px, py);
  await page.mouse.down();
  await page.mouse.move(px, tfBox.y + tfBox.height + 30, { steps: 3 });
  await page.mouse.up();
  const tfDeleted = await page.evaluate(() => window.tessera.tf());
  check('dragging an opacity point out of the editor deletes it',
        tfDeleted.opacity.length === tfBefore.opacity.length, `${tfDeleted.opacity.length} points`);

  // TF JSON: saved as a download, loaded through its picker (the CLI's format).
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#saveTf')]);
  const saved = JSON.parse(fs.readFileSync(await download.path(), 'utf8'));
  const current = await page.evaluate(() => window.tessera.tf());
  const tfFile = path.join(tmp, 'bone.json');
  fs.writeFileSync(tfFile, JSON.stringify({ name: 'two-points', opacity_unit_length: 1,
    color: [{ x: 0, rgb: [0, 0, 0] }, { x: 1, rgb: [1, 0.5, 0.25] }],
    opacity: [{ x: 0, alpha: 0 }, { x: 1, alpha: 0.3 }] }));
  await page.setInputFiles('#loadTf', tfFile);
  await page.waitForFunction(() => window.tessera.tf().name === 'two-points', null, { timeout: 10000 });
  check('TF saves as JSON and loads from a JSON file',
        JSON.stringify(saved) === JSON.stringify(current), `saved ${saved.opacity.length} opacity points`);
  await page.selectOption('#preset', 'mr-default');

  // Files through the picker.
  await page.setInputFiles('#file', path.join(tmp, 'phantom64.nrrd'));
  await page.waitForFunction(() => window.tessera.state().name === 'phantom64.nrrd', null, { timeout: 30000 });
  await page.evaluate(() => window.tessera.render());
  s = await page.evaluate(() => window.tessera.state());
  shot = await snapshot(page);
  check('a .nrrd opened through the picker renders', s.dims.join('x') === '64x64x64' && shot.lit > 0.05,
        `${s.description}; ${(100 * shot.lit).toFixed(1)} % lit`);
  await page.setInputFiles('#file', path.join(tmp, 'sphere48.nii.gz'));
  await page.waitForFunction(() => window.tessera.state().name === 'sphere48.nii.gz', null, { timeout: 30000 });
  await page.evaluate(() => window.tessera.render());
  s = await page.evaluate(() => window.tessera.state());
  shot = await snapshot(page);
  check('a .nii.gz opened through the picker renders (inflated in the browser)',
        s.dims.join('x') === '48x48x48' && shot.lit > 0.02, `${s.description}; ${(100 * shot.lit).toFixed(1)} % lit`);

  // Patient-direction letters at the view's edges follow the camera (a
  // NIfTI carries an orientation; azimuth 0 faces the patient).
  const labels = async () => page.evaluate(() => ['left', 'right', 'top', 'bottom']
    .map((e) => document.getElementById(`orient-${e}`).textContent).join(' '));
  await page.evaluate(() => window.tessera.setCamera(0, 0, 1));
  const front = await labels();
  await page.evaluate(() => window.tessera.setCamera(90, 0, 1));
  const side = await labels();
  check('orientation labels name the patient\'s sides (front: R L S I, from the right: P A S I)',
        front === 'R L S I' && side === 'P A S I', `front "${front}", side "${side}"`);

  // A file dropped on the view opens the same way.
  const dropped = await page.evaluateHandle((b64) => {
    const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
    const dt = new DataTransfer();
    dt.items.add(new File([bytes], 'dropped.nrrd'));
    return dt;
  }, fs.readFileSync(path.join(tmp, 'phantom64.nrrd')).toString('base64'));
  await page.dispatchEvent('#view', 'drop', { dataTransfer: dropped });
  await replaceOnOffer(page);
  await page.waitForFunction(() => window.tessera.state().name === 'dropped.nrrd', null, { timeout: 30000 });
  s = await page.evaluate(() => window.tessera.state());
  check('a file dropped on the view opens', s.dims.join('x') === '64x64x64', s.description);
  await page.setInputFiles('#file', path.join(tmp, 'sphere48.nii.gz'));
  await page.waitForFunction(() => window.tessera.state().name === 'sphere48.nii.gz', null, { timeout: 30000 });
  await page.evaluate(() => window.tessera.render());

  // Every format through the shared readers: it renders, with the dims,
  // orientation and affine that the native `tessera info` reads.
  for (const f of formats) {
    const r = await openThroughPicker(page, f.files.map((n) => path.join(tmp, n)), f.name);
    const st = r.state;
    const lit = (await snapshot(page)).lit;
    const labels = st.orientation_labels || {};
    const affineOk = Array.isArray(st.affine) && st.affine.every((row, i) => row.every((v, k) => Math.abs(v - f.info.affine[i][k]) < 1e-9));
    check(`${f.what} opened through the picker renders like tessera info reads it`,
          !r.error && st.name === f.name && st.dims.join('x') === f.info.dims.join('x') &&
          st.orientation === f.info.orientation && affineOk && lit > 0.02 &&
          ['left', 'right', 'top', 'bottom'].every((e) => labels[e]),
          r.error || `${st.dims.join('x')} ${st.orientation} (native ${f.info.dims.join('x')} ${f.info.orientation}), ` +
          `affine ${affineOk ? 'equal' : 'differs'}, ${(100 * lit).toFixed(1)} % lit; ${st.geometry_source}`);
  }
  // A header and its data dropped together.
  const droppedPair = await page.evaluateHandle((files) => {
    const dt = new DataTransfer();
    for (const [name, b64] of files) dt.items.add(new File([Uint8Array.from(atob(b64), (c) => c.charCodeAt(0))], name));
    return dt;
  }, ['pil.raw.json', 'pil.raw'].map((n) => [n, fs.readFileSync(path.join(tmp, n)).toString('base64')]));
  await openThroughPicker(page, [path.join(tmp, 'sphere48.nii.gz')], 'sphere48.nii.gz');
  await page.dispatchEvent('#view', 'drop', { dataTransfer: droppedPair });
  await replaceOnOffer(page);
  await page.waitForFunction(() => window.tessera.state().name === 'pil.raw.json', null, { timeout: 30000 });
  s = await page.evaluate(() => window.tessera.state());
  check('raw data and its JSON sidecar dropped together open', s.orientation === 'PIL', `${s.dims.join('x')} ${s.orientation}`);
  await page.setInputFiles('#file', path.join(tmp, 'sphere48.nii.gz'));
  await page.waitForFunction(() => window.tessera.state().name === 'sphere48.nii.gz', null, { timeout: 30000 });
  await page.evaluate(() => window.tessera.render());

  // Unreadable files: a message in the page; the previous volume stays.
  for (const bad of ['truncated.nii', 'broken.nii.gz', 'slice.dcm']) {
    const good = await snapshot(page);
    await page.setInputFiles('#file', path.join(tmp, bad));
    await page.waitForFunction(() => window.tessera.error() !== '', null, { timeout: 30000 });
    const msg = await page.evaluate(() => window.tessera.error());
    const visible = await page.locator('#error').isVisible();
    await page.evaluate(() => window.tessera.render());
    s = await page.evaluate(() => window.tessera.state());
    const still = await snapshot(page);
    check(`${bad}: error shown, previous volume stays`,
          visible && msg.includes(bad) && s.name === 'sphere48.nii.gz' && meanAbsDiff(good.pixels, still.pixels) < 0.01,
          `"${msg}"`);
    await page.evaluate(() => { document.getElementById('error').hidden = true; });
  }
  // PVM (no orientation in the file): dims as the native reader sees them.
  run('convert', pil, path.join(tmp, 'pil.pvm'));
  const pvmInfo = JSON.parse(run('info', '--json', path.join(tmp, 'pil.pvm')));
  const pvm = await openThroughPicker(page, [path.join(tmp, 'pil.pvm')], 'pil.pvm');
  const pvmLit = (await snapshot(page)).lit;
  check('.pvm opened through the picker renders', !pvm.error && pvm.state.dims.join('x') === pvmInfo.dims.join('x') && pvmLit > 0.02,
        pvm.error || `${pvm.state.dims.join('x')}, ${(100 * pvmLit).toFixed(1)} % lit`);
  await openThroughPicker(page, [path.join(tmp, 'sphere48.nii.gz')], 'sphere48.nii.gz');
  if (shots) {
    await page.screenshot({ path: path.join(shots, 'web-phantom.png') });
  }
  const errors = logs.filter((l) => l.startsWith('pageerror') || l.startsWith('error'));
  check('no script errors on the page', errors.length === 0, errors.join(' | '));
  await page.close();

  // ---- WebGL 1 (the ES 2.0 path, forced)
  const p1 = await openPage(context, url, `size=${SIZE}&webgl=1`);
  s = await p1.page.evaluate(() => window.tessera.state());
  check('?webgl=1 gives WebGL 1 (ES 2 path, 2D layout)', s.webgl === 1 && s.api === 'gles2' && s.layout !== 'texture3d',
        `${s.layout}: ${s.plan_reason}`);
  await withoutOverlays(p1.page);
  shot = await snapshot(p1.page);
  const m1 = await psnrAgainst(p1.page, path.join(tmp, 'native-webgl1.png'));
  check('WebGL 1 renders and matches the native ES 2 image (PSNR >= 50 dB)', shot.lit > 0.1 && m1.psnr >= 50,
        m1.error || `${m1.psnr.toFixed(2)} dB, ${(100 * shot.lit).toFixed(1)} % lit`);
  await p1.page.close();
}

// ch2 through the picker at 512x512, WebGL 2 and WebGL 1: median of 7 frames.
async function benchmark(context, url) {
  if (!fs.existsSync(CH2)) { console.log(`bench: ${CH2} missing (mricron-data)`); return; }
  for (const webgl of [2, 1]) {
    const { page } = await openPage(context, url, `size=512${webgl === 1 ? '&webgl=1' : ''}`);
    await page.setInputFiles('#file', CH2);
    await page.waitForFunction(() => window.tessera.state().name === 'ch2.nii.gz', null, { timeout: 60000 });
    if (shots) {
      await page.evaluate(() => window.tessera.setCamera(35, 15, 1));
      await page.screenshot({ path: path.join(shots, `web-ch2-webgl${webgl}.png`) });
    }
    const r = await page.evaluate(() => window.tessera.benchmark(7));
    const s = await page.evaluate(() => window.tessera.state());
    console.log(`bench: ch2 512x512 WebGL ${webgl} (${s.layout}; ${s.renderer}): median ${r.median.toFixed(0)} ms, ` +
                `min ${r.min.toFixed(0)}, max ${r.max.toFixed(0)} over ${r.times.length} frames`);
    await page.close();
  }
}

// A file dropped while another file's volume is open is offered as an
// overlay (frontends/web/overlay-panel.js; tests/browser/overlay.test.mjs):
// "Replace" opens it as the volume, as a drop did before.
async function replaceOnOffer(page) {
  const offered = await page.evaluate(() => window.tessera.overlay.promptShown());
  check('a file dropped while another is open is offered (replace or add as overlay)', offered);
  await page.evaluate(() => window.tessera.overlay.choose('replace'));
}
