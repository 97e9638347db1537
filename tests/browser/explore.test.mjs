// Browser test: the slice views and the bread-slice region, the grid view
// and the zoom-driven level swap (fixture.mjs serves the site and launches
// Chromium).
import { test } from 'node:test';
import fs from 'node:fs';
import path from 'node:path';
import {
  SIZE, PAGE_SAMPLING, CH2, shots, check, decodePng, psnrAgainst, snapshot, changedFraction,
  differingPixels, meanAbsDiff, openPage, writePilNifti, withoutOverlays, psnrOf, browserSuite,
} from './fixture.mjs';

// One Chromium for the file; checks(f) runs f (context, url, tmp, run) as a test.
const checks = browserSuite();

test('slice views equal `tessera slice`; a region renders like `tessera render --region`', checks(sliceViewsAndRegion));
test('grid view: blocks, moves and refusals', checks(gridView));
test('zoom swap: coarse, medium and native stages, cross-faded, bounded reads', checks(zoomSwapView));

// writePilNifti's volume (40x32 voxels a slice, u8 after the 352-byte
// header) with the voxels of the box [lo, hi) (x, y, z) set to `value`.
function writeMarkedNifti(file, lo, hi, value) {
  writePilNifti(file);
  const bytes = fs.readFileSync(file);
  const [nx, ny] = [40, 32];
  for (let z = lo[2]; z < hi[2]; z++) for (let y = lo[1]; y < hi[1]; y++) for (let x = lo[0]; x < hi[0]; x++) bytes[352 + x + nx * (y + ny * z)] = value;
  fs.writeFileSync(file, bytes);
}

// Slice views and the bread-slice region (issue 15 item 6). A PIL NIfTI
// (writePilNifti's, anisotropic voxels) with a bright cube near its
// (+x, +y, +z) index corner: the page's axial, coronal and sagittal images
// through the cube equal `tessera slice` PNGs of the same file and index
// pixel for pixel, with the same edge letters; a box dragged in a slice
// view renders like `tessera render --region` of that box; the overview then
// shows it as a red box; a one-finger drag pages through the slices.
async function sliceViewsAndRegion(context, url, tmp, run) {
  const t = Date.now();
  const file = path.join(tmp, 'marked.nii');
  writeMarkedNifti(file, [32, 24, 18], [36, 28, 22], 255);
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

// Grid view in the page (issue 15 items 3 and 6; Schultz 2016 §7.3), with
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
  writeMarkedNifti(file, [30, 12, 10], [37, 18, 16], 250);
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

// The zoom-driven level swap (issue 15 item 4) on the head, with budgets
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
