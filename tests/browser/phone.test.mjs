// Browser test: the page on a phone (390x844 CSS pixels, devicePixelRatio
// 3, emulated through the DevTools protocol): drags that turn the head by
// the same angle per CSS pixel at every pixel ratio, the frame rate of a
// touch drag on the head, and the page's details (a file dropped anywhere
// opens, disabled and hidden controls, the crosshair in millimetres); the
// same for an OME-Zarr store (a touch drag while it refines). The WebGL
// context lost and restored on a phone is context-loss.test.mjs.
// fixture.mjs serves the site and launches Chromium; every figure is
// printed for the record.
import { test } from 'node:test';
import fs from 'node:fs';
import path from 'node:path';
import {
  CH2, check, openPage, browserSuite, writePilNifti,
} from './fixture.mjs';

const checks = browserSuite();

test('a drag turns the view by the same angle per CSS pixel at pixel ratios 1, 2 and 3', checks(dragAngle));
test('touch drag on the head at 390x844, pixel ratio 3: frames per second', checks(dragFrameRate));
test('a file dropped anywhere opens; disabled and hidden controls; crosshair in mm', checks(pageDetails));
test('touch drag on an OME-Zarr store at 390x844, pixel ratio 3: frames per second, no freeze', checks(storeDragFrameRate));

const PHONE = { width: 390, height: 844, deviceScaleFactor: 3, mobile: true };

// A 50 CSS pixel mouse drag to the right (and 20 down) at pixel ratios 1, 2
// and 3: the azimuth and elevation turned per CSS pixel.
async function dragAngle(context, url) {
  const { page } = await openPage(context, url, '');
  const cdp = await context.newCDPSession(page);
  const per = {};
  for (const ratio of [1, 2, 3]) {
    await cdp.send('Emulation.setDeviceMetricsOverride', { ...PHONE, deviceScaleFactor: ratio });
    await page.evaluate(() => window.tessera.setCamera(0, 0, 1));
    await page.locator('#canvas').scrollIntoViewIfNeeded();
    const box = await page.locator('#canvas').boundingBox();
    const backing = await page.evaluate(() => document.getElementById('canvas').width);
    const x = box.x + box.width / 2 - 25, y = box.y + box.height / 2 - 10;
    await page.mouse.move(x, y);
    await page.mouse.down();
    await page.mouse.move(x + 50, y + 20, { steps: 5 });
    await page.mouse.up();
    await page.evaluate(() => window.tessera.render());
    const c = (await page.evaluate(() => window.tessera.state())).camera;
    per[ratio] = { az: -c.azimuth / 50, el: c.elevation / 20, backing, css: box.width };
    console.log(`ratio ${ratio}: canvas ${box.width.toFixed(0)} CSS px wide, ${backing} pixels; 50 px right turned ` +
                `${(-c.azimuth).toFixed(2)} deg (${per[ratio].az.toFixed(3)} deg/CSS px), 20 px down ${c.elevation.toFixed(2)} deg`);
  }
  const az = [1, 2, 3].map((r) => per[r].az), el = [1, 2, 3].map((r) => per[r].el);
  const spread = (v) => (Math.max(...v) - Math.min(...v)) / Math.max(...v);
  check('degrees per CSS pixel of drag are equal (within 2 %) at pixel ratios 1, 2 and 3',
        spread(az) < 0.02 && spread(el) < 0.02 && az[0] > 0.2 && per[3].backing > 2.5 * per[1].backing,
        `azimuth ${az.map((v) => v.toFixed(3)).join(' / ')} deg/px, elevation ${el.map((v) => v.toFixed(3)).join(' / ')} deg/px`);
  await page.close();
}

