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
  SIZE, PAGE_SAMPLING, check, decodePng, psnrAgainst, snapshot, openPage, browserSuite,
} from './fixture.mjs';

const checks = browserSuite();

test('channels: the panel lists the store\'s channels; toggle, colour and window render as the CLI does',
  checks(channelsPanel));

// The 3-channel u16 store of tests/support/ChannelStore.h (NGFF 0.4 on
// Zarr v2, one uncompressed chunk per channel and level): a sphere (channel 0), a
// slab (1), a rod (2) on a background of 100, with omero colours and windows.
function writeChannelStore(dir, [nx, ny, nz]) {
  fs.rmSync(dir, { recursive: true, force: true });
  fs.mkdirSync(path.join(dir, '0'), { recursive: true });
  fs.writeFileSync(path.join(dir, '.zgroup'), JSON.stringify({ zarr_format: 2 }));
  const axis = (name) => ({ name, type: 'space', unit: 'millimeter' });
  const win = (min, max, start, end) => ({ min, max, start, end });
  fs.writeFileSync(path.join(dir, '.zattrs'), JSON.stringify({
    multiscales: [{ version: '0.4', name: 'channels',
      axes: [{ name: 'c', type: 'channel' }, axis('z'), axis('y'), axis('x')],
      datasets: [{ path: '0', coordinateTransformations: [{ type: 'scale', scale: [1, 1, 1, 1] }] },
        { path: '1', coordinateTransformations: [{ type: 'scale', scale: [1, 2, 2, 2] },
          { type: 'translation', translation: [0, 0.5, 0.5, 0.5] }] }] }],
    omero: { channels: [
      { label: 'sphere', color: 'FF0000', active: true, window: win(100, 3000, 100, 3000) },
      { label: 'slab', color: '00FF00', active: true, window: win(100, 2000, 50, 2500) },
      { label: 'rod', color: '0080FF', active: true, window: win(100, 4000, 100, 4000) }] },
  }));
  const inside = (c, x, y, z) => {
    const fx = (x + 0.5) / nx, fy = (y + 0.5) / ny, fz = (z + 0.5) / nz;
    if (c === 0) return (fx - 0.35) ** 2 + (fy - 0.4) ** 2 + (fz - 0.5) ** 2 < 0.22 ** 2;
    if (c === 1) return fy > 0.62 && fy < 0.78;
    return (fx - 0.72) ** 2 + (fz - 0.45) ** 2 < 0.08 ** 2;
  };
  const value = [3000, 2000, 4000];
  // Level 1 (every other voxel): the page's bricks layout needs a level
  // coarser than the one it refines to.
  for (const [level, f] of [[0, 1], [1, 2]]) {
    const [lx, ly, lz] = [nx / f, ny / f, nz / f];
    fs.mkdirSync(path.join(dir, String(level)), { recursive: true });
    fs.writeFileSync(path.join(dir, String(level), '.zarray'), JSON.stringify({
      zarr_format: 2, shape: [3, lz, ly, lx], chunks: [1, lz, ly, lx], dtype: '<u2', compressor: null,
      fill_value: 0, order: 'C', filters: null, dimension_separator: '/' }));
    for (let c = 0; c < 3; c++) {
      const bytes = Buffer.alloc(lx * ly * lz * 2);
      let i = 0;
      for (let z = 0; z < lz; z++) for (let y = 0; y < ly; y++) for (let x = 0; x < lx; x++, i += 2) {
        bytes.writeUInt16LE(inside(c, x * f, y * f, z * f) ? value[c] : 100, i);
      }
      const chunk = path.join(dir, String(level), String(c), '0', '0');
      fs.mkdirSync(chunk, { recursive: true });
      fs.writeFileSync(path.join(chunk, '0'), bytes);
    }
  }
}

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
