// Browser test: a second volume over the first in the page (overlay.test.mjs
// of tests/browser; fixture.mjs serves the site and launches Chromium). The
// atlas aal with its table, added over ch2 through the "Add overlay…"
// picker, fused in the 3D view's ray march: the page's frame equals
// `tessera render ch2 --overlay aal --overlay-labels aal.nii.txt` at the same
// camera and crop; the crosshair at (40, -25, 52) mm reads Postcentral_R and
// at (-40, -25, 52) mm Postcentral_L (left and right not swapped); a file
// dropped while ch2 is open is offered as the overlay and added; the
// overlay's look is in the session's state (its restore: tests/session/
// FusionStateTest.cpp); on WebGL 1 the overlay is refused with a message.
// Over an OME-Zarr store of ch2 (`tessera convert`, drawn brick by brick):
// the same atlas fused in the store's ray march equals `tessera render STORE
// --layout bricks --overlay ...`, and the crosshair names both gyri. The
// store's slice views (read at the store's levels) show the atlas too,
// resampled by world coordinates onto each level's slice grid: at level 0
// the three views through the right postcentral gyrus equal the file's
// (in memory) pixel for pixel, and its crosshair readout equals the file's.
import { test } from 'node:test';
import fs from 'node:fs';
import path from 'node:path';
import { execFile } from 'node:child_process';
import { promisify } from 'node:util';
import {
  CH2, cli, check, differingPixels, psnrOf, psnrAgainst, openPage, openThroughPicker, withoutOverlays, writePilNifti, browserSuite,
} from './fixture.mjs';

const AAL = '/usr/share/mricron/templates/aal.nii.gz';
const AAL_NAMES = '/usr/share/mricron/templates/aal.nii.txt';
const SIZE = 192;
const checks = browserSuite();
const have = [CH2, AAL, AAL_NAMES].every((f) => fs.existsSync(f));

test('aal over ch2 in the page: the CLI\'s fused image, the crosshair names the region, a drop offers it',
  { skip: !have && 'needs mricron-data (ch2, aal)' }, checks(overlay));
test('aal over a ch2 OME-Zarr store in the page (bricks): the CLI\'s fused image, the crosshair names the region',
  { skip: !have && 'needs mricron-data (ch2, aal)' }, checks(overlayOverStore));

// The three slice views through the voxel nearest `mm` once none is pending
// (a store's at the level its panels ask for): their pixels, frames and
// the crosshair's readout.
async function slicesThrough(page, mm) {
  const at = await crosshairAt(page, mm);
  await page.waitForFunction(() => Object.values(window.tessera.slices.state().panels).every((p) => p.frame && !p.frame.pending),
    null, { timeout: 30000 }).catch(() => {});
  return page.evaluate((voxel) => {
    const st = window.tessera.slices.state();
    const panels = {};
    for (const [plane, p] of Object.entries(st.panels)) {
      const px = window.tessera.slices.imagePixels(plane);
      let coloured = 0;
      for (let i = 0; i < px.length; i += 4) if (px[i] !== px[i + 1] || px[i + 1] !== px[i + 2]) coloured++;
      panels[plane] = { pixels: px, coloured, width: p.frame.image_width, height: p.frame.image_height,
        level: p.frame.level, pending: !!p.frame.pending, index: p.index };
    }
    return { voxel, text: document.getElementById('crosshairInfo').textContent, panels };
  }, at.voxel);
}
// The file's slice views with aal (overlay()), for the store's (overlayOverStore).
let fileSlices = null;

// The crosshair's readout once it is at the voxel nearest `mm`.
async function crosshairAt(page, mm) {
  return page.evaluate(async (p) => {
    const v = window.tessera.overlay.voxelAtWorld(p[0], p[1], p[2]);
    window.tessera.slices.setCross(v[0], v[1], v[2]);
    return { voxel: v, text: document.getElementById('crosshairInfo').textContent };
  }, mm);
}