// Frames the page presents per second while one finger drags on the head
// (touch events on a 60 Hz clock for 3 s), on a 390x844 phone at ratio 3;
// with ?dragdensity=device (every interactive frame at the full backing
// size, as before) for comparison in the same run.
async function dragFrames(context, url, query) {
  const { page } = await openPage(context, url, query);
  const cdp = await context.newCDPSession(page);
  await cdp.send('Emulation.setDeviceMetricsOverride', PHONE);
  await cdp.send('Emulation.setTouchEmulationEnabled', { enabled: true, maxTouchPoints: 5 });
  await page.evaluate(() => window.tessera.render());
  await page.locator('#canvas').scrollIntoViewIfNeeded();
  const box = await page.locator('#canvas').boundingBox();
  const backing = await page.evaluate(() => [document.getElementById('canvas').width, document.getElementById('canvas').height]);
  const cx = Math.round(box.x + box.width / 2), cy = Math.round(box.y + box.height / 2);
  const touch = (type, dx) => cdp.send('Input.dispatchTouchEvent', {
    type, touchPoints: type === 'touchEnd' ? [] : [{ x: cx + dx, y: cy, id: 1 }] });
  await touch('touchStart', 0);
  const f0 = await page.evaluate(() => window.tessera.frames());
  const t = Date.now();
  const sent = [];
  const MOVES = 180;
  let during = null;
  for (let i = 0; i < MOVES; i++) {
    sent.push(touch('touchMove', Math.round(80 * Math.sin(2 * Math.PI * i / 90))));
    if (i === MOVES / 2) {
      during = page.evaluate(() => ({ canvas: [document.getElementById('canvas').width, document.getElementById('canvas').height],
        volume: window.tessera.state().render_size, ms: window.tessera.state().frame_ms }));
    }
    const due = t + (i + 1) * 1000 / 60;
    if (Date.now() < due) await new Promise((r) => setTimeout(r, due - Date.now()));
  }
  const f1 = await page.evaluate(() => window.tessera.frames());
  const seconds = (Date.now() - t) / 1000;
  await Promise.all(sent);
  await touch('touchEnd', 0);
  await page.evaluate(() => window.tessera.render());
  const end = await page.evaluate(() => ({ canvas: [document.getElementById('canvas').width, document.getElementById('canvas').height],
    volume: window.tessera.state().render_size }));
  const mid = await during;
  await page.close();
  return { fps: (f1 - f0) / seconds, frames: f1 - f0, seconds, backing, mid, end };
}

async function dragFrameRate(context, url) {
  if (!fs.existsSync(CH2)) { check(`drag frame rate test needs ${CH2} (mricron-data)`, false); return; }
  const query = 'url=/templates/ch2.nii.gz';
  const full = await dragFrames(context, url, `${query}&dragdensity=device`);
  const now = await dragFrames(context, url, query);
  const text = (r) => `${r.fps.toFixed(1)} frames/s (${r.frames} in ${r.seconds.toFixed(1)} s); backing ${r.backing.join('x')}, ` +
    `during the drag canvas ${r.mid.canvas.join('x')} with the volume at ${r.mid.volume.join('x')} (${r.mid.ms.toFixed(0)} ms a frame), ` +
    `after it canvas ${r.end.canvas.join('x')}`;
  console.log(`drag frame rate, interactive frames at full device density (before): ${text(full)}`);
  console.log(`drag frame rate, interactive frames at one pixel per CSS pixel (now): ${text(now)}`);
  check('a touch drag of the head at 390x844, ratio 3: >= 10 frames/s, or >= 2x the full-density drag of this run; full density back after it',
        (now.fps >= 10 || now.fps >= 2 * full.fps) && now.end.canvas.join() === now.backing.join(),
        `${now.fps.toFixed(1)} frames/s vs ${full.fps.toFixed(1)} frames/s at full density (${(now.fps / Math.max(full.fps, 1e-9)).toFixed(1)}x)`);
}

