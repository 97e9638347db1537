// Browser test of the web viewer: playwright-core drives Debian's
// headless Chromium (SwiftShader WebGL) against build-web/site served on
// localhost. Every check measures something; any failure exits 1.
//
//   node viewer.test.mjs            the test (scripts/browser-test.sh runs it)
//   node viewer.test.mjs --bench    also times ch2 at 512x512 in WebGL 2 and 1
//
// Environment: TESSERA_CLI (native tessera, for the reference image and test
// files; default build/tessera), TESSERA_SITE (default build-web/site),
// CHROMIUM (default /usr/bin/chromium), TESSERA_SHOTS (write screenshots there).
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import http from 'node:http';
import zlib from 'node:zlib';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const cli = process.env.TESSERA_CLI || path.join(root, 'build/tessera');
const site = process.env.TESSERA_SITE || path.join(root, 'build-web/site');
const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';
const shots = process.env.TESSERA_SHOTS || '';
const bench = process.argv.includes('--bench');
const SIZE = 256;
const VOLUME = 'gen:shepp-logan:96';
// The page samples adaptively but post-classified (webDefaultSampling() in
// web/src/WebViewer.cpp); CLI renders compared with the page's own frames
// take the same sampling.
const PAGE_SAMPLING = ['--preintegrate', 'off'];
const CH2 = '/usr/share/mricron/templates/ch2.nii.gz';

let failures = 0;
const t0 = Date.now();
function check(name, ok, detail) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${name}${detail ? ` — ${detail}` : ''}`);
  if (!ok) failures++;
}

// The site, and under /data/ the test's files (one origin, so the page may
// fetch them with ?url=), with Content-Length for the page's progress bar.
const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript',
  '.css': 'text/css', '.wasm': 'application/wasm', '.png': 'image/png', '.json': 'application/json' };
// Data prefixes serve their folder trees (an OME-Zarr store is one); a test
// may slow some paths down (served.delayMs) and count what was served.
const served = { delayMs: () => 0, fails: () => false, requests: 0, bytes: 0, paths: [] };
async function serve(dir, dataDirs) {
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
        res.writeHead(500, { 'Content-Type': 'text/plain' });
        res.end('injected failure');
        return;
      }
      if (err || !st.isFile()) {
        res.writeHead(404, { 'Content-Type': 'text/plain' });
        res.end('not found');
        return;
      }
      served.bytes += st.size;
      res.writeHead(200, { 'Content-Type': TYPES[path.extname(file)] || 'application/octet-stream',
        'Content-Length': st.size, 'Cache-Control': 'no-store' });
      fs.createReadStream(file).pipe(res);
    }, served.delayMs(p)));
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  return { server, url: `http://127.0.0.1:${server.address().port}` };
}