async function overlay(context, url, tmp) {
  const t0 = Date.now();
  const laps = [];
  const lap = (what) => laps.push(`${what} ${((Date.now() - t0) / 1000).toFixed(1)} s`);
  const ref = path.join(tmp, 'fused.png');
  // The CLI's reference while the page loads.
  const reference = promisify(execFile)(cli, ['render', CH2, '--overlay', AAL, '--overlay-labels', AAL_NAMES,
    '--overlay-alpha', '0.6', '--tf', 'mr-default', '--preintegrate', 'off', '--azimuth', '90', '--elevation', '20',
    '--crop', '0:0.68,0:1,0:1', '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl2', '--out', ref]);
  const dropped = path.join(tmp, 'ball.nii');  // a small second volume to drop
  writePilNifti(dropped);

  const { page, logs } = await openPage(context, url, `size=${SIZE}`);
  const opened = await openThroughPicker(page, [CH2], 'ch2.nii.gz');
  check('ch2 opens', !opened.error, opened.error);
  lap('ch2 open');
  await withoutOverlays(page);
  await page.evaluate(async () => {
    const menu = document.getElementById('preset');
    menu.value = 'mr-default';
    menu.dispatchEvent(new Event('change'));
    const x1 = document.getElementById('cropX1');
    x1.value = 0.68;
    x1.dispatchEvent(new Event('input'));
    document.getElementById('overlayAlpha').value = 0.6;
    await window.tessera.setCamera(90, 20, 1);
  });

  // The picker: the atlas and its table together (the table turns labels on).
  await page.setInputFiles('#overlayFile', [AAL, AAL_NAMES]);
  await page.waitForFunction(() => window.tessera.overlay.info().open || window.tessera.error() !== '', null, { timeout: 30000 });
  await page.evaluate(() => window.tessera.render());
  const info = await page.evaluate(() => window.tessera.overlay.info());
  const error = await page.evaluate(() => window.tessera.error());
  check('"Add overlay…" opens aal over ch2 as labels with its table (116 names), alpha 0.6',
        info.open && info.labels && info.labels_table.length === 116 && Math.abs(info.alpha - 0.6) < 1e-9 && !error,
        error || `${info.file} ${info.dims && info.dims.join('x')}, ${info.labels_table && info.labels_table.length} names, ` +
        `alpha ${info.alpha}, note "${info.note}", fusion note "${info.fusion_note}"`);
  lap('aal added');
  await reference;
  const m = await psnrAgainst(page, ref);
  check(`the page's fused frame equals tessera render --overlay aal --overlay-labels (PSNR >= 40 dB)`,
        m.psnr >= 40, m.error || `${m.psnr.toFixed(2)} dB`);

  lap('fused frame compared');
  // The slice views mix the overlay in: the grey axial slice gets the labels' colours.
  const coloured = await page.evaluate(() => {
    const px = window.tessera.slices.imagePixels('axial');
    let n = 0;
    for (let i = 0; i < px.length; i += 4) if (px[i] !== px[i + 1] || px[i + 1] !== px[i + 2]) n++;
    return { n, of: px.length / 4 };
  });
  check('the axial slice view shows the atlas\'s colours over the grey anatomy (> 5 % of its pixels)',
        coloured.n > 0.05 * coloured.of, `${coloured.n} of ${coloured.of} pixels coloured`);
  // The crosshair (slice views' readout): position in mm, both values, the region.
  const right = await crosshairAt(page, [40, -25, 52]);
  const left = await crosshairAt(page, [-40, -25, 52]);
  check('the crosshair at (40, -25, 52) mm names Postcentral_R, with its position and both values',
        /Postcentral_R/.test(right.text) && /\(40\.0, -25\.0, 52\.0\) mm/.test(right.text) && /value \d/.test(right.text),
        `voxel ${right.voxel}: "${right.text}"`);
  check('the crosshair at (-40, -25, 52) mm names Postcentral_L (left and right not swapped)',
        /Postcentral_L/.test(left.text) && !/Postcentral_R/.test(left.text), `voxel ${left.voxel}: "${left.text}"`);
  fileSlices = await slicesThrough(page, [40, -25, 52]);

  // The overlay's look is in the session's state, and restored from it.
  const saved = await page.evaluate(() => window.tessera.viewer().sessionState());
  check('the session state holds the overlay (file, labels, table name, alpha)',
        saved && saved.overlay && saved.overlay.file === 'aal.nii.gz' && saved.overlay.labels === true &&
        saved.overlay.label_table_name === 'aal.nii.txt' && Math.abs(saved.overlay.alpha - 0.6) < 1e-9,
        JSON.stringify(saved && saved.overlay));

  lap('crosshair, state');
  // A second file dropped while ch2 is open: the offer, then "Add as overlay".
  await page.evaluate(async () => {
    const input = document.createElement('input');
    input.type = 'file';
    input.id = 'testDrop';
    input.multiple = true;
    input.hidden = true;
    document.body.appendChild(input);
  });
  await page.setInputFiles('#testDrop', [dropped]);
  await page.evaluate(() => {
    const files = document.getElementById('testDrop').files;
    const e = new Event('drop', { bubbles: true, cancelable: true });
    Object.defineProperty(e, 'dataTransfer', { value: { types: ['Files'], files, items: [] } });
    document.getElementById('view').dispatchEvent(e);
  });
  await page.waitForFunction(() => window.tessera.overlay.promptShown(), null, { timeout: 10000 });
  const offer = await page.evaluate(() => window.tessera.overlay.promptText());
  check('a file dropped while ch2 is open is offered as an overlay (replace or add)',
        /ch2\.nii\.gz is open/.test(offer) && /ball\.nii/.test(offer) && /overlay/.test(offer), offer);
  await page.click('#overlayPromptAdd');
  // The offer closes at the click; the file is read and opened after it.
  await page.waitForFunction(() => !window.tessera.overlay.promptShown() && window.tessera.overlay.info().file === 'ball.nii',
                             null, { timeout: 30000 }).catch(() => {});  // the check below says what came instead
  const afterDrop = await page.evaluate(() => ({ info: window.tessera.overlay.info(), name: window.tessera.state().name }));
  check('"Add as overlay" keeps ch2 and makes the dropped file the overlay',
        afterDrop.name === 'ch2.nii.gz' && afterDrop.info.open && afterDrop.info.file === 'ball.nii',
        `volume ${afterDrop.name}; overlay ${afterDrop.info.file}`);
  const errors = logs.filter((l) => l.startsWith('pageerror') || (l.startsWith('error') && !l.includes('favicon')));
  check('no script errors on the page', errors.length === 0, errors.join(' | '));
  await page.close();

  lap('drop');
  // WebGL 1: refused with a message naming WebGL 2.
  const p1 = await openPage(context, url, 'size=64&webgl=1');
  const refusal = await p1.page.evaluate(() => document.getElementById('overlayInfo').textContent +
    ' | ' + document.getElementById('overlayFile').disabled);
  check('on WebGL 1 the overlay control is off and says it needs WebGL 2', /WebGL 2/.test(refusal) && /true$/.test(refusal), refusal);
  await p1.page.close();
  lap('WebGL 1');
  console.log(`overlay test: ${laps.join(', ')}`);
}

