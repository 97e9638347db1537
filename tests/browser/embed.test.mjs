// Browser test: examples/embed-web, a page that embeds the viewer through
// frontends/web/tessera.js (served from the site's examples/embed-web/). It renders
// the volume (pixels not background) and, without the overlays, matches the
// native CLI's image; ?url= opens a served file; a second viewer on the same
// page keeps its own volume, and disposing it leaves the first one working.
import { test, before, after } from 'node:test';
import fs from 'node:fs';
import path from 'node:path';
import { SIZE, VOLUME, check, checksPassed, startBrowser, psnrOf, decodePng } from './fixture.mjs';

let browser;
before(async () => { browser = await startBrowser(); });
after(async () => { if (browser) await browser.close(); });

// The example at `query`, once it has rendered: {page, logs}.
async function openExample(query) {
  const page = await browser.context.newPage();
  const logs = [];
  page.on('console', (m) => logs.push(`${m.type()}: ${m.text()}`));
  page.on('pageerror', (e) => logs.push(`pageerror: ${e.message}`));
  await page.goto(`${browser.url}/examples/embed-web/index.html${query}`);
  await page.waitForFunction(() => window.embedded && window.embedded.state().has_volume, null, { timeout: 30000 });
  return { page, logs };
}

const lit = (px) => {
  let n = 0;
  for (let i = 0; i < px.length; i += 4) if (px[i] + px[i + 1] + px[i + 2] > 24) n++;
  return n / (px.length / 4);
};

test('the embedding example renders the volume like the native CLI', () => checksPassed(async () => {
  const { tmp, run } = browser;
  const nativePng = path.join(tmp, 'native-webgl2.png');
  run('render', VOLUME, '--tf', 'mr-default', '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl2',
      '--preintegrate', 'off', '--out', nativePng);
  const { page, logs } = await openExample('');
  const s = await page.evaluate(() => window.embedded.state());
  const shown = await page.evaluate(() => Array.from(window.embedded.pixels()));
  check('embed: a TesseraViewer on the example\'s canvas renders the generated volume (pixels not background)',
        s.webgl === 2 && s.name === VOLUME && lit(shown) > 0.1, `${s.description}; ${(100 * lit(shown)).toFixed(1)} % lit`);
  const framed = await page.evaluate(() => {
    const v = window.embedded;
    let frames = 0;
    const off = v.on('frame', () => frames++);
    v.setOverlays({ box: false, axes: false });
    v.render();
    off();
    return { frames, pixels: Array.from(v.pixels()) };
  });
  const ref = await decodePng(page, nativePng);
  const db = framed.pixels.length === ref.data.length ? psnrOf(framed.pixels, ref.data) : 0;
  check('embed: without overlays the frame matches `tessera render` with the page\'s sampling (PSNR >= 50 dB); one frame event',
        db >= 50 && framed.frames === 1, `${db.toFixed(2)} dB, ${framed.frames} frame events`);

  // Another viewer on the same page: its own module, context and volume.
  const two = await page.evaluate(async () => {
    const { TesseraViewer } = await import('../../tessera.js');
    const c = document.createElement('canvas');
    c.width = c.height = 128;
    document.body.append(c);
    const other = await TesseraViewer.create(c, { profile: 'webgl1' });
    other.loadGenerated('gen:sphere:40');
    other.render();
    const otherState = other.state();
    const otherLit = Array.from(other.pixels());
    const firstName = window.embedded.state().name;
    other.dispose();
    window.embedded.render();
    return { otherState, otherLit, firstName, afterDispose: other.state(), first: Array.from(window.embedded.pixels()) };
  });
  check('embed: a second viewer on the page keeps its own volume and profile; disposing it leaves the first rendering',
        two.otherState.name === 'gen:sphere:40' && two.otherState.webgl === 1 && lit(two.otherLit) > 0.05 &&
        two.firstName === VOLUME && two.afterDispose === null && psnrOf(two.first, framed.pixels) >= 50,
        `second ${two.otherState.name} on WebGL ${two.otherState.webgl}, first ${two.firstName}; ` +
        `first after dispose ${psnrOf(two.first, framed.pixels).toFixed(1)} dB against before`);
  const errors = logs.filter((l) => l.startsWith('pageerror') || l.startsWith('error'));
  check('embed: no script errors', errors.length === 0, errors.join(' | '));
  await page.close();
}));