// A PNG decoded by the browser: {width, height, data (RGBA)}.
function decodePng(page, pngPath) {
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
async function psnrAgainst(page, pngPath) {
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
async function snapshot(page) {
  return page.evaluate(() => {
    const p = window.tessera.pixels();
    let lit = 0;
    for (let i = 0; i < p.length; i += 4) if (p[i] + p[i + 1] + p[i + 2] > 24) lit++;
    return { pixels: Array.from(p), lit: lit / (p.length / 4) };
  });
}
// Fraction of pixels where some channel differs by more than 8 levels.
function changedFraction(a, b) {
  let n = 0;
  for (let i = 0; i < a.length; i += 4) {
    if (Math.abs(a[i] - b[i]) > 8 || Math.abs(a[i + 1] - b[i + 1]) > 8 || Math.abs(a[i + 2] - b[i + 2]) > 8) n++;
  }
  return n / (a.length / 4);
}
// Pixels where some channel differs by more than `tol` levels.
function differingPixels(a, b, tol) {
  let n = 0;
  for (let i = 0; i < a.length; i += 4) {
    if (Math.abs(a[i] - b[i]) > tol || Math.abs(a[i + 1] - b[i + 1]) > tol || Math.abs(a[i + 2] - b[i + 2]) > tol) n++;
  }
  return n;
}
function meanAbsDiff(a, b) {
  let s = 0;
  for (let i = 0; i < a.length; i++) s += Math.abs(a[i] - b[i]);
  return s / a.length;
}

async function openPage(context, base, query) {
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
function writePilNifti(file) {
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
async function openThroughPicker(page, files, name) {
  await page.evaluate(() => { document.getElementById('error').hidden = true; });
  await page.setInputFiles('#file', files);
  await page.waitForFunction((n) => window.tessera.state().name === n || window.tessera.error() !== '',
    name, { timeout: 30000 });
  await page.evaluate(() => window.tessera.render());
  return { state: await page.evaluate(() => window.tessera.state()), error: await page.evaluate(() => window.tessera.error()) };
}

async function withoutOverlays(page) {
  await page.uncheck('#box');
  await page.uncheck('#axes');
  await page.evaluate(() => window.tessera.render());
}

async function main() {
  if (!fs.existsSync(path.join(site, 'tessera.wasm'))) throw new Error(`no web build in ${site} (scripts/web.sh)`);
  if (!fs.existsSync(cli)) throw new Error(`no native tessera at ${cli} (set TESSERA_CLI)`);
  const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'tessera-browser-'));
  const run = (...args) => execFileSync(cli, args, { stdio: ['ignore', 'pipe', 'pipe'] }).toString();
  // Reference images of the page's default view, and files to open.
  // The page samples as `tessera render` does by default, post-classified
  // (WebViewer.cpp: webDefaultSampling()); the CLI pre-integrates lit frames
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

  if (shots) fs.mkdirSync(shots, { recursive: true });
  const { server, url } = await serve(site, { '/data/': tmp, '/templates/': path.dirname(CH2) });
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'tessera-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: chromiumPath,
    headless: true,
    viewport: { width: 1280, height: 900 },
    acceptDownloads: true,
    args: ['--no-sandbox', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--disable-quic',
      '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
  try {
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
    const setSampling = (preint, adaptive) => page.evaluate(async ([p, a]) => {
      document.getElementById('preint').checked = p;
      document.getElementById('adaptive').checked = a;
      document.getElementById('adaptive').dispatchEvent(new Event('change'));
      await window.tessera.render();
    }, [preint, adaptive]);
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
    const setLines = (box, axes) => page.evaluate(async ([b, a]) => {
      document.getElementById('box').checked = b;
      document.getElementById('axes').checked = a;
      document.getElementById('axes').dispatchEvent(new Event('change'));
      await window.tessera.render();
    }, [box, axes]);
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

    await inputDuringSlowFrames(context, url);
    await responsiveCanvas(context, url);
    await loadFromUrl(context, url, tmp, run);
    await sliceViewsAndRegion(context, url, tmp, run);
    await gridView(context, url, tmp, run);
    await dicomFolder(context, url, tmp, run);
    await zarrStoreFromUrl(context, url, tmp, run);
    await zarrRegionFromUrl(context, url, tmp, run);
    await zarrGridFromUrl(context, url, tmp, run);
    await zarrSlicesFromUrl(context, url, tmp, run);
    await zoomSwapView(context, url);
    await shadingAndCrop(context, url, tmp, run);

    if (bench) await benchmark(context, url);
  } finally {
    await context.close();
    server.close();
    fs.rmSync(profile, { recursive: true, force: true });
    fs.rmSync(tmp, { recursive: true, force: true });
  }
  console.log(`browser test: ${failures ? `${failures} FAILED` : 'all passed'} in ${((Date.now() - t0) / 1000).toFixed(1)} s`);
  process.exit(failures ? 1 : 0);
}

// Slice views and the bread-slice region. A PIL NIfTI
// (writePilNifti's, anisotropic voxels) with a bright cube near its
// (+x, +y, +z) index corner: the page's axial, coronal and sagittal images
// through the cube equal `tessera slice` PNGs of the same file and index
// pixel for pixel, with the same edge letters; a box dragged in a slice
// view renders like `tessera render --region` of that box; the overview then
// shows it as a red box; a one-finger drag pages through the slices.
async function sliceViewsAndRegion(context, url, tmp, run) {
  const t = Date.now();
  const file = path.join(tmp, 'marked.nii');
  writePilNifti(file);
  const bytes = fs.readFileSync(file);
  const [nx, ny] = [40, 32];
  for (let z = 18; z < 22; z++) for (let y = 24; y < 28; y++) for (let x = 32; x < 36; x++) bytes[352 + x + nx * (y + ny * z)] = 255;
  fs.writeFileSync(file, bytes);
  const { page, logs } = await openPage(context, url, `size=${SIZE}&url=/data/marked.nii`);
  const slices = () => page.evaluate(() => window.tessera.slices.state());
  const decode = (png) => decodePng(page, png);

  const cross = [33, 25, 19];  // through the cube
  await page.evaluate((v) => window.tessera.slices.setCross(...v), cross);
  let st = await slices();
  const rows = [];
  let allOk = true;
  for (let axis = 0; axis < 3; axis++) {
    const png = path.join(tmp, `slice-${axis}.png`);
    const cli = JSON.parse(run('slice', file, '--axis', 'xyz'[axis], '--index', String(cross[axis]), '--out', png, '--json'));
    const plane = Object.keys(st.panels).find((q) => st.panels[q].axis === axis);
    const ref = await decode(png);
    const shown = await page.evaluate((q) => window.tessera.slices.imagePixels(q), plane);
    const f = st.panels[plane].frame;
    const sameSize = f.width === ref.width && f.height === ref.height && shown.length === ref.data.length;
    const db = sameSize ? psnrOf(shown, ref.data) : 0;
    const differing = sameSize ? differingPixels(shown, ref.data, 0) : -1;
    const letters = st.panels[plane].letters;
    const lettersOk = ['left', 'right', 'top', 'bottom'].every((e) => letters[e] === cli.edges[e] && letters[e] !== '');
    // The cube lies posterior, inferior and left of the patient: bottom
    // right in all three views of the radiological convention.
    let n = 0, sx = 0, sy = 0;
    for (let i = 0; i < shown.length; i += 4) {
      if (shown[i] === 255) { n++; sx += (i / 4) % f.width; sy += Math.floor(i / 4 / f.width); }
    }
    const quadrant = n > 0 && sx / n > f.width / 2 && sy / n > f.height / 2;
    const ok = plane === cli.plane && sameSize && db >= 50 && lettersOk && quadrant;
    allOk = allOk && ok;
    rows.push(`${plane} ${'xyz'[axis]}=${cross[axis]} ${f.width}x${f.height}: ${differing} pixels differ (${db === 999 ? 'identical' : `${db.toFixed(1)} dB`}), ` +
              `letters ${['left', 'right', 'top', 'bottom'].map((e) => letters[e]).join('')} (CLI ${cli.plane} ` +
              `${['left', 'right', 'top', 'bottom'].map((e) => cli.edges[e]).join('')}), ` +
              `cube ${quadrant ? 'bottom right' : 'NOT bottom right'} (${n} pixels)`);
  }
  check('slice views equal `tessera slice` (pixels >= 50 dB, plane, edge letters; a posterior-inferior-left cube bottom right in each)', allOk, rows.join('; '));
  // In the TF's colours: as `tessera slice --tf` with the page's TF (mr-default).
  await page.check('#sliceColour');
  await page.evaluate(() => window.tessera.render());
  const colourPng = path.join(tmp, 'slice-colour.png');
  run('slice', file, '--axis', 'z', '--index', String(cross[2]), '--tf', 'mr-default', '--out', colourPng);
  const colourRef = await decode(colourPng);
  st = await slices();
  const zPlane = Object.keys(st.panels).find((q) => st.panels[q].axis === 2);
  const colourShown = await page.evaluate((q) => window.tessera.slices.imagePixels(q), zPlane);
  const colourDb = colourShown.length === colourRef.data.length ? psnrOf(colourShown, colourRef.data) : 0;
  check('a slice in the TF\'s colours equals `tessera slice --tf mr-default` (>= 50 dB)', colourDb >= 50,
        `${zPlane} z=${cross[2]}: ${colourDb === 999 ? 'identical' : `${colourDb.toFixed(1)} dB`}`);
  await page.uncheck('#sliceColour');
  await page.evaluate(() => window.tessera.render());

  // One finger dragging up in the coronal view pages through its slices.
  const coronal = st.panels.coronal;
  const before = await page.evaluate(() => window.tessera.slices.imagePixels('coronal'));
  await page.locator('#slice-coronal').scrollIntoViewIfNeeded();
  const ob = await page.locator('#slice-coronal .slice-overlay').boundingBox();
  const cdp = await context.newCDPSession(page);
  const tx = Math.round(ob.x + ob.width / 2), ty = Math.round(ob.y + ob.height * 0.7);
  const touch = (type, dy) => cdp.send('Input.dispatchTouchEvent', {
    type, touchPoints: type === 'touchEnd' ? [] : [{ x: tx, y: ty - dy, id: 7 }] });
  await touch('touchStart', 0);
  for (const dy of [10, 20, 30, 40, 50]) await touch('touchMove', dy);
  await touch('touchEnd', 0);
  st = await slices();
  const after = await page.evaluate(() => window.tessera.slices.imagePixels('coronal'));
  const moved = st.cross[coronal.axis] - cross[coronal.axis];
  check('a one-finger drag in a slice view changes its slice (pointer events from touch)',
        moved > 0 && changedFraction(before, after) > 0.01,
        `${'xyz'[coronal.axis]} ${cross[coronal.axis]} -> ${st.cross[coronal.axis]} after 50 px up, ` +
        `${(100 * changedFraction(before, after)).toFixed(1)} % of the coronal image changed`);
  await page.evaluate((v) => window.tessera.slices.setCross(...v), cross);

  // A region dragged in the axial view: at most 16 voxels each way (the
  // side), 16 deep around its slice.
  const regionPixels = async () => page.evaluate(() => {
    const p = window.tessera.slices.framePixels();  // the box is drawn by depth in the frame
    let n = 0;
    for (let i = 0; i < p.length; i += 4) if (p[i + 3] > 128 && p[i] > 200 && p[i + 1] < 70 && p[i + 2] < 70) n++;
    return n;
  });
  await withoutOverlays(page);
  const redBefore = await regionPixels();
  st = await slices();
  const ax = st.panels.axial;
  await page.evaluate(() => { window.tessera.slices.setRegionSide(16); });
  await page.click('#pickRegion');
  await page.locator('#slice-axial').scrollIntoViewIfNeeded();
  const ab = await page.locator('#slice-axial .slice-overlay').boundingBox();
  // Image pixels -> page coordinates.
  const at = (ix, iy) => [ab.x + ax.fit.left + ix * ax.fit.scale, ab.y + ax.fit.top + iy * ax.fit.scale];
  const [x0, y0] = at(0.2 * ax.frame.width, 0.15 * ax.frame.height);
  const [x1, y1] = at(0.75 * ax.frame.width, 0.6 * ax.frame.height);
  await page.mouse.move(x0, y0);
  await page.mouse.down();
  await page.mouse.move(x1, y1, { steps: 4 });
  await page.mouse.up();
  await page.waitForFunction(() => window.tessera.slices.state().showing_region || window.tessera.error() !== '',
    null, { timeout: 20000 });
  const pickError = await page.evaluate(() => window.tessera.error());
  if (pickError) throw new Error(`picking a region: ${pickError}`);
  await page.evaluate(() => window.tessera.render());
  st = await slices();
  const r = st.region;
  const spec = [0, 1, 2].map((a) => `${r.begin[a]}:${r.end[a]}`).join(',');
  const s3d = await page.evaluate(() => window.tessera.state());
  const refPng = path.join(tmp, 'native-region.png');
  run('render', file, '--region', spec, '--tf', 'mr-default', '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl2', ...PAGE_SAMPLING, '--out', refPng);
  const m = await psnrAgainst(page, refPng);
  const size = [0, 1, 2].map((a) => r.end[a] - r.begin[a]);
  check('a box dragged in the axial view renders like `tessera render --region` of it (PSNR >= 50 dB)',
        m.psnr >= 50 && s3d.dims.join('x') === size.join('x') && size[ax.axis] === 16 && size.every((d) => d > 1 && d <= 16),
        m.error || `region ${spec} (${size.join('x')} voxels, 3D view ${s3d.dims.join('x')}): ${m.psnr.toFixed(2)} dB`);

  await page.click('#overview');
  await page.waitForFunction(() => !window.tessera.slices.state().showing_region, null, { timeout: 20000 });
  await page.evaluate(() => window.tessera.render());
  const back = await page.evaluate(() => window.tessera.state());
  const redAfter = await regionPixels();
  check('Overview returns to the whole volume and shows the region as a red box',
        back.dims.join('x') === '40x32x24' && redBefore === 0 && redAfter > SIZE / 2,
        `3D view ${back.dims.join('x')}; ${redBefore} red overlay pixels before the pick, ${redAfter} after`);
  // The box is composed with the volume by depth (the viewer's lines, not a
  // 2D overlay): inside an opaque volume most of it is hidden, inside a
  // clear one it shows whole.
  const tfKept = await page.evaluate(() => JSON.stringify(window.tessera.tf()));
  const redWith = async (alpha) => {
    await page.evaluate((tf) => window.tessera.setTfJson(tf), JSON.stringify({ name: 'uniform', opacity_unit_length: 1,
      color: [{ x: 0, rgb: [0.2, 0.3, 0.9] }, { x: 1, rgb: [0.9, 0.9, 0.2] }], opacity: [{ x: 0, alpha }, { x: 1, alpha }] }));
    await page.evaluate(() => window.tessera.render());
    return regionPixels();
  };
  const redOpaque = await redWith(1), redClear = await redWith(0);
  await page.evaluate((tf) => window.tessera.setTfJson(tf), tfKept);
  check('the region box in the 3D view is composed by depth: hidden inside an opaque volume, whole in a clear one',
        redClear > SIZE / 2 && redOpaque < 0.5 * redClear,
        `${redOpaque} red pixels in an opaque volume, ${redClear} in a clear one`);
  // On a phone (390x844): one view at a time under tabs; the axial tab
  // shows the axial slice across the screen, and a tap moves the crosshair
  // to the voxel under the finger.
  await cdp.send('Emulation.setDeviceMetricsOverride', { width: 390, height: 844, deviceScaleFactor: 3, mobile: true });
  await page.evaluate((v) => window.tessera.slices.setCross(...v), cross);
  await page.click('#view-tabs button[data-tab="axial"]');
  const phone = await page.evaluate(() => {
    const box = (id) => document.getElementById(id).getBoundingClientRect();
    return { axial: box('slice-axial').width, view: box('view').width, coronal: box('slice-coronal').width, page: document.documentElement.scrollWidth };
  });
  await page.locator('#slice-axial').scrollIntoViewIfNeeded();
  const pb = await page.locator('#slice-axial .slice-overlay').boundingBox();
  const ps = (await slices()).panels.axial;
  // Tap at image pixel (4.5, 4.5): the voxel of the top-left corner's pixels.
  const tap = [Math.round(pb.x + ps.fit.left + 4.5 * ps.fit.scale), Math.round(pb.y + ps.fit.top + 4.5 * ps.fit.scale)];
  await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: [{ x: tap[0], y: tap[1], id: 3 }] });
  await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
  const tapped = (await slices()).cross;
  // The axial view's top left is the patient's right and anterior: in this
  // PIL volume low z (z runs left) and low x (x runs posterior); pixel 4
  // is voxel x 4 (1.5 mm pixels and voxels), z 3 (2 mm voxels).
  const expected = [4, cross[1], 3];
  await cdp.send('Emulation.clearDeviceMetricsOverride');
  check('phone (390x844): tabs show one view across the screen; a tap moves the crosshair',
        phone.axial > 300 && phone.axial <= 390 && phone.view === 0 && phone.coronal === 0 && phone.page <= 390 &&
        tapped.join() === expected.join(),
        `axial ${phone.axial.toFixed(0)} CSS px wide, 3D view and coronal hidden, page ${phone.page} px; ` +
        `tap at the top-left pixels -> crosshair (${tapped.join(', ')}), expected (${expected.join(', ')})`);
  const errors = logs.filter((l) => l.startsWith('pageerror') || l.startsWith('error'));
  check('no script errors on the slice-view page', errors.length === 0, errors.join(' | '));
  await page.close();

  if (shots && fs.existsSync(CH2)) {
    // The page as a user sees it: the head, a region rendered at native
    // resolution, then the overview with the region highlighted; and the
    // axial tab on a phone.
    const { page: p2 } = await openPage(context, url, 'url=/templates/ch2.nii.gz');
    await p2.setViewportSize({ width: 1280, height: 1220 });  // the controls' Slices and region too
    await p2.evaluate(async () => {
      window.tessera.slices.setCross(70, 120, 95);
      await window.tessera.slices.showRegion({ begin: [40, 90, 70], end: [100, 150, 130] });
      await window.tessera.setCamera(35, 15, 1);
    });
    await p2.screenshot({ path: path.join(shots, 'web-region-native.jpg'), type: 'jpeg', quality: 85 });
    await p2.evaluate(async () => {
      await window.tessera.slices.overview();
      await window.tessera.setCamera(35, 15, 1);
    });
    await p2.screenshot({ path: path.join(shots, 'web-slices-region.jpg'), type: 'jpeg', quality: 85 });
    const cdp2 = await context.newCDPSession(p2);
    await cdp2.send('Emulation.setDeviceMetricsOverride', { width: 390, height: 844, deviceScaleFactor: 2, mobile: true });
    await p2.click('#view-tabs button[data-tab="axial"]');
    await p2.evaluate(() => window.tessera.render());
    const phoneShot = await cdp2.send('Page.captureScreenshot', { format: 'jpeg', quality: 80 });
    fs.writeFileSync(path.join(shots, 'web-phone-axial.jpg'), Buffer.from(phoneShot.data, 'base64'));
    await p2.close();
  }
  console.log(`     (slice views and region: ${((Date.now() - t) / 1000).toFixed(1)} s)`);
}

// Grid view in the page (Schultz 2016 §7.3), with
// the native lod::GridNavigator through tessera_grid_*: a PIL NIfTI of
// 40x32x24 voxels (writePilNifti's, a bright cube added at high x) in cells
// of 8 voxels (5x4x3 cells, grid points 0..5 x 0..4 x 0..3). Entering at
// the crosshair (the centre voxel 20,16,12) stands on the nearest point
// (3,2,2): its 2x2x2 block, voxels 16:32,8:24,8:24, renders like
// `tessera render --region` of that box. From the front (azimuth 0,
// elevation 0: looking posterior, and index x runs posterior in a PIL
// file) Forward is +x: the block moves one cell (8 voxels) along x and
// nothing else. At the +x face a further Forward is refused, the block and
// the image stay and the page says why. On a phone the pad's buttons fit
// the screen and a tap moves. Overview shows the block as a cyan box.
async function gridView(context, url, tmp, run) {
  const t = Date.now();
  const file = path.join(tmp, 'grid.nii');
  writePilNifti(file);
  const bytes = fs.readFileSync(file);
  const [nx, ny] = [40, 32];
  for (let z = 10; z < 16; z++) for (let y = 12; y < 18; y++) for (let x = 30; x < 37; x++) bytes[352 + x + nx * (y + ny * z)] = 250;
  fs.writeFileSync(file, bytes);
  const { page, logs } = await openPage(context, url, `size=${SIZE}&url=/data/grid.nii`);
  const grid = () => page.evaluate(() => window.tessera.slices.grid.state());
  const cyanPixels = async () => page.evaluate(() => {
    const p = window.tessera.slices.grid.framePixels();  // the box is drawn by depth in the frame
    let n = 0;
    for (let i = 0; i < p.length; i += 4) if (p[i + 3] > 128 && p[i] < 110 && p[i + 1] > 170 && p[i + 2] > 190) n++;
    return n;
  });
  const boxSpec = (b) => [0, 1, 2].map((a) => `${b.begin[a]}:${b.end[a]}`).join(',');
  await withoutOverlays(page);
  await page.evaluate(() => window.tessera.setCamera(0, 0, 1));
  await page.evaluate(() => window.tessera.slices.setCross(20, 16, 12));
  const cyanBefore = await cyanPixels();

  // Enter (the button, after setting the cell side in its field).
  await page.fill('#gridCell', '8');
  await page.click('#gridEnter');
  await page.waitForFunction(() => window.tessera.slices.grid.state().active || window.tessera.error() !== '', null, { timeout: 20000 });
  const enterError = await page.evaluate(() => window.tessera.error());
  if (enterError) throw new Error(`entering the grid view: ${enterError}`);
  await page.evaluate(() => window.tessera.render());
  let g = await grid();
  let s3d = await page.evaluate(() => window.tessera.state());
  const first = '16:32,8:24,8:24';
  const refPng = path.join(tmp, 'grid-block.png');
  run('render', file, '--region', first, '--tf', 'mr-default', '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl2', ...PAGE_SAMPLING, '--out', refPng);
  let m = await psnrAgainst(page, refPng);
  const padShown = await page.locator('#grid-pad').isVisible();
  check('G enters the grid view: the 2x2x2 block around the point nearest the crosshair renders like `tessera render --region` of it (PSNR >= 50 dB)',
        g.active && g.point.join() === '3,2,2' && g.cells.join() === '5,4,3' && boxSpec(g.block) === first &&
        s3d.dims.join('x') === '16x16x16' && m.psnr >= 50 && padShown,
        m.error || `point (${g.point.join(', ')}) ${g.point_class}, block ${boxSpec(g.block)} (3D view ${s3d.dims.join('x')}): ${m.psnr.toFixed(2)} dB; pad ${padShown ? 'shown' : 'HIDDEN'}`);

  // Forward from the front: +x, one cell. The other labels follow from the
  // PIL axes too: the screen's right is the patient's left (+z), up is
  // superior (-y).
  const labels = await page.evaluate(() => Array.from(document.querySelectorAll('#grid-pad button[data-move]'))
    .map((b) => `${b.dataset.move}:${b.textContent.trim().replace(/\s+/g, ' ')}`));
  const forwardLabel = labels.find((l) => l.startsWith('0:'));
  const before = await snapshot(page);
  await page.click('#grid-pad button[data-move="0"]');
  await page.evaluate(() => window.tessera.render());
  const g2 = await grid();
  const after = await snapshot(page);
  const db = [0, 1, 2].map((a) => g2.block.begin[a] - g.block.begin[a]);
  const de = [0, 1, 2].map((a) => g2.block.end[a] - g.block.end[a]);
  const movedRef = path.join(tmp, 'grid-moved.png');
  run('render', file, '--region', boxSpec(g2.block), '--tf', 'mr-default', '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl2', ...PAGE_SAMPLING, '--out', movedRef);
  const m2 = await psnrAgainst(page, movedRef);
  check('from the front the buttons read Forward +x, Right +z (patient left), Up -y (superior); Forward moves the block one cell (8 voxels) along x only, rendered like the CLI (>= 50 dB)',
        forwardLabel === '0:Forward +x' && labels.join() === '4:Up -y,0:Forward +x,5:Down +y,2:Left -z,1:Back -x,3:Right +z' && g2.point.join() === '4,2,2' && db.join() === '8,0,0' && de.join() === '8,0,0' &&
        m2.psnr >= 50 && changedFraction(before.pixels, after.pixels) > 0.01,
        m2.error || `buttons ${labels.join(', ')}; block ${boxSpec(g.block)} -> ${boxSpec(g2.block)}: ${m2.psnr.toFixed(2)} dB, ` +
        `${(100 * changedFraction(before.pixels, after.pixels)).toFixed(1)} % of the view changed`);

  // The arrow key to the +x face (point x 5), then once more: refused.
  await page.keyboard.press('ArrowUp');
  await page.waitForFunction(() => window.tessera.slices.grid.state().point[0] === 5, null, { timeout: 20000 });
  await page.evaluate(() => window.tessera.render());
  const atFace = await grid();
  const faceShot = await snapshot(page);
  await page.keyboard.press('ArrowUp');
  await page.evaluate(() => window.tessera.render());
  const refused = await grid();
  const stillShot = await snapshot(page);
  const note = (await page.locator('#gridNote').textContent()).trim();
  const noteVisible = await page.locator('#gridNote').isVisible();
  const forwardMarked = await page.evaluate(() => document.querySelector('#grid-pad button[data-move="0"]').classList.contains('illegal'));
  check('at the +x face Forward (ArrowUp) is refused: the block and the image stay, the reason shows in the page',
        atFace.point.join() === '5,2,2' && boxSpec(atFace.block) === '32:40,8:24,8:24' && refused.point.join() === '5,2,2' &&
        boxSpec(refused.block) === boxSpec(atFace.block) && refused.refused && noteVisible && /\+x face/.test(note) &&
        forwardMarked && meanAbsDiff(faceShot.pixels, stillShot.pixels) < 0.01,
        `${atFace.describe}; "${note}"; forward button ${forwardMarked ? 'marked illegal' : 'NOT marked'}`);

  // A phone (390x844): the pad's six buttons fit the screen, at least 44 px
  // tall, under the 3D view; a tap on Back moves the block back.
  const cdp = await context.newCDPSession(page);
  await cdp.send('Emulation.setDeviceMetricsOverride', { width: 390, height: 844, deviceScaleFactor: 3, mobile: true });
  await cdp.send('Emulation.setTouchEmulationEnabled', { enabled: true, maxTouchPoints: 5 });
  await page.click('#view-tabs button[data-tab="3d"]');
  await page.locator('#grid-pad').scrollIntoViewIfNeeded();
  const phone = await page.evaluate(() => {
    const r = (e) => e.getBoundingClientRect();
    const buttons = Array.from(document.querySelectorAll('#grid-pad button[data-move]')).map(r);
    return { buttons: buttons.map((b) => [b.left, b.right, b.height]), view: r(document.getElementById('view')).bottom,
      pad: r(document.getElementById('grid-pad')).top, page: document.documentElement.scrollWidth };
  });
  const backBox = await page.locator('#grid-pad button[data-move="1"]').boundingBox();
  const tap = [Math.round(backBox.x + backBox.width / 2), Math.round(backBox.y + backBox.height / 2)];
  await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: [{ x: tap[0], y: tap[1], id: 5 }] });
  await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
  await page.waitForFunction(() => window.tessera.slices.grid.state().point[0] === 4, null, { timeout: 5000 }).catch(() => {});
  const tapped = await grid();
  await cdp.send('Emulation.setTouchEmulationEnabled', { enabled: false });
  await cdp.send('Emulation.clearDeviceMetricsOverride');
  const fits = phone.buttons.every(([l, r, h]) => l >= 0 && r <= 390 && h >= 44) && phone.page <= 390 && phone.pad >= phone.view - 1;
  check('phone (390x844): the six move buttons fit the screen under the 3D view (>= 44 px tall) and a tap on Back moves back (-x)',
        fits && tapped.point.join() === '4,2,2',
        `buttons x ${phone.buttons.map(([l, r, h]) => `${l.toFixed(0)}-${r.toFixed(0)}/${h.toFixed(0)}px`).join(' ')}, page ${phone.page} px; ` +
        `tap -> point (${tapped.point.join(', ')}), "${tapped.note}"`);

  // One action back: the overview, with the block as a cyan box.
  await page.click('#gridLeave');
  await page.waitForFunction(() => !window.tessera.slices.grid.state().active, null, { timeout: 20000 });
  await page.evaluate(() => window.tessera.render());
  const back = await page.evaluate(() => window.tessera.state());
  const cyanAfter = await cyanPixels();
  const last = await grid();
  check('Overview returns to the whole volume and shows the last block as a cyan box',
        back.dims.join('x') === '40x32x24' && cyanBefore === 0 && cyanAfter > SIZE / 2 && boxSpec(last.block) === '24:40,8:24,8:24',
        `3D view ${back.dims.join('x')}; block ${boxSpec(last.block)}; ${cyanBefore} cyan overlay pixels before, ${cyanAfter} after`);
  const errors = logs.filter((l) => l.startsWith('pageerror') || l.startsWith('error'));
  check('no script errors on the grid-view page', errors.length === 0, errors.join(' | '));
  await page.close();
  if (shots && fs.existsSync(CH2)) {
    // The head: a grid block after one move forward, then the overview with
    // the block's cyan box; and the move pad on a phone.
    const { page: p2 } = await openPage(context, url, 'url=/templates/ch2.nii.gz');
    await p2.setViewportSize({ width: 1280, height: 1220 });
    await p2.evaluate(async () => {
      window.tessera.slices.setCross(70, 120, 95);
      await window.tessera.setCamera(35, 15, 1);
      await window.tessera.slices.grid.enter();
      await window.tessera.slices.grid.move(0);
    });
    await p2.screenshot({ path: path.join(shots, 'web-grid-block.jpg'), type: 'jpeg', quality: 85 });
    await p2.evaluate(() => window.tessera.slices.grid.leave());
    await p2.screenshot({ path: path.join(shots, 'web-grid-overview.jpg'), type: 'jpeg', quality: 85 });
    const cdp2 = await context.newCDPSession(p2);
    await cdp2.send('Emulation.setDeviceMetricsOverride', { width: 390, height: 844, deviceScaleFactor: 2, mobile: true });
    await p2.evaluate(() => window.tessera.slices.grid.enter());
    await p2.evaluate(() => window.tessera.render());
    const phoneShot = await cdp2.send('Page.captureScreenshot', { format: 'jpeg', quality: 80 });
    fs.writeFileSync(path.join(shots, 'web-phone-grid.jpg'), Buffer.from(phoneShot.data, 'base64'));
    await p2.close();
  }
  console.log(`     (grid view: ${((Date.now() - t) / 1000).toFixed(1)} s)`);
}