// A NIfTI dropped on the header (not the 3D view) opens; disabled buttons
// look disabled; every [hidden] element is hidden; the crosshair readout
// gives the voxel and its position in millimetres (the file's affine).
async function pageDetails(context, url, tmp) {
  writePilNifti(path.join(tmp, 'pil.nii'));
  const { page } = await openPage(context, url, 'size=256');
  const opened = await page.evaluate(async () => {
    const bytes = await (await fetch('/data/pil.nii')).arrayBuffer();
    const dt = new DataTransfer();
    dt.items.add(new File([bytes], 'pil.nii'));
    const target = document.querySelector('header h1');
    target.dispatchEvent(new DragEvent('dragover', { dataTransfer: dt, bubbles: true, cancelable: true }));
    const shown = getComputedStyle(document.getElementById('drop-hint')).display;
    const accepted = !target.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
    return { shown, accepted };
  });
  await page.waitForFunction(() => window.tessera.state().name === 'pil.nii' || window.tessera.error() !== '',
    null, { timeout: 10000 }).catch(() => {});
  const s = await page.evaluate(() => window.tessera.state());
  check('a file dropped on the header (not the 3D view) opens, with the drop hint shown while dragging',
        s.name === 'pil.nii' && opened.accepted && opened.shown !== 'none',
        `volume "${s.name}", drop handled ${opened.accepted}, hint display "${opened.shown}"`);

  const looks = await page.evaluate(() => {
    const style = (id) => { const c = getComputedStyle(document.getElementById(id)); return { opacity: +c.opacity, cursor: c.cursor }; };
    return { disabled: style('deletePoint'), enabled: style('saveTf'), disabledFlag: document.getElementById('deletePoint').disabled };
  });
  check('a disabled button looks disabled (dimmed, no pointer cursor); an enabled one does not',
        looks.disabledFlag && looks.disabled.opacity <= 0.6 && looks.disabled.cursor !== 'pointer' && looks.enabled.opacity === 1,
        `disabled: opacity ${looks.disabled.opacity}, cursor ${looks.disabled.cursor}; enabled: opacity ${looks.enabled.opacity}, cursor ${looks.enabled.cursor}`);

  const hiddenShown = async (p) => p.evaluate(() => Array.from(document.querySelectorAll('[hidden]'))
    .filter((e) => getComputedStyle(e).display !== 'none').map((e) => `${e.tagName.toLowerCase()}#${e.id}`));
  const shownHere = await hiddenShown(page);
  const bare = await openPage(context, url, 'size=64&slices=0');
  const shownBare = await hiddenShown(bare.page);
  const count = await bare.page.evaluate(() => document.querySelectorAll('[hidden]').length);
  await bare.page.close();
  check('every element with the hidden attribute is hidden (no CSS display rule overrides it), also with ?slices=0',
        shownHere.length === 0 && shownBare.length === 0, `${count} hidden elements with ?slices=0; shown: ${[...shownHere, ...shownBare].join(', ') || 'none'}`);

  // The crosshair at a voxel: its position in mm through the file's affine.
  const readout = [];
  for (const voxel of [null, [3, 25, 7]]) {
    if (voxel) await page.evaluate((v) => window.tessera.slices.setCross(...v), voxel);
    const r = await page.evaluate(() => ({ text: document.getElementById('crosshairInfo').textContent,
      cross: window.tessera.slices.state().cross, affine: window.tessera.state().affine }));
    const mm = [0, 1, 2].map((row) => r.affine[row][0] * r.cross[0] + r.affine[row][1] * r.cross[1] +
      r.affine[row][2] * r.cross[2] + r.affine[row][3]);
    const want = mm.map((v) => v.toFixed(1)).join(', ');
    readout.push({ ok: r.text.includes(`(${r.cross.join(', ')})`) && r.text.includes(`${want}) mm`), text: r.text, want });
  }
  check('the crosshair readout gives the voxel and its position in mm (the file\'s affine)', readout.every((r) => r.ok),
        readout.map((r) => `"${r.text}" (expected (${r.want}) mm)`).join('; '));
  await page.close();
}

// ch2 as an OME-Zarr store (zlib chunks) under /data/, once per run.
function ch2Store(tmp, run) {
  const store = path.join(tmp, 'ch2.ome.zarr');
  if (!fs.existsSync(store)) run('convert', CH2, store, '--compressor', 'zlib');
  return '/data/ch2.ome.zarr';
}

// Runs in the page before its scripts: when each animation-frame callback
// that drew on the canvas (a draw, clear or blit into the default
// framebuffer) ended, in window.drawnFrames; and each draw outside one (a
// store's drag move answered as it arrived: app.js, pointerrawupdate),
// when its task's code ended.
function recordDrawnFrames() {
  window.drawnFrames = [];
  let drew = false;
  let inCallback = false;
  let outside = false;  // a draw outside an animation-frame callback (a move answered as it arrived)
  for (const Ctx of [window.WebGL2RenderingContext, window.WebGLRenderingContext]) {
    if (!Ctx) continue;
    const p = Ctx.prototype;
    const bind = p.bindFramebuffer;
    p.bindFramebuffer = function (target, fb) {
      if (target !== this.READ_FRAMEBUFFER) this.drawsOnCanvas = fb === null;
      return bind.call(this, target, fb);
    };
    for (const name of ['drawArrays', 'drawElements', 'clear', 'blitFramebuffer']) {
      const f = p[name];
      if (!f) continue;
      p[name] = function (...args) {
        if (this.drawsOnCanvas !== false) {
          drew = true;
          if (!inCallback && !outside) {
            outside = true;
            queueMicrotask(() => { window.drawnFrames.push(performance.now()); outside = false; });
          }
        }
        return f.apply(this, args);
      };
    }
  }
  const raf = window.requestAnimationFrame.bind(window);
  window.requestAnimationFrame = (cb) => raf((ts) => {
    drew = false;
    inCallback = true;
    try {
      cb(ts);
    } finally {
      inCallback = false;
      if (drew) window.drawnFrames.push(performance.now());
    }
  });
}

const storeStats = (page) => page.evaluate(() => window.tessera.zarr());