// aal over a store of ch2 (written by `tessera convert`, read over fetch and
// drawn through the bricks layout): fused in the store's ray march, aligned
// by world coordinates with the store's level 0.
async function overlayOverStore(context, url, tmp, run) {
  const t0 = Date.now();
  const store = path.join(tmp, 'ch2-overlay.ome.zarr');
  run('convert', CH2, store);
  const ref = path.join(tmp, 'fused-store.png');
  const reference = promisify(execFile)(cli, ['render', store, '--layout', 'bricks', '--overlay', AAL,
    '--overlay-labels', AAL_NAMES, '--overlay-alpha', '0.6', '--tf', 'mr-default', '--preintegrate', 'off',
    '--azimuth', '90', '--elevation', '20', '--crop', '0:0.68,0:1,0:1', '--size', `${SIZE}x${SIZE}`,
    '--profile', 'webgl2', '--out', ref]);
  const { page, logs } = await openPage(context, url, `size=${SIZE}&url=/data/ch2-overlay.ome.zarr`);
  await page.waitForFunction(() => window.tessera.zarr().completeMs !== null || window.tessera.error() !== '',
    null, { timeout: 60000 });
  await withoutOverlays(page);
  await page.evaluate(async () => {
    const menu = document.getElementById('preset');
    menu.value = 'mr-default';
    menu.dispatchEvent(new Event('change'));
    const x1 = document.getElementById('cropX1');
    x1.value = 0.68;
    x1.dispatchEvent(new Event('input'));
    document.getElementById('overlayAlpha').value = 0.6;
    await window.tessera.setCamera(90, 20, 1);
  });
  await page.setInputFiles('#overlayFile', [AAL, AAL_NAMES]);
  await page.waitForFunction(() => window.tessera.overlay.info().open || window.tessera.error() !== '', null, { timeout: 30000 });
  const info = await page.evaluate(() => window.tessera.overlay.info());
  const error = await page.evaluate(() => window.tessera.error());
  check('"Add overlay…" over the store opens aal as labels (116 names), no error',
        info.open && info.labels && info.labels_table.length === 116 && !error && !info.note,
        error || `${info.file}, ${info.labels_table && info.labels_table.length} names, note "${info.note}"`);
  // The store's frame once every brick this view wants is in.
  await page.evaluate(() => window.tessera.render());
  await page.waitForFunction(() => {
    const z = window.tessera.zarr();
    return z.last && z.last.complete && !z.last.pending && z.inFlight === 0 && z.queued === 0;
  }, null, { timeout: 60000 });
  await page.evaluate(() => window.tessera.render());
  await page.waitForFunction(() => { const z = window.tessera.zarr(); return z.last && z.last.complete && !z.last.pending; },
    null, { timeout: 60000 });
  await reference;
  const m = await psnrAgainst(page, ref);
  check('over a store: the page\'s fused frame equals tessera render STORE --layout bricks --overlay aal (PSNR >= 40 dB)',
        m.psnr >= 40, m.error || `${m.psnr.toFixed(2)} dB`);
  const right = await crosshairAt(page, [40, -25, 52]);
  const left = await crosshairAt(page, [-40, -25, 52]);
  check('over a store: the crosshair at (40, -25, 52) mm names Postcentral_R, with its position',
        /Postcentral_R/.test(right.text) && /\(40\.0, -25\.0, 52\.0\) mm/.test(right.text),
        `voxel ${right.voxel}: "${right.text}"`);
  check('over a store: the crosshair at (-40, -25, 52) mm names Postcentral_L (left and right not swapped)',
        /Postcentral_L/.test(left.text) && !/Postcentral_R/.test(left.text), `voxel ${left.voxel}: "${left.text}"`);
  await storeSlices(page);
  // Removing it gives the store alone back.
  await page.evaluate(() => document.getElementById('overlayRemove').click());
  await page.waitForFunction(() => !window.tessera.overlay.info().open, null, { timeout: 10000 });
  await page.evaluate(() => window.tessera.render());
  await page.waitForFunction(() => { const z = window.tessera.zarr(); return z.last && z.last.complete && !z.last.pending; },
    null, { timeout: 60000 });
  const plain = await psnrAgainst(page, ref);
  check('over a store: removing the overlay changes the frame (below 35 dB against the fused reference)',
        plain.psnr < 35, plain.error || `${plain.psnr.toFixed(2)} dB`);
  const errors = logs.filter((l) => l.startsWith('pageerror') || (l.startsWith('error') && !l.includes('favicon') && !/status of 404/.test(l)));
  check('no script errors on the store page', errors.length === 0, errors.join(' | '));
  await page.close();
  console.log(`overlay over a store: ${((Date.now() - t0) / 1000).toFixed(1)} s`);
}