function psnrOf(a, b) {
  let sum = 0;
  for (let i = 0; i < a.length; i += 4) for (let k = 0; k < 3; k++) sum += (a[i + k] - b[i + k]) ** 2;
  const mse = sum / (a.length / 4 * 3);
  return mse === 0 ? 999 : 10 * Math.log10(255 * 255 / mse);
}

// Input during a slow full-quality frame (slice3d on the head): mouse moves
// dispatched at 60 Hz while the frame renders, counted as the page handles
// them; with progressive frames (the default) and, for comparison, without.
async function inputDuringSlowFrames(context, url) {
  if (!fs.existsSync(CH2)) return;
  const SLOW = 256;
  const runs = {};
  for (const progressive of [true, false]) {
    const { page } = await openPage(context, url, `size=${SLOW}&url=/templates/ch2.nii.gz${progressive ? '' : '&progressive=0'}`);
    await page.selectOption('#technique', 'slice3d');
    await page.evaluate(() => window.tessera.render());
    const wholeMs = await page.evaluate(() => { window.tessera.setProgressive(false); return window.tessera.render(); });
    await page.evaluate((on) => window.tessera.setProgressive(on), progressive);
    await page.evaluate(() => {
      window.inputSeen = 0;
      document.getElementById('canvas').addEventListener('pointermove', () => { window.inputSeen++; });
    });
    const box = await page.locator('#canvas').boundingBox();
    // A new full-quality frame (not awaited), then 60 Hz mouse moves over it.
    await page.evaluate(() => { window.tessera.setCamera(25, 5, 1); });
    const framesBefore = await page.evaluate(() => window.tessera.frames());
    const t = Date.now();
    const MOVES = 150;
    // Sent on a 60 Hz clock, not one after the other's acknowledgement
    // (which waits for the next frame the page shows).
    const sent = [];
    for (let i = 0; i < MOVES; i++) {
      sent.push(page.mouse.move(box.x + 20 + (i % 40) * 4, box.y + 30 + (i % 7) * 3));
      const due = t + (i + 1) * 1000 / 60;
      if (Date.now() < due) await new Promise((r) => setTimeout(r, due - Date.now()));
    }
    const seconds = (Date.now() - t) / 1000;
    const seen = await page.evaluate(() => window.inputSeen);
    await Promise.all(sent);
    const stillRefining = await page.evaluate(() => window.tessera.state().refining);
    await page.evaluate(() => window.tessera.render());
    const framesAfter = await page.evaluate(() => window.tessera.frames());
    runs[progressive] = { rate: seen / seconds, seen, seconds, wholeMs, stillRefining, frames: framesAfter - framesBefore,
      pixels: (await snapshot(page)).pixels };
    await page.close();
  }
  const p = runs[true], b = runs[false];
  const same = psnrOf(p.pixels, b.pixels);
  check('input during a slow slice3d full-quality frame: >= 30 events/s handled (progressive frames)',
        p.rate >= 30 && same >= 50,
        `${p.rate.toFixed(1)} events/s (${p.seen} of 150 moves handled in the ${p.seconds.toFixed(1)} s they were sent over; one whole frame takes ` +
        `${p.wholeMs.toFixed(0)} ms at ${SLOW}x${SLOW}); without progressive frames ${b.rate.toFixed(1)} events/s ` +
        `(${b.seen} in ${b.seconds.toFixed(1)} s); finished frame vs whole frame ${same.toFixed(1)} dB`);
}

