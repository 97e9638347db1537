// Browser test: DICOM folders dropped and picked (fixture.mjs serves the
// site and launches Chromium).
import { test } from 'node:test';
import fs from 'node:fs';
import path from 'node:path';
import {
  SIZE, CH2, check, snapshot, openPage, openThroughPicker, withoutOverlays, psnrOf, browserSuite,
} from './fixture.mjs';

// One Chromium for the file; checks(f) runs f (context, url, tmp, run) as a test.
const checks = browserSuite();

test('a DICOM folder renders like the NIfTI of the same head; a broken slice is named', checks(dicomFolder));

// A DICOM series in the browser (issue 18): ch2 written as a folder by
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
      Object.defineProperty(e, 'dataTransfer', { value: { types: ['Files'], files: [], items: [{ kind: 'file', webkitGetAsEntry: () => dir }] } });
      document.getElementById('error').hidden = true;
      document.getElementById('view').dispatchEvent(e);
    }, { folderName, which });
  };
  // The series is an MR (convert writes ch2 so): it opens with mr-percentile
  // (session/ModalityDefault.h), which the preset menu shows; the NIfTI's
  // look (mr-default on the value range) is then chosen to compare.
  const shown = async (name) => {
    await page.waitForFunction((n) => window.tessera.state().name === n || window.tessera.error() !== '', name, { timeout: 60000 });
    await page.evaluate(() => window.tessera.render());
    const preset = await page.evaluate(() => document.getElementById('preset').value);
    await page.evaluate(() => {
      const menu = document.getElementById('preset');
      menu.value = 'mr-default';
      menu.dispatchEvent(new Event('change'));
      document.getElementById('resetWindow').click();
    });
    await page.evaluate(() => window.tessera.render());
    return { state: await page.evaluate(() => window.tessera.state()), error: await page.evaluate(() => window.tessera.error()),
      pixels: (await snapshot(page)).pixels, preset };
  };
  const t = Date.now();
  await drop('ch2-dicom', null);
  const dropped = await shown(`ch2-dicom/${names[0]}`);
  const dropMs = Date.now() - t;
  check('a dropped MR series opens with mr-percentile, shown in the preset menu',
        dropped.preset === 'mr-percentile', dropped.preset);
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