test('the embedding example opens ?url= and reports a failed one', () => checksPassed(async () => {
  const { tmp, run } = browser;
  run('convert', 'gen:sphere:48', path.join(tmp, 'sphere48.nii.gz'));
  const { page } = await openExample('?url=/data/sphere48.nii.gz');
  const s = await page.evaluate(() => window.embedded.state());
  const px = await page.evaluate(() => Array.from(window.embedded.pixels()));
  check('embed ?url=: the served .nii.gz is fetched, inflated and rendered', s.name === 'sphere48.nii.gz' &&
        s.dims.join('x') === '48x48x48' && lit(px) > 0.02, `${s.description}; ${(100 * lit(px)).toFixed(1)} % lit`);
  const failed = await page.evaluate(async () => {
    try {
      await window.embedded.openUrl('/data/missing.nii');
      return '';
    } catch (e) {
      return e.message;
    }
  });
  const still = await page.evaluate(() => window.embedded.state().name);
  check('embed: openUrl of a missing file rejects with an error naming the URL; the volume stays',
        failed.includes('/data/missing.nii') && failed.includes('404') && still === 'sphere48.nii.gz', `"${failed}"`);
  await page.close();
}));

test('the page saves its session state and restores the same view from it', () => checksPassed(async () => {
  const { page, logs } = await openExample('');
  const r = await page.evaluate(() => {
    const v = window.embedded;
    v.setOverlays({ box: false, axes: false });
    v.setTransferFunction('ct-bone');
    v.setCamera({ azimuth: 40, elevation: 15, zoom: 1.2 });
    v.render();
    const saved = Array.from(v.pixels());
    const state = v.sessionState();
    v.setTransferFunction('mr-default');
    v.setCamera({ azimuth: 0, elevation: 0, zoom: 1 });
    v.render();
    const moved = Array.from(v.pixels());
    v.restoreSession(JSON.stringify(state));
    v.render();
    const restored = Array.from(v.pixels());
    let refused = '';
    try {
      v.restoreSession({ version: 1, settings: { version: 1, mode: 'loud' } });
    } catch (e) {
      refused = e.message;
    }
    v.render();
    const afterRefusal = Array.from(v.pixels());
    return { state, saved, moved, restored, refused, afterRefusal };
  });
  const same = (a, b) => a.length === b.length && a.every((x, i) => x === b[i]);
  check('state: the saved state holds the camera and look set on the page (versioned)',
        r.state.version === 1 && r.state.settings.camera.azimuth === 40 &&
        r.state.settings.camera.elevation === 15 && r.state.volume.name === VOLUME,
        JSON.stringify(r.state.settings.camera));
  check('state: restoring it shows the saved frame again, byte for byte (the moved view differed)',
        same(r.restored, r.saved) && psnrOf(r.moved, r.saved) < 40,
        `moved view ${psnrOf(r.moved, r.saved).toFixed(1)} dB from the saved one`);
  check('state: a bad state is refused naming the setting, and the view stays as it was',
        r.refused.includes('loud') && same(r.afterRefusal, r.restored), r.refused);
  // The CLI takes the page's state: `tessera render --state` draws the saved view.
  const { tmp, run } = browser;
  const statePath = path.join(tmp, 'page-state.json');
  const cliPng = path.join(tmp, 'page-state.png');
  fs.writeFileSync(statePath, JSON.stringify(r.state));
  run('render', VOLUME, '--state', statePath, '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl2',
      '--out', cliPng);
  const ref = await decodePng(page, cliPng);
  const db = ref.data.length === r.saved.length ? psnrOf(r.saved, ref.data) : 0;
  check('state: `tessera render --state` of the page\'s state draws the saved view (PSNR >= 50 dB)',
        db >= 50, `${db.toFixed(2)} dB`);
  const errors = logs.filter((l) => l.startsWith('pageerror'));
  check('state: no script errors', errors.length === 0, errors.join(' | '));
  await page.close();
}));