// Canvas backing size = CSS size x devicePixelRatio, following resizes
// (emulated through the DevTools protocol), and on an emulated phone.
async function responsiveCanvas(context, url) {
  const { page, logs } = await openPage(context, url, '');
  const cdp = await context.newCDPSession(page);
  const metrics = async (width, height, dpr, mobile) => {
    await cdp.send('Emulation.setDeviceMetricsOverride', { width, height, deviceScaleFactor: dpr, mobile });
    await page.evaluate(() => window.tessera.render());
    const m = await page.evaluate(() => {
      const c = document.getElementById('canvas');
      return { w: c.width, h: c.height, cw: c.clientWidth, ch: c.clientHeight, dpr: devicePixelRatio,
               render: window.tessera.state().render_size };
    });
    m.lit = (await snapshot(page)).lit;
    m.ok = m.dpr === dpr && m.w === Math.round(m.cw * dpr) && m.h === Math.round(m.ch * dpr) && m.lit > 0.02;
    m.text = `${m.cw}x${m.ch} CSS px at DPR ${m.dpr}: backing ${m.w}x${m.h}, volume ${m.render.join('x')}, ${(100 * m.lit).toFixed(1)} % lit`;
    return m;
  };
  const wide = await metrics(1200, 860, 2, false);
  const narrow = await metrics(800, 700, 2, false);
  check('canvas backing = CSS size x devicePixelRatio 2, following a window resize',
        wide.ok && narrow.ok && narrow.w < wide.w, `${wide.text}; resized: ${narrow.text}`);
  const phone = await metrics(390, 844, 3, true);
  check('on an emulated phone (390x844, DPR 3) the canvas fits the screen at 3 pixels per CSS pixel',
        phone.ok && phone.cw <= 390, phone.text);
  if (shots) {
    // Through the protocol: Playwright's own screenshot would reset the emulated metrics.
    const shot = await cdp.send('Page.captureScreenshot', { format: 'jpeg', quality: 85 });
    fs.writeFileSync(path.join(shots, 'web-phone.jpg'), Buffer.from(shot.data, 'base64'));
  }
  const errors = logs.filter((l) => l.startsWith('pageerror') || l.startsWith('error'));
  check('no script errors on the responsive page', errors.length === 0, errors.join(' | '));
  await page.close();
}

