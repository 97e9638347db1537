// Browser test: an OME-Zarr store with three channels over fetch() (?url=)
// shown with all its channels together and the Channels panel
// (frontends/web/channels-panel.js): the page's frame equals `tessera render
// STORE --channels ... --channel-colors ... --channel-windows ...` (PSNR >=
// 40 dB) with the store's omero defaults and after the panel's toggle,
// colour and window; the toggle changes only that channel's pixels.
import { test } from 'node:test';
import fs from 'node:fs';
import path from 'node:path';
import {
  SIZE, PAGE_SAMPLING, check, decodePng, psnrAgainst, snapshot, openPage, browserSuite, writeChannelStore,
} from './fixture.mjs';

const checks = browserSuite();

test('channels: the panel lists the store\'s channels; toggle, colour and window render as the CLI does',
  checks(channelsPanel));

// Pixels where some component differs by more than `tol` levels.
const differs = (a, b, p, tol) => [0, 1, 2].some((k) => Math.abs(a[4 * p + k] - b[4 * p + k]) > tol);

async function channelsPanel(context, url, tmp, run) {
  const store = path.join(tmp, 'three.ome.zarr');
  writeChannelStore(store, [48, 48, 24]);
  const t0 = Date.now();
  const { page, logs } = await openPage(context, url, `size=${SIZE}&slices=0&url=/data/three.ome.zarr`);
  // (The error line may show the bricks plan's note meanwhile: wait for the list.)
  await page.waitForFunction(() => window.tessera.channels() !== null, null, { timeout: 30000 })
    .catch(() => {});
  const listed = await page.evaluate(() => window.tessera.channels());
  if (!listed) console.log(logs.join('\n'));
  check('channels: the panel lists the store\'s three channels with their omero labels, colours and windows',
    listed && listed.open && listed.channels.map((c) => c.label).join(',') === 'sphere,slab,rod' &&
    [0, 128 / 255, 1].every((v, k) => Math.abs(listed.channels[2].color[k] - v) < 1e-6) &&
    JSON.stringify(listed.channels[1].window) === '[50,2500]' && listed.mode === 'additive',
    JSON.stringify(listed) + (await page.evaluate(() => window.tessera.error())));
  check('channels: the panel shows a row per channel',
    (await page.locator('#channel-list .channel').count()) === 3 && await page.isVisible('#channels'), '');
  await page.evaluate(() => window.tessera.setCamera(30, 20, 1));
  const tfPath = path.join(tmp, 'page-tf.json');
  fs.writeFileSync(tfPath, JSON.stringify(await page.evaluate(() => window.tessera.tf())));
  const look = ['--tf', tfPath, '--azimuth', '30', '--elevation', '20', '--size', `${SIZE}x${SIZE}`,
    '--profile', 'webgl2', ...PAGE_SAMPLING];
  const cli = (name, ...args) => {
    const out = path.join(tmp, `${name}.png`);
    run('render', store, ...args, ...look, '--out', out);
    return out;
  };

  const defaults = cli('defaults', '--channels', '0,1,2');
  const m0 = await psnrAgainst(page, defaults);
  check('channels: the omero defaults render as `tessera render STORE --channels 0,1,2` (PSNR >= 40 dB)',
    m0.psnr >= 40, m0.error || `${m0.psnr.toFixed(2)} dB`);
  const all = (await snapshot(page)).pixels;

  // The slab off through its checkbox.
  await page.click('[aria-label="show slab"]');
  await page.evaluate(() => window.tessera.render());
  const noSlab = (await snapshot(page)).pixels;
  const slabAlone = (await decodePng(page, cli('slab-alone', '--channels', '1'))).data;
  let inside = 0, outside = 0;
  for (let p = 0; p < all.length / 4; p++) {
    if (differs(all, noSlab, p, 2)) (slabAlone[4 * p] + slabAlone[4 * p + 1] + slabAlone[4 * p + 2] > 0 ? inside++ : outside++);
  }
  check('channels: toggling the slab off changes only pixels where the slab shows',
    inside > SIZE * SIZE / 50 && outside === 0, `${inside} changed inside its projection, ${outside} outside`);
  const m1 = await psnrAgainst(page, cli('no-slab', '--channels', '0,2'));
  check('channels: the slab off renders as `--channels 0,2` (PSNR >= 40 dB)', m1.psnr >= 40,
    m1.error || `${m1.psnr.toFixed(2)} dB`);

  // The sphere yellow through its swatch; the rod's window narrowed.
  await page.$eval('[aria-label="sphere colour"]', (e) => { e.value = '#ffff00'; e.dispatchEvent(new Event('input')); });
  await page.$eval('[aria-label="rod window high"]', (e) => { e.value = '2000'; e.dispatchEvent(new Event('change')); });
  await page.evaluate(() => window.tessera.render());
  const edited = await page.evaluate(() => window.tessera.channels());
  const m2 = await psnrAgainst(page, cli('edited', '--channels', '0,2', '--channel-colors', 'ffff00,0080ff',
    '--channel-windows', '100:3000,100:2000'));
  check('channels: colour and window set in the panel render as `--channel-colors ffff00,0080ff ' +
    '--channel-windows 100:3000,100:2000` (PSNR >= 40 dB)', m2.psnr >= 40, m2.error || `${m2.psnr.toFixed(2)} dB`);
  check('channels: the session holds the edits',
    JSON.stringify(edited.channels.map((c) => c.visible)) === '[true,false,true]' &&
    JSON.stringify(edited.channels[0].color) === '[1,1,0]' && JSON.stringify(edited.channels[2].window) === '[100,2000]',
    JSON.stringify(edited.channels));
  const errors = logs.filter((l) => l.startsWith('pageerror') || (l.startsWith('error') && !/status of 404/.test(l)));
  check('channels: no script errors', errors.length === 0, errors.join(' | '));
  console.log(`channels: ${SIZE}x${SIZE}, defaults ${m0.psnr.toFixed(1)} dB, slab off ${m1.psnr.toFixed(1)} dB, ` +
    `edited ${m2.psnr.toFixed(1)} dB; ${inside} pixels changed by the toggle; ${Date.now() - t0} ms`);
  await page.close();
}