// One finger drags on the store (touch events on a 60 Hz clock for 3 s)
// right after its first image, at 390x844 and ratio 3, while its bricks
// arrive: the frames the page shows per second and the longest time
// without a new frame (a freeze).
async function storeDragFrameRate(context, url, tmp, run) {
  if (!fs.existsSync(CH2)) { check(`store drag test needs ${CH2} (mricron-data)`, false); return; }
  const store = ch2Store(tmp, run);
  const page = await context.newPage();
  const logs = [];
  page.on('console', (m) => logs.push(`${m.type()}: ${m.text()}`));
  page.on('pageerror', (e) => logs.push(`pageerror: ${e.message}`));
  await page.addInitScript(recordDrawnFrames);
  await page.goto(`${url}/index.html?url=${store}`);
  await page.evaluate(() => window.tessera.ready);
  const cdp = await context.newCDPSession(page);
  await cdp.send('Emulation.setDeviceMetricsOverride', PHONE);
  await cdp.send('Emulation.setTouchEmulationEnabled', { enabled: true, maxTouchPoints: 5 });
  await page.waitForFunction(() => { const z = window.tessera.zarr(); return z && z.firstImageMs !== null; }, null, { timeout: 60000 });
  await page.locator('#canvas').scrollIntoViewIfNeeded();
  const box = await page.locator('#canvas').boundingBox();
  const backing = await page.evaluate(() => [document.getElementById('canvas').width, document.getElementById('canvas').height]);
  const cx = Math.round(box.x + box.width / 2), cy = Math.round(box.y + box.height / 2);
  const touch = (type, dx) => cdp.send('Input.dispatchTouchEvent', {
    type, touchPoints: type === 'touchEnd' ? [] : [{ x: cx + dx, y: cy + Math.round(dx / 4), id: 1 }] });
  await touch('touchStart', 0);
  const start = await page.evaluate(() => ({ now: performance.now(), frames: window.tessera.frames() }));
  const t = Date.now();
  const sent = [];
  const MOVES = 180;
  for (let i = 0; i < MOVES; i++) {
    sent.push(touch('touchMove', Math.round(80 * Math.sin(2 * Math.PI * i / 90))));
    const due = t + (i + 1) * 1000 / 60;
    if (Date.now() < due) await new Promise((r) => setTimeout(r, due - Date.now()));
  }
  const end = await page.evaluate(() => ({ now: performance.now(), frames: window.tessera.frames(),
    canvas: [document.getElementById('canvas').width, document.getElementById('canvas').height] }));
  await Promise.all(sent);
  await touch('touchEnd', 0);
  const z = await storeStats(page);
  const seconds = (end.now - start.now) / 1000;
  const fps = (end.frames - start.frames) / seconds;
  // Animation frames that drew on the canvas, in the page's clock.
  const drawn = await page.evaluate(() => window.drawnFrames);
  const shown = [start.now, ...drawn.filter((at) => at > start.now && at < end.now), end.now];
  let freeze = 0;
  for (let i = 1; i < shown.length; i++) freeze = Math.max(freeze, shown[i] - shown[i - 1]);
  const calls = (z.calls || []).filter((c) => c.t + (z.t0 || 0) > start.now && c.t + (z.t0 || 0) < end.now);
  const worstCall = calls.reduce((a, c) => Math.max(a, c.ms), 0);
  const previews = calls.filter((c) => c.preview);
  const median = (v) => (v.length ? [...v].sort((a, b) => a - b)[Math.floor(v.length / 2)] : NaN);
  const sizes = [...new Set(previews.map((c) => (c.preview_size || ['?']).join('x')))].slice(0, 4).join(', ');
  console.log(`store drag at 390x844, ratio 3 (backing ${backing.join('x')}, during the drag ${end.canvas.join('x')}): ` +
              `${fps.toFixed(1)} frames/s (${end.frames - start.frames} in ${seconds.toFixed(1)} s), longest without a frame ${freeze.toFixed(0)} ms; ` +
              `${calls.length} store calls, worst ${worstCall.toFixed(0)} ms; ${previews.length} previews at ${sizes || 'none'}, ` +
              `median ${median(previews.map((c) => c.ms)).toFixed(1)} ms (ray march, compose and wait ${median(previews.map((c) => c.preview_ms || 0)).toFixed(1)} ms); ` +
              `${z.requests} requests; refined ${z.completeMs === null ? 'not yet' : `after ${z.completeMs.toFixed(0)} ms`}`);
  check('a touch drag of a refining store at 390x844, ratio 3: >= 10 frames/s and never 500 ms without a frame',
        fps >= 10 && freeze <= 500, `${fps.toFixed(1)} frames/s, longest gap ${freeze.toFixed(0)} ms`);
  // A store's keys that are not there (.zattrs of a v2 array) answer 404 by design.
  const errors = logs.filter((l) => l.startsWith('pageerror') || (l.startsWith('error') && !/favicon|status of 404/.test(l)));
  check('store drag: no script errors', errors.length === 0, errors.join(' | '));
  await page.close();
}