// ?url=: the head from the test's own server, with progress, rendering like
// the native image; box and axes hidden behind the face; errors for a 404
// and for a file that is not a volume.
async function loadFromUrl(context, url, tmp, run) {
  if (!fs.existsSync(CH2)) { check(`?url= test needs ${CH2} (mricron-data)`, false); return; }
  run('render', CH2, '--tf', 'mr-default', '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl2',
      ...PAGE_SAMPLING, '--out', path.join(tmp, 'native-ch2.png'));
  const { page, logs } = await openPage(context, url, `size=${SIZE}&url=/templates/ch2.nii.gz`);
  const s = await page.evaluate(() => window.tessera.state());
  const load = await page.evaluate(() => window.tessera.lastLoad());
  const bytes = fs.statSync(CH2).size;
  check('?url= loads a served file with progress', s.name === 'ch2.nii.gz' && s.dims.join('x') === '181x217x181' &&
        load.bytes === bytes && load.total === bytes && load.updates >= 1,
        `${s.description}; ${load.bytes} of ${load.total} bytes in ${load.updates} progress updates`);
  await withoutOverlays(page);
  const plain = (await snapshot(page)).pixels;
  const m = await psnrAgainst(page, path.join(tmp, 'native-ch2.png'));
  check('?url= volume renders like the native image (PSNR >= 50 dB)', m.psnr >= 50, m.error || `${m.psnr.toFixed(2)} dB`);
  await page.check('#box');
  await page.check('#axes');
  await page.evaluate(() => window.tessera.render());
  const lined = (await snapshot(page)).pixels;
  // The face: pixels the volume lights; lines behind it must not change them.
  let face = 0, changed = 0, all = 0;
  for (let i = 0; i < plain.length; i += 4) {
    const d = Math.max(Math.abs(plain[i] - lined[i]), Math.abs(plain[i + 1] - lined[i + 1]), Math.abs(plain[i + 2] - lined[i + 2]));
    if (d > 8) all++;
    if (plain[i] + plain[i + 1] + plain[i + 2] > 150) { face++; if (d > 8) changed++; }
  }
  check('front view of the head: box and axes behind the face are not drawn over it',
        face > SIZE * SIZE / 8 && changed <= face * 0.002 && all > 2 * SIZE,
        `${changed} of ${face} face pixels changed by the lines (${all} pixels in all)`);
  if (shots) await page.locator('#view').screenshot({ path: path.join(shots, 'web-ch2-lines-by-depth.png') });
  const errors = logs.filter((l) => l.startsWith('pageerror') || l.startsWith('error'));
  check('no script errors on the ?url= page', errors.length === 0, errors.join(' | '));
  await page.close();

  fs.writeFileSync(path.join(tmp, 'notes.txt'), 'these are notes, not a volume\n');
  for (const [file, expect] of [['missing.nii', '404'], ['notes.txt', '']]) {
    const target = `${url}/data/${file}`;
    const p = await openPage(context, url, `size=64&url=${encodeURIComponent(target)}`);
    const msg = await p.page.evaluate(() => window.tessera.error());
    const visible = await p.page.locator('#error').isVisible();
    check(`?url= ${file === 'notes.txt' ? 'of a file that is not a volume' : 'that answers 404'}: a visible error naming the URL`,
          visible && msg.includes(target) && msg.includes(expect), `"${msg}"`);
    await p.page.close();
  }
}

