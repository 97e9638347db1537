// Browser test: input during slow frames, the responsive canvas, ?url=
// loads, shading, the crop box and label volumes (fixture.mjs serves the
// site and launches Chromium).
import { test } from 'node:test';
import fs from 'node:fs';
import path from 'node:path';
import {
  SIZE, VOLUME, PAGE_SAMPLING, CH2, shots, check, served, psnrAgainst, snapshot, changedFraction,
  openPage, withoutOverlays, psnrOf, browserSuite,
} from './fixture.mjs';

// One Chromium for the file; checks(f) runs f (context, url, tmp, run) as a test.
const checks = browserSuite();

test('input during slow full-quality frames', checks(inputDuringSlowFrames));
test('canvas backing size follows CSS size and devicePixelRatio', checks(responsiveCanvas));
test('?url= loads a served file; errors name the URL', checks(loadFromUrl));
test('shading, gradient opacity, the crop box and label volumes match the CLI', checks(shadingAndCrop));

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

// Light and clip controls (issue 16): shade on matches `tessera render
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