// The store's slice views with aal: from the coarsest level (panels of one
// pixel) the atlas's colours are there; at level 0 (panels of 512² pixels)
// the views through the right postcentral gyrus equal the file's, and the
// crosshair reads the same (Postcentral_R at x > 0 mm).
async function storeSlices(page) {
  const t0 = Date.now();
  await page.evaluate(() => window.tessera.slices.setPanelPixels(1));
  const coarse = await slicesThrough(page, [40, -25, 52]);
  const coarseS = (Date.now() - t0) / 1000;
  const coarseRows = Object.entries(coarse.panels).map(([q, p]) => `${q} level ${p.level} ${p.width}x${p.height}: ${p.coloured} coloured`);
  check('over a store: the coarsest level\'s slice views show the atlas (> 5 % of each view\'s pixels coloured)',
        Object.values(coarse.panels).every((p) => p.level > 0 && p.coloured > 0.05 * p.width * p.height), coarseRows.join('; '));
  await page.evaluate(() => window.tessera.slices.setPanelPixels(512 * 512));
  const shown = await slicesThrough(page, [40, -25, 52]);
  const level0S = (Date.now() - t0) / 1000;
  const rows = [];
  let ok = !!fileSlices;
  for (const [plane, p] of Object.entries(shown.panels)) {
    const f = fileSlices && fileSlices.panels[plane];
    const same = f && f.width === p.width && f.height === p.height && f.index === p.index;
    const differ = same ? differingPixels(p.pixels, f.pixels, 0) : -1;
    const db = same ? psnrOf(p.pixels, f.pixels) : 0;
    ok = ok && same && p.level === 0 && !p.pending && p.coloured > 0.05 * p.width * p.height && (differ === 0 || db >= 40);
    rows.push(`${plane} ${p.index}: level ${p.level}, ${p.width}x${p.height}, ${p.coloured} coloured, ` +
      `${differ} pixels differ from the file's (${db >= 999 ? 'identical' : `${db.toFixed(2)} dB`})`);
  }
  check('over a store: the level-0 slice views through (40, -25, 52) mm show aal as the file\'s do (identical or >= 40 dB)',
        ok, fileSlices ? rows.join('; ') : 'the file\'s slice views were not taken (the first test failed early)');
  const overlayPart = (t) => (t.split(' · ')[1] || '');
  const mmOf = (t) => { const m = /at \(([-\d.]+), ([-\d.]+), ([-\d.]+)\) mm RAS/.exec(t); return m ? m.slice(1).map(Number) : null; };
  const mm = mmOf(shown.text);
  check('over a store: the crosshair there reads Postcentral_R at x > 0 mm (RAS), as over the file',
        /Postcentral_R/.test(overlayPart(shown.text)) && mm && mm[0] > 0 && fileSlices &&
        overlayPart(shown.text) === overlayPart(fileSlices.text) && shown.voxel.join() === fileSlices.voxel.join(),
        `store: "${shown.text}"; file: "${fileSlices && fileSlices.text}"`);
  console.log(`overlay over a store, slice views: coarsest ${coarseS.toFixed(1)} s, level 0 ${level0S.toFixed(1)} s, ` +
    `compared ${((Date.now() - t0) / 1000).toFixed(1)} s`);
}