// A DICOM series in the browser: ch2 written as a folder by
// `tessera convert`, dropped on the view as a folder (a drop event whose
// item is a directory entry, walked like a real one: webkitGetAsEntry,
// createReader, readEntries) and picked through the folder picker
// (webkitdirectory); each render must match the NIfTI's (>= 35 dB). A
// dropped folder with a broken slice shows an error naming the file.
async function dicomFolder(context, url, tmp, run) {
  if (!fs.existsSync(CH2)) { check(`DICOM folder test needs ${CH2} (mricron-data)`, false); return; }
  const folder = path.join(tmp, 'ch2-dicom');
  run('convert', CH2, `${folder}/`);
  const names = fs.readdirSync(folder).sort();
  const { page, logs } = await openPage(context, url, `size=${SIZE}`);
  await openThroughPicker(page, [CH2], 'ch2.nii.gz');
  await withoutOverlays(page);
  const nifti = (await snapshot(page)).pixels;
  // The folder's files as File objects in the page, for the drop.
  await page.evaluate(() => {
    const input = Object.assign(document.createElement('input'), { type: 'file', multiple: true, id: 'dicom-files' });
    input.hidden = true;
    document.body.appendChild(input);
  });
  await page.setInputFiles('#dicom-files', names.map((n) => path.join(folder, n)));
  const drop = async (folderName, which) => {
    await page.evaluate(({ folderName, which }) => {
      const files = Array.from(document.getElementById('dicom-files').files).filter((f, i) => which === null || i === which);
      const fileEntry = (f) => ({ isFile: true, isDirectory: false, name: f.name, file: (ok) => ok(f) });
      const dir = { isFile: false, isDirectory: true, name: folderName, createReader() {
        let given = false;  // readEntries in batches until an empty one, as browsers do
        return { readEntries: (ok) => { const b = given ? [] : files.map(fileEntry); given = true; ok(b); } };
      } };
      const e = new Event('drop', { bubbles: true, cancelable: true });
      Object.defineProperty(e, 'dataTransfer', { value: { files: [], items: [{ kind: 'file', webkitGetAsEntry: () => dir }] } });
      document.getElementById('error').hidden = true;
      document.getElementById('view').dispatchEvent(e);
    }, { folderName, which });
  };
  const shown = async (name) => {
    await page.waitForFunction((n) => window.tessera.state().name === n || window.tessera.error() !== '', name, { timeout: 60000 });
    await page.evaluate(() => window.tessera.render());
    return { state: await page.evaluate(() => window.tessera.state()), error: await page.evaluate(() => window.tessera.error()),
      pixels: (await snapshot(page)).pixels };
  };
  const t = Date.now();
  await drop('ch2-dicom', null);
  const dropped = await shown(`ch2-dicom/${names[0]}`);
  const dropMs = Date.now() - t;
  const dropPsnr = psnrOf(dropped.pixels, nifti);
  check('a dropped DICOM folder (ch2) renders like the NIfTI of the same head (PSNR >= 35 dB)',
        !dropped.error && dropped.state.dims.join('x') === '181x217x181' && dropPsnr >= 35,
        dropped.error || `${dropPsnr.toFixed(2)} dB, ${names.length} files in ${dropMs} ms; ${dropped.state.description.slice(0, 90)}…`);
  // The folder picker (webkitdirectory), the same series.
  await openThroughPicker(page, [CH2], 'ch2.nii.gz');
  await page.evaluate(() => { document.getElementById('error').hidden = true; });
  await page.setInputFiles('#folder', folder);
  const picked = await shown(`ch2-dicom/${names[0]}`);
  const pickPsnr = psnrOf(picked.pixels, nifti);
  check('a DICOM folder opened with the folder picker renders like the NIfTI (PSNR >= 35 dB)',
        !picked.error && pickPsnr >= 35, picked.error || `${pickPsnr.toFixed(2)} dB`);
  // A broken slice: the file cut short, alone in a dropped folder.
  const cut = fs.readFileSync(path.join(folder, names[0]));
  fs.writeFileSync(path.join(tmp, names[0]), cut.subarray(0, cut.length - 1000));
  await page.setInputFiles('#dicom-files', [path.join(tmp, names[0])]);
  await drop('broken', 0);
  await page.waitForFunction(() => window.tessera.error() !== '', null, { timeout: 30000 });
  const msg = await page.evaluate(() => window.tessera.error());
  check('a dropped DICOM folder with a truncated slice: a visible error naming the file',
        (await page.locator('#error').isVisible()) && msg.includes(`broken/${names[0]}`) && msg.includes('truncated'), `"${msg}"`);
  const errors = logs.filter((l) => l.startsWith('pageerror') || l.startsWith('error'));
  check('no script errors on the DICOM page', errors.length === 0, errors.join(' | '));
  await page.close();
}

// ?url= of an OME-Zarr store: ch2 written by `tessera convert
// --compressor zlib`, served as a folder tree and read key by key with
// fetch(). The finest level's chunks are served 0.75 s late, so the page must
// show the coarser levels first; it then refines to what the native CLI
// renders of the same store (bricks layout, same profile). A chunk that
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
        z.last.complete && JSON.stringify(lastCells) === JSON.stringify(nativeCells) && changedFraction(coarse.pixels, fine.pixels) > 0.02,
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
  for (const codec of ['blosc', 'zstd']) {
    run('convert', CH2, path.join(tmp, `ch2-${codec}.ome.zarr`), '--compressor', codec);
    const p = await openPage(context, url, `size=${SIZE}&url=/data/ch2-${codec}.ome.zarr`);
    await p.page.waitForFunction(() => window.tessera.zarr().completeMs !== null || window.tessera.error() !== '',
                                 null, { timeout: 60000 });
    await withoutOverlays(p.page);
    const zc = await p.page.evaluate(() => window.tessera.zarr());
    const mc = await psnrAgainst(p.page, nativePng);
    const error = await p.page.evaluate(() => window.tessera.error());
    check(`OME-Zarr ?url= of a ${codec} store (decoded by numcodecs in the page) matches the native render (PSNR >= 50 dB)`,
          !error && zc.last && zc.last.complete && mc.psnr >= 50,
          error || mc.error || `${mc.psnr.toFixed(2)} dB, refined in ${zc.completeMs.toFixed(0)} ms, ${zc.requests} requests`);
    await p.page.close();
  }
}

// Light and clip controls: shade on matches `tessera render
// --shade`; dragging the crop box's superior handle down with the mouse
// lowers the top face (the slider follows), and the cropped image matches
// `tessera render --crop` of the box the page reports.
async function shadingAndCrop(context, url, tmp, run) {
  const { page } = await openPage(context, url, `size=${SIZE}`);
  await withoutOverlays(page);
  const plain = await snapshot(page);
  await page.check('#shade');
  await page.evaluate(() => window.tessera.render());
  const shadedPng = path.join(tmp, 'native-shaded.png');
  run('render', VOLUME, '--tf', 'mr-default', '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl2', '--shade',
      ...PAGE_SAMPLING, '--out', shadedPng);
  const ms = await psnrAgainst(page, shadedPng);
  const shaded = await snapshot(page);
  check('shade on in the page matches `tessera render --shade` (PSNR >= 50 dB) and changes the image',
        ms.psnr >= 50 && changedFraction(plain.pixels, shaded.pixels) > 0.05,
        ms.error || `${ms.psnr.toFixed(2)} dB, ${(100 * changedFraction(plain.pixels, shaded.pixels)).toFixed(1)} % of pixels changed`);

  // Gradient opacity on (and the light still on), as the CLI's
  // --gradient-opacity 0.02,0.08; then off again.
  await page.check('#gradOpacity');
  await page.evaluate(() => {
    document.getElementById('gradLow').value = 0.02;
    document.getElementById('gradHigh').value = 0.08;
    document.getElementById('gradHigh').dispatchEvent(new Event('input'));
  });
  await page.evaluate(() => window.tessera.render());
  const gradPng = path.join(tmp, 'native-gradient-opacity.png');
  run('render', VOLUME, '--tf', 'mr-default', '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl2', '--shade',
      '--gradient-opacity', '0.02,0.08', ...PAGE_SAMPLING, '--out', gradPng);
  const mg = await psnrAgainst(page, gradPng);
  const graded = await snapshot(page);
  await page.uncheck('#gradOpacity');
  await page.evaluate(() => window.tessera.render());
  check('gradient opacity in the page matches `tessera render --gradient-opacity 0.02,0.08` (PSNR >= 50 dB) and fades interiors',
        mg.psnr >= 50 && changedFraction(shaded.pixels, graded.pixels) > 0.02,
        mg.error || `${mg.psnr.toFixed(2)} dB, ${(100 * changedFraction(shaded.pixels, graded.pixels)).toFixed(1)} % of pixels changed`);

  await page.check('#cropShow');
  await page.evaluate(() => window.tessera.render());
  const before = await page.evaluate(() => window.tessera.crop());
  const top = before.handles[5];  // +z: superior, at the top of the front view
  await page.locator('#canvas').scrollIntoViewIfNeeded();  // the controls scrolled the page
  const box = await page.locator('#canvas').boundingBox();
  const css = box.width / SIZE;
  await page.mouse.move(box.x + top[0] * css, box.y + top[1] * css);
  await page.mouse.down();
  for (let k = 1; k <= 4; k++) await page.mouse.move(box.x + top[0] * css, box.y + (top[1] + 20 * k) * css);
  await page.mouse.up();
  await page.uncheck('#cropShow');  // the image without the box's lines
  await page.evaluate(() => window.tessera.render());
  const after = await page.evaluate(() => window.tessera.crop());
  const slider = +(await page.locator('#cropZ1').inputValue());
  const cam = await page.evaluate(() => window.tessera.state().camera);
  check('dragging the superior crop handle down lowers the top face only; the slider follows; the camera stays',
        top[1] < SIZE / 2 && after.max[2] < before.max[2] - 0.1 && after.max[0] === 1 && after.max[1] === 1 &&
        after.min.every((v) => v === 0) && Math.abs(slider - after.max[2]) <= 0.006 &&
        cam.azimuth === 0 && cam.elevation === 0,
        `handle at ${top.map((v) => v.toFixed(1))}, z max ${before.max[2]} -> ${after.max[2].toFixed(4)}, slider ${slider}`);
  const cropPng = path.join(tmp, 'native-crop.png');
  run('render', VOLUME, '--tf', 'mr-default', '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl2', '--shade',
      '--crop', `0:1,0:1,0:${after.max[2].toPrecision(17)}`, ...PAGE_SAMPLING, '--out', cropPng);
  const mc = await psnrAgainst(page, cropPng);
  const cropped = await snapshot(page);
  check('the dragged crop box matches `tessera render --crop` (PSNR >= 50 dB) and removes part of the image',
        mc.psnr >= 50 && cropped.lit < shaded.lit - 0.02,
        mc.error || `${mc.psnr.toFixed(2)} dB, lit ${(100 * shaded.lit).toFixed(1)} % -> ${(100 * cropped.lit).toFixed(1)} %`);

  // Labels: the phantom's integer values as a label volume (default palette),
  // then a label text file that hides all but two labels.
  await page.uncheck('#shade');
  await page.evaluate(() => document.getElementById('resetCrop').click());
  // Slice views: grey before, the label colours with labels on.
  const colouredSlicePixels = () => page.evaluate(() => {
    const planes = ['axial', 'coronal', 'sagittal'];
    let n = 0;
    for (const q of planes) {
      const p = window.tessera.slices.imagePixels(q);
      for (let i = 0; i < p.length; i += 4) if (Math.max(p[i], p[i + 1], p[i + 2]) - Math.min(p[i], p[i + 1], p[i + 2]) > 40) n++;
    }
    return n;
  });
  const greySlices = await colouredSlicePixels();
  await page.check('#labels');
  await page.evaluate(() => window.tessera.render());
  const labelSlices = await colouredSlicePixels();
  check('the slice views show a label volume in its label colours (grey before)', greySlices === 0 && labelSlices > 100,
        `${greySlices} coloured slice pixels before, ${labelSlices} with labels on`);
  const labelsPng = path.join(tmp, 'native-labels.png');
  run('render', VOLUME, '--labels', '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl2', '--out', labelsPng);
  const ml = await psnrAgainst(page, labelsPng);
  const rows = await page.locator('#labelList input').count();
  const labelsShot = await snapshot(page);
  check('labels on in the page match `tessera render --labels` (PSNR >= 40 dB), one row per label',
        ml.psnr >= 40 && rows > 2 && labelsShot.lit > 0.02,
        ml.error || `${ml.psnr.toFixed(2)} dB, ${rows} labels listed, ${(100 * labelsShot.lit).toFixed(1)} % lit`);
  // The phantom's values (multiples of 25.5, rounded) as the default list shows them.
  const values = await page.$$eval('#labelList input', (boxes) => boxes.map((b) => +b.dataset.value));
  const tablePath = path.join(tmp, 'labels.txt');
  fs.writeFileSync(tablePath, `# ITK-SNAP\n${values[0]} 255 0 0 1 1 1 "first"\n${values[1]} 0 0 255 1 1 1 "second"\n`);
  await page.setInputFiles('#labelFile', tablePath);
  await page.evaluate(() => window.tessera.render());
  const tablePng = path.join(tmp, 'native-labels-table.png');
  run('render', VOLUME, '--labels', tablePath, '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl2', '--out', tablePng);
  const mt = await psnrAgainst(page, tablePng);
  const rowsT = await page.locator('#labelList input').count();
  const withTable = await snapshot(page);
  // One label inside the other may be hidden by it: unchecking both boxes leaves the background.
  for (let k = 0; k < rowsT; k++) await page.locator('#labelList input').nth(k).uncheck();
  await page.evaluate(() => window.tessera.render());
  const hidden = await snapshot(page);
  const changed = changedFraction(withTable.pixels, hidden.pixels);
  check('a label table file loads through the same parser (PSNR >= 40 dB vs the CLI); unchecking its labels leaves the background',
        mt.psnr >= 40 && rowsT === 2 && withTable.lit > 0.02 && changed > 0.02 && hidden.lit < 0.001,
        mt.error || `${mt.psnr.toFixed(2)} dB, ${rowsT} labels (${values[0]}, ${values[1]}), ${(100 * withTable.lit).toFixed(1)} % lit, unchecked: ${(100 * changed).toFixed(2)} % of pixels changed, ${(100 * hidden.lit).toFixed(2)} % lit`);
  await page.close();
  if (shots && fs.existsSync(CH2)) await viewerControlShots(context, url);
}

// docs/viewers.md's web screenshots (TESSERA_SHOTS only): ch2 shaded, cropped
// with the handles shown, MinIP and average, with the controls beside.
async function viewerControlShots(context, url) {
  const { page } = await openPage(context, url, 'size=420');
  await page.setViewportSize({ width: 1600, height: 1000 });
  // Controls set from script: in the 2x2 layout the slice views may cover them.
  const setBox = (id, on) => page.evaluate(([id, on]) => {
    const e = document.getElementById(id);
    e.checked = on;
    e.dispatchEvent(new Event('change'));
  }, [id, on]);
  const setSelect = (id, v) => page.evaluate(([id, v]) => {
    const e = document.getElementById(id);
    e.value = v;
    e.dispatchEvent(new Event('change'));
  }, [id, v]);
  await page.setInputFiles('#file', CH2);
  await page.waitForFunction(() => window.tessera.state().name === 'ch2.nii.gz', null, { timeout: 60000 });
  const setRange = (id, v) => page.evaluate(([id, v]) => {
    const e = document.getElementById(id);
    e.value = v;
    e.dispatchEvent(new Event('input'));
  }, [id, v]);
  const shot = async (name) => {
    await page.evaluate(() => window.tessera.render());
    await page.screenshot({ path: path.join(shots, name), type: 'jpeg', quality: 80 });
  };
  await setBox('shade', true);
  await page.evaluate(() => window.tessera.setCamera(30, 10, 1));
  await shot('web-shaded.jpg');
  await setBox('cropShow', true);
  await setRange('cropZ1', 0.62);
  await setRange('cropY1', 0.7);
  await page.evaluate(() => window.tessera.setCamera(-60, 30, 1));
  await shot('web-crop-handles.jpg');
  await setBox('cropShow', false);
  await page.evaluate(() => document.getElementById('resetCrop').click());
  await setBox('shade', false);
  await setSelect('preset', 'grey');
  await setSelect('mode', '2');  // MinIP inside a box around the ventricles
  for (const [id, v] of [['cropX0', 0.25], ['cropX1', 0.75], ['cropY0', 0.25], ['cropY1', 0.75], ['cropZ0', 0.3], ['cropZ1', 0.8]]) {
    await setRange(id, v);
  }
  await page.evaluate(() => window.tessera.setCamera(0, 0, 2));
  await shot('web-minip.jpg');
  await page.evaluate(() => document.getElementById('resetCrop').click());
  await page.evaluate(() => window.tessera.setCamera(0, 0, 1));
  await setSelect('mode', '3');
  await shot('web-average.jpg');
  // The aal atlas as labels with mricron's names (only where mricron-data has it).
  const aal = '/usr/share/mricron/templates/aal.nii.gz';
  if (fs.existsSync(aal)) {
    await setSelect('mode', '0');
    await page.setInputFiles('#file', aal);
    await page.waitForFunction(() => window.tessera.state().name === 'aal.nii.gz', null, { timeout: 60000 });
    await page.setInputFiles('#labelFile', '/usr/share/mricron/templates/aal.nii.txt');
    await page.evaluate(() => window.tessera.setCamera(40, 20, 1));
    // The whole page: the view at the top, the Labels list further down.
    await page.evaluate(() => window.tessera.render());
    await page.evaluate(() => window.scrollTo(0, 0));
    await page.screenshot({ path: path.join(shots, 'web-labels-aal.jpg'), type: 'jpeg', quality: 75, fullPage: true });
  }
  await page.close();
}

// The bread-slice region of a served store: the slice views show
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
  const meta = JSON.parse(fs.readFileSync(path.join(store, '0', '.zarray'), 'utf8'));
  const chunk = [...meta.chunks].reverse();  // x, y, z
  const expected = [];
  for (let cz = Math.floor(begin[2] / chunk[2]); cz * chunk[2] < end[2]; cz++) {
    for (let cy = Math.floor(begin[1] / chunk[1]); cy * chunk[1] < end[1]; cy++) {
      for (let cx = Math.floor(begin[0] / chunk[0]); cx * chunk[0] < end[0]; cx++) {
        expected.push(`/data/ch2.ome.zarr/0/${cz}/${cy}/${cx}`);
      }
    }
  }
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

// The level-0 chunk keys of a store's box [begin, end) (x, y, z).
function chunkKeys(store, begin, end) {
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

// Grid view on a store: each 2x2x2 block is read at level 0 with
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

// The zoom-driven level swap on the head, with budgets
// small enough for all three stages (overview 1 Mi voxels: medium level 1,
// coarse level 2; native blocks of 64³): zooming in goes coarse -> medium ->
// native block, each swap cross-faded over several frames (no frame changes
// the picture by more than a fraction of the swap's jump), the reads are
// bounded (never level 0 whole), the slice views keep the whole volume, and
// turning it off restores the whole volume's image at the same camera.
async function zoomSwapView(context, url) {
  if (!fs.existsSync(CH2)) return;
  const t = Date.now();
  const { page, logs } = await openPage(context, url, `size=${SIZE}&url=/templates/ch2.nii.gz`);
  await withoutOverlays(page);
  const zoomState = () => page.evaluate(() => window.tessera.slices.grid.zoomState());
  const on = await page.evaluate(() => window.tessera.slices.grid.zoomSwap(true, { overviewVoxels: 1 << 20, blockVoxels: 1 << 18 }));
  let z = await zoomState();
  if (!on || !z.active || z.stages.length !== 3) {
    check('zoom swap: three stages on the head', false, `${await page.evaluate(() => window.tessera.error())} ${JSON.stringify(z)}`);
    await page.close();
    return;
  }
  const stagesText = z.stages.map((st) => `${st.native ? 'native' : `${st.name} L${st.level}`} from ${st.enter_zoom.toFixed(2)}`).join(', ');
  // Zooms to `zoom` and renders frame after frame (in one task: the page's
  // own loop cannot interleave) until the fade ends: per frame the stage, the
  // mix and the PSNR against the frame before; and the PSNR of the first
  // frame (mix 0: the old stage) against the last (the swap's whole jump).
  const zoomTo = (zoom) => page.evaluate((zm) => {
    const psnr = (a, b) => {
      let sum = 0;
      for (let i = 0; i < a.length; i += 4) for (let k = 0; k < 3; k++) sum += (a[i + k] - b[i + k]) ** 2;
      const mse = sum / (a.length / 4 * 3);
      return mse === 0 ? 999 : 10 * Math.log10(255 * 255 / mse);
    };
    window.tessera.setCamera(30, 15, zm);  // not awaited: the frames below are the swap's
    const out = [];
    let first = null;
    let last = null;
    for (let i = 0; i < 60; i++) {
      window.tessera.timeFrames(1);
      const st = window.tessera.slices.grid.zoomState();
      const px = window.tessera.pixels();
      out.push({ stage: st.shown_stage, mix: st.mix, step: last ? psnr(last, px) : 999 });
      if (!first) first = px;
      last = px;
      if (i >= 1 && !st.fading && st.target === st.shown_stage) break;
    }
    return { frames: out, jump: psnr(first, last) };
  }, zoom);
  const [z0, z1, z2] = [0.5 * z.stages[1].enter_zoom, Math.sqrt(z.stages[1].enter_zoom * z.stages[2].enter_zoom), 1.25 * z.stages[2].enter_zoom];
  // The whole volume at zoom z0 (the swap off), then on again at z0.
  await page.evaluate(() => window.tessera.slices.grid.zoomSwap(false));
  await page.evaluate((zm) => window.tessera.setCamera(30, 15, zm), z0);
  const before = { state: await page.evaluate(() => window.tessera.state()), shot: await snapshot(page) };
  await page.evaluate(() => window.tessera.slices.grid.zoomSwap(true, { overviewVoxels: 1 << 20, blockVoxels: 1 << 18 }));
  await zoomTo(z0);
  const atStart = await zoomState();
  const fadeCheck = (what, swap, want) => {
    const seq = swap.frames;
    const fading = seq.filter((f) => f.mix > 0 && f.mix < 1).length;
    const end = seq[seq.length - 1];
    const worst = Math.min(...seq.slice(1).map((f) => f.step));
    check(`zoom swap: ${what}: cross-faded over ${fading} frames, no frame changes the view as much as the swap (each step >= the jump + 6 dB)`,
          seq[0].stage === want && seq[0].mix === 0 && end.stage === want && end.mix === 1 && fading >= 2 && worst >= swap.jump + 6,
          `stage@mix ${seq.map((f) => `${f.stage}@${f.mix.toFixed(2)}`).join(' ')}; smallest frame-to-frame PSNR ${worst.toFixed(1)} dB, whole swap ${swap.jump.toFixed(1)} dB`);
  };
  const toMedium = await zoomTo(z1);
  fadeCheck(`coarse L2 -> medium L1 at zoom ${z1.toFixed(2)}`, toMedium, 1);
  const toNative = await zoomTo(z2);
  fadeCheck(`medium L1 -> the native 64³ block at zoom ${z2.toFixed(2)}`, toNative, 2);
  z = await zoomState();
  const s3d = await page.evaluate(() => window.tessera.state());
  const ex = await page.evaluate(() => window.tessera.slices.state().explore);
  const blockVoxels = z.block ? [0, 1, 2].reduce((n, a) => n * (z.block.end[a] - z.block.begin[a]), 1) : 0;
  const levels = [[91, 109, 91], [46, 55, 46]].reduce((n, d) => n + d[0] * d[1] * d[2], 0);
  check('zoom swap: the native stage is a 2x2x2 block of level 0 (bounded reads: the two levels and the block, never level 0 whole); the slices keep the whole head',
        atStart.shown_stage === 0 && z.shown_stage === 2 && blockVoxels === 64 ** 3 && s3d.dims.join('x') === '64x64x64' &&
        z.voxels_read === levels + blockVoxels && z.voxels_read < z.whole_voxels / 2 && ex.dims.join('x') === '181x217x181',
        `stages ${stagesText}; block ${z.block ? [0, 1, 2].map((a) => `${z.block.begin[a]}:${z.block.end[a]}`).join(',') : 'none'}, ` +
        `${z.voxels_read} voxels read of ${z.whole_voxels}; 3D view ${s3d.dims.join('x')}, slices ${ex.dims.join('x')}`);
  // Back out and off: the whole volume at the same camera, as before.
  await zoomTo(z0);
  await page.evaluate(() => window.tessera.slices.grid.zoomSwap(false));
  await page.evaluate((zm) => window.tessera.setCamera(30, 15, zm), z0);
  const after = { state: await page.evaluate(() => window.tessera.state()), shot: await snapshot(page) };
  const unchecked = await page.evaluate(() => !document.getElementById('zoomSwap').checked);
  const db = psnrOf(before.shot.pixels, after.shot.pixels);
  check('zoom swap: off gives the whole volume back (its name, and the image before the zoom swap at the same camera, >= 50 dB)',
        after.state.dims.join('x') === '181x217x181' && after.state.name === before.state.name && unchecked && db >= 50,
        `3D view ${after.state.dims.join('x')} "${after.state.name}", ${db.toFixed(1)} dB`);
  const errors = logs.filter((l) => l.startsWith('pageerror') || l.startsWith('error'));
  check('zoom swap: no script errors', errors.length === 0, errors.join(' | '));
  await page.close();
  console.log(`     (zoom swap: ${((Date.now() - t) / 1000).toFixed(1)} s)`);
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

main().catch((e) => {
  console.error(`browser test: error: ${e.stack || e}`);
  process.exit(1);
});
