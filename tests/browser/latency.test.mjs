// Browser test: the page answers input within its frame budget while an
// OME-Zarr store refines (fixture.mjs serves the site and launches
// Chromium). The store's finest chunks are served late, so bricks keep
// arriving while a drag and wheel turns are sent; each input event's
// latency is the time from the event (its timeStamp, the earliest of the
// pointer moves coalesced into it) to the end of the first draw on the
// canvas after it was handled (a preview, or a finished frame): an
// animation-frame callback, or the page's input handler that answered the
// event as it arrived (a drag's move in pointerrawupdate, a release, a
// wheel turn; its read-back included; such a draw reaches the compositor
// with the next animation frame, and the test reports the time until then
// too). TESSERA_LATENCY_QUERY=lowlatency=1 asks the page for a
// desynchronized (low-latency) canvas (bench/web_latency.py alternates
// such settings). Whole ray marches per frame (0.6-2.5
// s on SwiftShader) hold input up that long; frames in strips of about the
// budget answer it with a preview, and the target is two budgets. The wait
// for the next animation frame (up to 16.7 ms: Chromium dispatches
// pointermove and wheel turns with it; pointerrawupdate comes as the move
// arrives) is part of every latency answered by one, and a move's raw
// handler waits for the task running, so nothing else may hold the main
// thread for long: chunks are inflated in slices in idle time, and the
// worst events are explained frame by frame (explainWorst). A wheel turn
// sent through DevTools, as here, waits for one frame more before it
// reaches the page (explainTrace): its latency is at least a frame
// interval plus the answering callback, whatever the page does.
// TESSERA_LATENCY_TRACE=FILE records a Chrome trace of the input sequence
// and prints each input's way through Chromium (TESSERA_LATENCY_TRACE_MORE:
// more trace categories, comma-separated, such as the GPU process's
// disabled-by-default-gpu.decoder and gpu.angle). TESSERA_LATENCY_FLOOR=1
// answers the same input with a page that does the least a WebGL page can
// (floorPage): the floor under the page's latencies on this machine;
// TESSERA_LATENCY_FLOOR=window, the same in a copy of the page's window
// (what presenting its controls adds). TESSERA_LATENCY_INPUT=x11
// sends the same input through the X server instead (XTest, as a mouse
// would: x11_input.py), with Chromium on a display of its own
// (TESSERA_HEADFUL=1 xvfb-run -a node --test tests/browser/latency.test.mjs):
// wheel turns then reach the page without DevTools' wait. The file's second
// test runs it so, when xvfb-run is there, after the DevTools run.
import { test } from 'node:test';
import { execFile } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { CH2, check, served, browserSuite, snapshot, differingPixels, psnrOf } from './fixture.mjs';

const checks = browserSuite();

// The page's frame budget (app.js: ?budget=, 12 ms by default), stated here.
const BUDGET_MS = 12;
const SIZE = 256;

test('input during a store\'s refinement: every event answered by the next frame, none held by a stall (worst vs 2 frame budgets reported)', checks(storeInputLatency));

// The same input as a mouse's reaches Chromium, through the X server: a
// wheel turn sent through DevTools waits for a frame more before the page
// sees it (explainTrace), so the run above cannot show a wheel turn's
// latency as a user meets it. This file again, under xvfb-run with
// Chromium on its display (TESSERA_HEADFUL=1, TESSERA_LATENCY_INPUT=x11),
// with the same checks; skipped in that run itself (or any run that chose
// its input), and where xvfb-run is missing.
const xvfbRun = ['/usr/bin/xvfb-run', '/usr/local/bin/xvfb-run'].find((p) => fs.existsSync(p));
test('the same input through the X server (xvfb-run, headful Chromium, XTest): the same checks (worst vs 2 frame budgets reported)',
  { skip: process.env.TESSERA_LATENCY_INPUT ? 'this run chose its input' : !xvfbRun ? 'no xvfb-run (scripts/setup.sh)' : false },
  () => runAgain('x11', { TESSERA_HEADFUL: '1', TESSERA_LATENCY_INPUT: 'x11' }, true));

// The floor under the page's latencies in this run: the floor page
// (TESSERA_LATENCY_FLOOR=1, floorPage) answers the same input, through
// DevTools and through the X server, and its latencies are reported beside
// the page's (bench/web_latency.py --floor alternates them).
test('the floor page (the least any page can do) through DevTools and the X server: every input answered (its worst reported)',
  { skip: process.env.TESSERA_LATENCY_INPUT || process.env.TESSERA_LATENCY_FLOOR ? 'this run chose its input or page' : false },
  async () => {
    await runAgain('floor devtools', { TESSERA_LATENCY_FLOOR: '1', TESSERA_LATENCY_INPUT: 'devtools' }, false);
    if (xvfbRun) await runAgain('floor x11', { TESSERA_LATENCY_FLOOR: '1', TESSERA_HEADFUL: '1', TESSERA_LATENCY_INPUT: 'x11' }, true);
  });

// This file run again as a test run of its own with `env` added (under
// xvfb-run when `onDisplay`), its latency lines printed with `prefix`.
async function runAgain(prefix, env, onDisplay) {
  const args = ['--test', '--test-reporter=spec', fileURLToPath(import.meta.url)];
  const run = await new Promise((resolve) => {
    execFile(onDisplay ? xvfbRun : process.execPath, onDisplay ? ['-a', process.execPath, ...args] : args,
      // (Without the test runner's NODE_TEST_CONTEXT: the run is a test run of its own.)
      { env: { ...Object.fromEntries(Object.entries(process.env).filter(([k]) => k !== 'NODE_TEST_CONTEXT')), ...env },
        timeout: 300000, maxBuffer: 64 << 20 },
      (err, stdout, stderr) => resolve({ err, out: `${stdout}${stderr}` }));
  });
  const lines = run.out.split('\n').filter((l) => /latency|FAIL|Error|not ok/.test(l));
  for (const l of lines) console.log(`${prefix} ${l.trim()}`);
  if (run.err) throw new Error(`the ${prefix} run failed (${run.err.code ?? run.err.signal ?? run.err.message}):\n${run.out.slice(-4000)}`);
}

// Runs in the page before its scripts: which animation-frame callbacks drew
// on the canvas (a draw, clear or blit into the default framebuffer), and
// when input events were stamped and handled.
// A draw outside an animation-frame callback (the page answering a move as
// it arrives, in its pointerrawupdate handler) counts as a frame too, from
// its first draw call to the end of the handler that made it (a microtask
// after it: the page's handler ends with the preview's read-back, which
// waits for the GPU). window.latencyCaptureNext = true: the next frame's
// pixels (top row first) are kept in latency.capture.
function instrument() {
  const lat = { frames: [], events: [], callbacks: [], capture: null };
  window.latency = lat;
  let drew = false;
  let inCallback = false;
  let outside = null;  // a draw outside an animation-frame callback, until its task's microtask
  let gl = null;
  const capture = (raw) => {
    if (!window.latencyCaptureNext || !gl) return;
    window.latencyCaptureNext = false;
    const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
    const p = new Uint8Array(w * h * 4);
    const two = typeof WebGL2RenderingContext !== 'undefined' && gl instanceof WebGL2RenderingContext;
    const draw = gl.getParameter(two ? gl.DRAW_FRAMEBUFFER_BINDING : gl.FRAMEBUFFER_BINDING);
    const read = two ? gl.getParameter(gl.READ_FRAMEBUFFER_BINDING) : draw;
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, p);
    if (two) {
      gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, draw);
      gl.bindFramebuffer(gl.READ_FRAMEBUFFER, read);
    } else {
      gl.bindFramebuffer(gl.FRAMEBUFFER, draw);
    }
    const top = new Uint8Array(w * h * 4);
    for (let y = 0; y < h; y++) top.set(p.subarray((h - 1 - y) * w * 4, (h - y) * w * 4), y * w * 4);
    lat.capture = { raw, pixels: Array.from(top) };
  };
  // GL errors asked for (getError: a round trip to the GPU process each)
  // and textures and buffers made (each checks its allocation: two
  // getErrors), outside animation-frame callbacks per task (an input
  // handler's), and inside them in all.
  lat.handlerGl = [];
  lat.frameGetErrors = 0;
  let glTask = null;
  const countGl = (key) => {
    if (inCallback) {
      if (key === 'getError') lat.frameGetErrors++;
      return;
    }
    if (!glTask) {
      glTask = { getError: 0, made: 0, drew: false, start: performance.now() };
      lat.handlerGl.push(glTask);
      queueMicrotask(() => { glTask = null; });
    }
    if (key === 'draw') glTask.drew = true;
    else glTask[key]++;
  };
  for (const Ctx of [window.WebGL2RenderingContext, window.WebGLRenderingContext]) {
    if (!Ctx) continue;
    const p = Ctx.prototype;
    for (const name of ['getError', 'createTexture', 'createBuffer']) {
      const f = p[name];
      p[name] = function (...args) {
        countGl(name === 'getError' ? name : 'made');
        return f.apply(this, args);
      };
    }
    const bind = p.bindFramebuffer;
    p.bindFramebuffer = function (target, fb) {
      if (target !== this.READ_FRAMEBUFFER) this.latencyDefault = fb === null;
      return bind.call(this, target, fb);
    };
    for (const name of ['drawArrays', 'drawElements', 'clear', 'blitFramebuffer']) {
      const f = p[name];
      if (!f) continue;
      p[name] = function (...args) {
        if (this.latencyDefault !== false) {
          drew = true;
          gl = this;
          countGl('draw');
          if (!inCallback && !outside) {
            outside = { start: performance.now() };
            queueMicrotask(() => {
              lat.frames.push({ start: outside.start, end: performance.now(), raw: true });
              capture(true);
              outside = null;
            });
          }
        }
        return f.apply(this, args);
      };
    }
  }
  const raf = window.requestAnimationFrame.bind(window);
  window.requestAnimationFrame = (cb) => raf((ts) => {
    const start = performance.now();
    drew = false;
    inCallback = true;
    try {
      cb(ts);
    } finally {
      inCallback = false;
      const end = performance.now();
      if (drew) {
        lat.frames.push({ start, end });
        capture(false);
      }
      lat.callbacks.push({ start, end, drew });
      if (lat.callbacks.length > 20000) lat.callbacks.splice(0, 5000);
    }
  });
  const note = (e) => {
    const coalesced = e.getCoalescedEvents ? e.getCoalescedEvents() : [];
    const stamp = Math.min(e.timeStamp, ...coalesced.map((c) => c.timeStamp));
    const z = window.tessera && window.tessera.zarr && window.tessera.zarr();
    lat.events.push({ type: e.type, stamp, handled: performance.now(),
      refining: !!(z && z.last && !z.last.complete), buttons: e.buttons });
  };
  for (const type of ['pointermove', 'pointerup', 'wheel']) window.addEventListener(type, note, { capture: true, passive: true });
  // Raw moves are noted only when the page listens for them (Chromium sends
  // them only then).
  const add = EventTarget.prototype.addEventListener;
  let rawNoted = false;
  EventTarget.prototype.addEventListener = function (type, ...rest) {
    if (type === 'pointerrawupdate' && !rawNoted) {
      rawNoted = true;
      add.call(window, type, note, { capture: true, passive: true });
    }
    return add.call(this, type, ...rest);
  };
}

// Each drag move, release and wheel turn: its stamp, when the page first
// handled it (a drag move: as it arrived, pointerrawupdate, when the page
// listens for it; else at its pointermove), the first frame drawn after
// that, and when that frame reached the compositor: at the end of its
// animation-frame callback, or, drawn outside one, at the start of the next
// animation frame (the frame it is committed with).
function answers(lat) {
  const raw = lat.events.filter((e) => e.type === 'pointerrawupdate');
  const rows = [];
  for (const e0 of lat.events) {
    if (e0.type === 'pointerrawupdate') continue;
    if (e0.type === 'pointermove' && !e0.buttons) continue;  // a move without a drag asks for no frame
    let e = e0;
    if (e0.type === 'pointermove') {
      const r = raw.find((x) => Math.abs(x.stamp - e0.stamp) < 0.01 && x.handled <= e0.handled);
      if (r) e = { ...e0, handled: r.handled, raw: true };
    }
    const f = lat.frames.find((fr) => fr.start >= e.handled);
    if (!f) { rows.push({ e, f: null }); continue; }
    let committed = f.end;
    if (f.raw) {
      const next = lat.callbacks.find((cb) => cb.start >= f.end);
      committed = next ? next.start : NaN;
    }
    rows.push({ e, f, latency: f.end - e.stamp, toCommit: committed - e.stamp });
  }
  return rows;
}

// Where the worst latencies came from, frame by frame: for each of the five
// worst events, the wait until the page handled it (the animation-frame
// callbacks and the chunk decodes in idle time that held the main thread
// meanwhile, the longest with its store call; the rest: other tasks, or
// Chromium waiting for the next frame) and the frame that answered it, with
// the store call's parts (its own work before the preview, the layout's
// update, the wait for its uploads, the ray caster's tables, the preview
// and its size); then the store's calls by kind and the chunks decoded and
// handed over meanwhile.
function explainWorst(lat, z) {
  const callAt = (cb) => (z.calls || []).find((c) => c.t + z.t0 >= cb.start - 0.5 && c.t + z.t0 <= cb.end + 0.5);
  const parts = (c) => (!c ? 'no store call' : `${c.preview ? 'preview' : c.stream_ms > 0 ? 'streaming' : c.tables_ms > 0.5 && !c.shown ? 'tables' : 'strip'} ` +
    `${c.ms.toFixed(1)} ms (setup ${(c.setup_ms || 0).toFixed(1)}, update ${(c.update_ms || 0).toFixed(1)}, upload wait ${(c.upload_wait_ms || 0).toFixed(1)}, ` +
    `tables ${(c.tables_ms || 0).toFixed(1)}, preview ${(c.preview_ms || 0).toFixed(1)}` +
    `${c.preview ? ` at ${c.preview_size.join('x')}` : ''}, ${c.uploaded || 0} bricks uploaded` +
    `${c.strip_rows > 0 ? `, ${(100 * c.strip_rows).toFixed(1)} % of the rows` : ''})`);
  const decodeTasks = (z.decodeTasks || []).map((d) => ({ start: d.t + z.t0, end: d.t + z.t0 + d.ms }));
  const overlap = (list, a, b) => list.reduce((sum, x) => sum + Math.max(0, Math.min(b, x.end) - Math.max(a, x.start)), 0);
  const rows = [];
  for (const { e, f, latency } of answers(lat)) {
    if (!f) continue;
    const held = lat.callbacks.filter((cb) => cb.end > e.stamp && cb.start < e.handled);
    const longest = held.reduce((a, b) => (!a || b.end - b.start > a.end - a.start ? b : a), null);
    rows.push({ e, f, latency, longest,
      frameMs: overlap(lat.callbacks, e.stamp, e.handled), decodeMs: overlap(decodeTasks, e.stamp, e.handled) });
  }
  rows.sort((a, b) => b.latency - a.latency);
  for (const r of rows.slice(0, 5)) {
    const wait = r.e.handled - r.e.stamp;
    const held = r.longest ? `; the longest ${(r.longest.end - r.longest.start).toFixed(1)} ms: ${parts(callAt(r.longest))}` : '';
    console.log(`latency: worst ${r.e.type}${r.e.raw ? ' (raw)' : ''} ${r.latency.toFixed(1)} ms = handled after ${wait.toFixed(1)} ms ` +
                `(frame callbacks ${r.frameMs.toFixed(1)}, chunk decodes ${r.decodeMs.toFixed(1)}, ` +
                `other tasks or the wait for a frame ${Math.max(0, wait - r.frameMs - r.decodeMs).toFixed(1)}${held}); ` +
                `answered ${(r.f.start - r.e.handled).toFixed(1)} ms later by a ${(r.f.end - r.f.start).toFixed(1)} ms ` +
                `${r.f.raw ? 'draw as it arrived' : 'frame'}: ${parts(callAt(r.f))}`);
  }
  const calls = (z.calls || []).filter((c) => c.t > z.firstImageMs);
  const kinds = { preview: (c) => c.preview, streaming: (c) => !c.preview && c.stream_ms > 0,
    tables: (c) => !c.preview && !(c.stream_ms > 0) && !c.shown && c.tables_ms > 0.5, strip: (c) => !c.preview && !(c.stream_ms > 0) && !(c.tables_ms > 0.5 && !c.shown) };
  const text = (v) => { const s = stats(v); return `median ${s.median.toFixed(1)}, worst ${s.worst.toFixed(1)}`; };
  console.log('latency: store calls by kind (ms): ' + Object.entries(kinds).map(([k, is]) => {
    const v = calls.filter(is);
    return `${k} ${v.length}: ${text(v.map((c) => c.ms))} [setup ${text(v.map((c) => c.setup_ms || 0))}; update ${text(v.map((c) => c.update_ms || 0))}; ` +
      `upload wait ${text(v.map((c) => c.upload_wait_ms || 0))}; tables ${text(v.map((c) => c.tables_ms || 0))}; preview ${text(v.map((c) => c.preview_ms || 0))}]`;
  }).join('; '));
  const decodes = z.decodes || [];
  console.log(`latency: chunks decoded in the page ${decodes.length}: ${text(decodes.map((d) => d.ms))} ms until done, ` +
              `busy ${text(decodes.map((d) => d.busy_ms || d.ms))} ms in ${text(decodes.map((d) => d.slices || 1))} slices, ` +
              `idle tasks ${text((z.decodeTasks || []).map((d) => d.ms))} ms; ` +
              `handed to the module ${(z.tasks || []).length}: ${text((z.tasks || []).map((d) => d.put_ms))} ms; ` +
              `animation-frame callbacks ${lat.callbacks.length}: ${text(lat.callbacks.map((c) => c.end - c.start))} ms`);
}

// Each input event's way through Chromium, from a trace of the input
// sequence (TESSERA_LATENCY_TRACE): from its timestamp to the browser
// forwarding it to the page's renderer, to its dispatch on the page's main
// thread (at the start of an animation frame: Chromium aligns moves and
// wheel turns with them), and to the end of the animation-frame callback
// after it. A wheel turn sent through DevTools (Input.dispatchMouseEvent)
// is forwarded only once the renderer has committed a frame
// (InputHandler::HandleMouseEvent: InsertVisualStateCallback), so it is
// dispatched at the second frame after its timestamp, never the first.
function explainTrace(trace) {
  const ev = trace.traceEvents || trace;
  const dispatch = ev.filter((e) => e.name === 'EventDispatch' && e.args && e.args.data);
  if (!dispatch.length) { console.log('latency trace: no input events dispatched in the trace'); return; }
  const renderer = dispatch[0].pid;
  const byTs = (a, b) => a.ts - b.ts;
  const frames = ev.filter((e) => e.name === 'BeginMainThreadFrame' && e.pid === renderer).map((e) => e.ts).sort((a, b) => a - b);
  const callbacks = ev.filter((e) => e.name === 'FireAnimationFrame' && e.pid === renderer && e.dur !== undefined).sort(byTs);
  const forwards = ev.filter((e) => e.name === 'RenderWidgetHostImpl::ForwardWheelEvent' && e.args && e.args.dy !== 0).sort(byTs);
  const generated = (type) => [...new Set(ev.filter((e) => e.name === 'EventLatency' && e.ph === 'b' &&
    e.args && e.args.event_latency && e.args.event_latency.event_type === type).map((e) => e.ts))].sort((a, b) => a - b);
  const ms = (us) => us / 1000;
  const text = (v) => { const s = stats(v); return `median ${s.median.toFixed(1)}, worst ${s.worst.toFixed(1)}`; };
  for (const [type, dom] of [['MOUSE_DRAGGED', 'pointermove'], ['MOUSE_WHEEL', 'wheel']]) {
    const rows = [];
    for (const g of generated(type)) {
      const d = dispatch.find((e) => e.ts >= g && e.args.data.type === dom);
      if (!d) continue;
      const cb = callbacks.find((c) => c.ts >= d.ts);
      const f = forwards.find((e) => e.ts >= g);
      rows.push({ forward: type === 'MOUSE_WHEEL' && f ? ms(f.ts - g) : 0, dispatch: ms(d.ts - g),
        frameIndex: frames.filter((t) => t > g && t <= d.ts + 1000).length,
        callback: cb ? ms(cb.dur) : NaN, end: cb ? ms(cb.ts + cb.dur - g) : NaN });
    }
    if (!rows.length) continue;
    const nth = {};
    rows.forEach((r) => { nth[r.frameIndex] = (nth[r.frameIndex] || 0) + 1; });
    console.log(`latency trace: ${dom} ${rows.length}: ` +
      (type === 'MOUSE_WHEEL' ? `forwarded by the browser after ${text(rows.map((r) => r.forward))} ms (its wait for a committed frame); ` : '') +
      `dispatched after ${text(rows.map((r) => r.dispatch))} ms, at the Nth frame after its timestamp ` +
      `${Object.entries(nth).map(([n, c]) => `${n}: ${c}`).join(', ')}; the answering callback ${text(rows.map((r) => r.callback))} ms; ` +
      `timestamp to its end ${text(rows.map((r) => r.end))} ms`);
  }
}

// TESSERA_LATENCY_INPUT=x11: the plan sent through the X server
// (x11_input.py), at the screen position of the page's coordinates
// (calibrated by one move: where the page saw it). Returns the page's time
// origin and each event sent, with its epoch times before and after the X
// server took it.
async function sendThroughX(page, plan, captureAt) {
  // (The context's first tab stays open: Chromium on a display quits with
  // its last window.)
  await page.bringToFront();
  await page.evaluate(() => {
    window.latencyLastMove = null;
    window.addEventListener('pointermove', (e) => {
      window.latencyLastMove = { x: e.clientX, y: e.clientY, t: performance.timeOrigin + e.timeStamp };
    }, { capture: true });
  });
  const driver = path.join(path.dirname(fileURLToPath(import.meta.url)), 'x11_input.py');
  const drive = (events, start) => new Promise((resolve, reject) => {
    execFile('python3', [driver, JSON.stringify(events), String(start)], { timeout: 60000 }, (err, stdout, stderr) => {
      if (err) reject(new Error(`x11_input.py: ${stderr || err.message}`));
      else resolve(stdout.trim().split('\n').filter((l) => l).map((l) => JSON.parse(l)));
    });
  });
  const guess = await page.evaluate(() => ({ x: window.screenX + (window.outerWidth - window.innerWidth) / 2,
    y: window.screenY + window.outerHeight - window.innerHeight }));
  // Where the page sees a move to `to` (screen pixels): the first move
  // stamped after it was sent (the pointer may have moved the page before).
  const seenAt = async (to) => {
    const [r] = await drive([{ at: 0, kind: 'move', ...to }], Date.now());
    await page.waitForFunction((t) => window.latencyLastMove && window.latencyLastMove.t >= t, r.before - 2, { timeout: 5000 });
    return page.evaluate(() => window.latencyLastMove);
  };
  const probe = { x: Math.round(guess.x + plan[0].x - 40), y: Math.round(guess.y + plan[0].y - 40) };
  const seen = await seenAt(probe);
  const off = { x: probe.x - seen.x, y: probe.y - seen.y };
  const centre = { x: Math.round(plan[0].x + off.x), y: Math.round(plan[0].y + off.y) };
  const atCentre = await seenAt(centre);
  if (Math.abs(atCentre.x - plan[0].x) > 1 || Math.abs(atCentre.y - plan[0].y) > 1) {
    throw new Error(`x11 input: a move to the view's centre (${plan[0].x}, ${plan[0].y} in the page) reached it at ${atCentre.x}, ${atCentre.y}`);
  }
  console.log(`latency: x11 input: the page at screen offset ${off.x.toFixed(0)}, ${off.y.toFixed(0)} (window ${guess.x.toFixed(0)}, ${guess.y.toFixed(0)})`);
  const events = [{ at: -150, kind: 'move', x: plan[0].x + off.x, y: plan[0].y + off.y }];
  for (const e of plan) {
    const x = Math.round(e.x + off.x), y = Math.round(e.y + off.y);
    if (e.kind === 'move') events.push({ at: e.at, kind: 'move', x, y });
    else if (e.kind === 'wheel') events.push({ at: e.at, kind: 'press', button: e.up ? 4 : 5 }, { at: e.at, kind: 'release', button: e.up ? 4 : 5 });
    else events.push({ at: e.at, kind: e.kind, button: 1 });
  }
  const timeOrigin = await page.evaluate(() => performance.timeOrigin);
  const start = Date.now() + 400;
  const capture = new Promise((resolve) => setTimeout(() => resolve(page.evaluate(() => { window.latencyCaptureNext = true; })),
    start + captureAt - Date.now()));
  const sentEvents = await drive(events, start);
  await capture;
  return { timeOrigin, sent: sentEvents.map((r) => ({ ...events[r.i], before: r.before, after: r.after })) };
}

// x11 mode: each page event's own timeStamp against the time the X server
// took it (the page's clock: performance.timeOrigin + timeStamp), and the
// latencies again from the time it was sent.
function explainX(x11, lat) {
  const sentAt = (kind) => x11.sent.filter((e) => e.kind === kind && (kind !== 'press' || e.button >= 4))
    .map((e) => ({ before: e.before - x11.timeOrigin, after: e.after - x11.timeOrigin }));
  const moves = sentAt('move').slice(1), wheels = sentAt('press');
  // The last one sent before the page's stamp (X server time is in whole
  // milliseconds: up to 1 ms early).
  const match = (sent, stamp) => sent.filter((x) => x.before <= stamp + 2).pop() || null;
  const text = (v) => { const s = stats(v); return `median ${s.median.toFixed(1)}, min ${Math.min(...v).toFixed(1)}, worst ${s.worst.toFixed(1)} over ${s.n}`; };
  const stampOffsets = { pointermove: [], wheel: [] };
  const fromSend = { pointermove: [], wheel: [] };
  for (const { e, f } of answers(lat)) {
    if (!f || !(e.type in stampOffsets)) continue;
    const s = match(e.type === 'wheel' ? wheels : moves, e.stamp);
    if (!s) continue;
    stampOffsets[e.type].push(e.stamp - s.before);
    fromSend[e.type].push(f.end - s.before);
  }
  for (const t of Object.keys(stampOffsets)) {
    console.log(`latency: x11 ${t}: its timeStamp after the X server was sent it: ${text(stampOffsets[t])} ms ` +
                `(the XSync took ${text((t === 'wheel' ? wheels : moves).map((s) => s.after - s.before))} ms); ` +
                `from sending it to the end of the draw that answered it: ${text(fromSend[t])} ms`);
  }
  return stampOffsets;
}

// TESSERA_LATENCY_FLOOR=1: the page is replaced, in the same tab and
// window, by one with a canvas of the 3D view's box and context whose
// handlers answer each input with the least any WebGL page must do to show
// an answer: a clear of its canvas to a new colour and a one-pixel
// read-back (which waits for the GPU process, as the store's preview
// does), a drag's moves as they arrive (pointerrawupdate), a release and a
// wheel turn in their handlers, and an animation-frame loop that draws
// nothing (the store's refinement asks for every frame). Its latencies are
// what Chromium, the GPU process and the display take on this machine
// whatever a page does: the floor under the page's.
// TESSERA_LATENCY_FLOOR=window: the same answers, on a copy of the page's
// window (its markup as it stands, with its style sheet and without its
// scripts; the 3D view's canvas answers as above): what presenting a
// window with the page's controls adds on this machine, the preview aside.
async function floorPage(page, url, tmp, box, attributes, webgl2, withWindow) {
  const content = withWindow
    ? (await page.evaluate(() => document.body.innerHTML)).replace(/<script\b[^>]*>[\s\S]*?<\/script>/gi, '')
    : '<canvas id="canvas"></canvas>';
  const style = withWindow ? '<link rel="stylesheet" href="/style.css">' : `<style>
html, body { margin: 0; overflow: hidden; background: #202020; }
canvas { position: absolute; left: ${box.x}px; top: ${box.y}px; width: ${box.width}px; height: ${box.height}px; touch-action: none; }
</style>`;
  const html = `<!doctype html><html><head><meta charset="utf-8"><title>latency floor</title>${style}</head><body>${content}<script>
const canvas = document.getElementById('canvas');
${withWindow ? '' : `canvas.width = Math.round(${box.width} * devicePixelRatio);
canvas.height = Math.round(${box.height} * devicePixelRatio);`}
const gl = canvas.getContext('${webgl2 ? 'webgl2' : 'webgl'}', ${JSON.stringify(attributes)});
const pixel = new Uint8Array(4);
let answers = 0;
function answer() {
  answers++;
  gl.clearColor((answers * 37 % 256) / 255, (answers * 91 % 256) / 255, 0.5, 1);
  gl.clear(gl.COLOR_BUFFER_BIT);
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
}
canvas.addEventListener('pointerdown', (e) => { canvas.setPointerCapture(e.pointerId); answer(); });
canvas.addEventListener('pointerrawupdate', (e) => { if (e.buttons) answer(); });
canvas.addEventListener('pointerup', answer);
canvas.addEventListener('wheel', (e) => { e.preventDefault(); answer(); }, { passive: false });
(function loop() { requestAnimationFrame(loop); })();
window.floorReady = true;
</script></body></html>`;
  fs.writeFileSync(path.join(tmp, 'floor.html'), html);
  await page.goto(`${url}/data/floor.html`);
  await page.waitForFunction(() => window.floorReady === true);
  const placed = await page.locator('#canvas').boundingBox();
  if (Math.abs(placed.x - box.x) > 0.5 || Math.abs(placed.y - box.y) > 0.5 || Math.abs(placed.width - box.width) > 0.5) {
    throw new Error(`latency floor: the canvas at ${JSON.stringify(placed)}, not the 3D view's ${JSON.stringify(box)}`);
  }
}

// The floor page's latencies (floorPage), as the store's are reported, with
// the same target; every event must have been answered.
function reportFloor(lat, x11, box) {
  if (x11) explainX(x11, lat);
  const latencies = { pointermove: [], pointerup: [], wheel: [] };
  let unanswered = 0;
  for (const { e, f, latency } of answers(lat)) {
    if (!f) { unanswered++; continue; }
    latencies[e.type].push(latency);
  }
  const all = stats([...latencies.pointermove, ...latencies.pointerup, ...latencies.wheel]);
  const text = (s) => `median ${s.median.toFixed(1)} ms, 90th percentile ${s.p90.toFixed(1)} ms, worst ${s.worst.toFixed(1)} ms over ${s.n}`;
  console.log(`latency: the floor page at ${Math.round(box.width)}x${Math.round(box.height)}, budget ${BUDGET_MS} ms: all events ${text(all)}; ` +
              Object.entries(latencies).map(([t, v]) => `${t}: ${text(stats(v))}`).join('; '));
  console.log(`latency: the floor page: target worst <= ${2 * BUDGET_MS} ms (2 frame budgets): ${all.worst <= 2 * BUDGET_MS ? 'met' : 'NOT met'} ` +
              `(worst ${all.worst.toFixed(1)} ms, median ${all.median.toFixed(1)} ms; load average ${os.loadavg()[0].toFixed(1)} on ${os.cpus().length} cores)`);
  check('latency floor: the drag, its release and the wheel turns were each answered by a frame',
        latencies.pointermove.length >= 5 && latencies.pointerup.length === 1 && latencies.wheel.length >= 6 && unanswered === 0,
        `${all.n} answered, ${unanswered} without a frame after them`);
}

function stats(values) {
  const v = [...values].sort((a, b) => a - b);
  const at = (q) => (v.length ? v[Math.min(v.length - 1, Math.floor(q * v.length))] : NaN);
  return { n: v.length, median: at(0.5), p90: at(0.9), worst: v.length ? v[v.length - 1] : NaN };
}

async function storeInputLatency(context, url, tmp, run) {
  if (!fs.existsSync(CH2)) { check(`latency test needs ${CH2} (mricron-data)`, false); return; }
  const store = path.join(tmp, 'ch2.ome.zarr');
  run('convert', CH2, store, '--compressor', 'zlib');
  // The finest level 2 s late, the next 0.4 s: refinement goes on for
  // several seconds after the first image, through the whole input sequence.
  served.delayMs = (p) => (/^\/data\/ch2\.ome\.zarr\/0\/\d/.test(p) ? 2000 : /^\/data\/ch2\.ome\.zarr\/1\/\d/.test(p) ? 400 : 0);
  const page = await context.newPage();
  const logs = [];
  page.on('console', (m) => logs.push(`${m.type()}: ${m.text()}`));
  page.on('pageerror', (e) => logs.push(`pageerror: ${e.message}`));
  await page.addInitScript(instrument);
  // TESSERA_LATENCY_QUERY: more of the page's parameters (a=1&b=2), for
  // alternating runs of two settings.
  const extra = process.env.TESSERA_LATENCY_QUERY ? `&${process.env.TESSERA_LATENCY_QUERY}` : '';
  await page.goto(`${url}/index.html?size=${SIZE}&slices=0&budget=${BUDGET_MS}&url=/data/ch2.ome.zarr${extra}`);
  await page.evaluate(() => window.tessera.ready);
  // The 3D view's context is an ordinary one unless the page is asked for
  // a low-latency (desynchronized) one (tessera.js: lowLatencyContext).
  const [attributes, webgl2] = await page.evaluate(() => {
    const c = document.getElementById('canvas');
    const gl2 = c.getContext('webgl2');
    return [(gl2 || c.getContext('webgl')).getContextAttributes(), !!gl2];
  });
  const lowLatency = /(^|&)lowlatency=1(&|$)/.test(extra.slice(1));
  check(`latency: the canvas's WebGL context is ${lowLatency ? 'a low-latency (desynchronized)' : 'an ordinary'} one`,
        attributes.desynchronized === lowLatency, `desynchronized: ${attributes.desynchronized}`);
  await page.waitForFunction(() => { const z = window.tessera.zarr(); return z && z.firstImageMs !== null; }, null, { timeout: 60000 });
  const before = await snapshot(page);  // the first view, for the drag's last preview below
  const box = await page.locator('#canvas').boundingBox();
  // TESSERA_LATENCY_FLOOR=1: the same window, canvas box and input,
  // answered by a page that does the least any WebGL page must to show an
  // answer (floorPage): what the browser alone takes, for comparison.
  const floorMode = process.env.TESSERA_LATENCY_FLOOR || '';
  if (!['', '0', '1', 'window'].includes(floorMode)) throw new Error(`TESSERA_LATENCY_FLOOR=${floorMode}: 1 or window`);
  const floor = floorMode === '1' || floorMode === 'window';
  if (floor) await floorPage(page, url, tmp, box, attributes, webgl2, floorMode === 'window');
  const cdp = await context.newCDPSession(page);
  const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
  // Sent on a clock, never awaiting the page (an acknowledgement waits for
  // the page's main thread), each stamped with its time of sending.
  const sent = [];
  const send = (type, params) => sent.push(cdp.send(type, { ...params, timestamp: Date.now() / 1000 }));
  // TESSERA_LATENCY_INPUT=x11 (with TESSERA_HEADFUL=1 under xvfb-run): the
  // input goes through the X server as a mouse's would (x11_input.py,
  // XTest), not DevTools.
  // TESSERA_LATENCY_INPUT=touch: the drag is one finger's (DevTools' touch
  // events, touch emulated), the wheel turns as before.
  const inputMode = process.env.TESSERA_LATENCY_INPUT || 'devtools';
  if (!['devtools', 'touch', 'x11'].includes(inputMode)) {
    throw new Error(`TESSERA_LATENCY_INPUT=${inputMode}: devtools (the default), touch or x11`);
  }
  if (inputMode === 'touch') await cdp.send('Emulation.setTouchEmulationEnabled', { enabled: true, maxTouchPoints: 5 });
  if (inputMode === 'x11' && process.env.TESSERA_HEADFUL !== '1') {
    throw new Error('TESSERA_LATENCY_INPUT=x11 needs Chromium on an X display: TESSERA_HEADFUL=1, under xvfb-run');
  }
  // TESSERA_LATENCY_TRACE=FILE: a Chrome trace of the input sequence (input,
  // latencyInfo, scheduler, cc, viz and gpu categories) written to FILE, to
  // follow an event from the browser process to the frame that answered it.
  const traceFile = process.env.TESSERA_LATENCY_TRACE || '';
  if (traceFile) {
    await cdp.send('Tracing.start', { transferMode: 'ReturnAsStream', traceConfig: { recordMode: 'recordAsMuchAsPossible',
      includedCategories: ['input', 'latencyInfo', 'benchmark', 'devtools.timeline', 'toplevel', 'gpu', 'cc', 'viz',
        'blink', 'renderer.scheduler', 'disabled-by-default-devtools.timeline.frame', 'v8.execute',
        ...(process.env.TESSERA_LATENCY_TRACE_MORE || '').split(',').filter((c) => c)] } });
  }
  // The input sequence (ms from its start, page coordinates): a drag of
  // MOVES moves 70 ms apart, its release, and WHEELS wheel turns about
  // 200 ms apart, in and out. Chromium holds moves and wheel turns for the
  // next animation frame, so an event's wait depends on where in the frame
  // interval (16.7 ms at 60 Hz) it comes: the moves' 70 ms steps fall at
  // five points of it, and the wheel turns' steps are 200 ms plus a
  // twelfth of an interval (200 ms alone is twelve intervals: every turn
  // would fall at the same point, and a run's worst turn would depend on
  // that point alone), so that they sample the whole interval.
  // TESSERA_LATENCY_WHEEL_MS sets the turns' step instead (a wheel spun
  // fast sends them tens of ms apart: bench/web_latency.py --wheel-ms).
  const MOVES = 40, WHEELS = 12;
  const WHEEL_STEP_MS = Number(process.env.TESSERA_LATENCY_WHEEL_MS) || 200 + 1000 / 60 / WHEELS;
  const plan = [{ at: 0, kind: 'press', x: cx, y: cy }];
  for (let i = 1; i <= MOVES; i++) plan.push({ at: i * 70, kind: 'move', x: cx + 3 * i, y: cy + (i % 5) });
  plan.push({ at: (MOVES + 1) * 70, kind: 'release', x: cx + 3 * MOVES, y: cy });
  for (let i = 0; i < WHEELS; i++) plan.push({ at: (MOVES + 4) * 70 + i * WHEEL_STEP_MS, kind: 'wheel', x: cx, y: cy, up: i % 2 === 0 });
  // The last move's answer is kept (its pixels: checked against the
  // refined frame of the same view below); asked for 30 ms before it.
  const captureAt = MOVES * 70 - 30;
  let x11 = null;
  if (inputMode === 'x11') {
    x11 = await sendThroughX(page, plan, captureAt);
  } else {
    const t0 = Date.now();
    const at = async (ms) => { const due = t0 + ms; if (Date.now() < due) await new Promise((r) => setTimeout(r, due - Date.now())); };
    const cdpEvent = { press: 'mousePressed', move: 'mouseMoved', release: 'mouseReleased', wheel: 'mouseWheel' };
    const touchEvent = { press: 'touchStart', move: 'touchMove', release: 'touchEnd' };
    let captured = false;
    for (const e of plan) {
      if (!captured && e.at >= captureAt) {
        await at(captureAt);
        sent.push(page.evaluate(() => { window.latencyCaptureNext = true; }));
        captured = true;
      }
      await at(e.at);
      if (e.kind === 'wheel') send('Input.dispatchMouseEvent', { type: 'mouseWheel', x: e.x, y: e.y, deltaX: 0, deltaY: e.up ? -100 : 100 });
      else if (inputMode === 'touch') send('Input.dispatchTouchEvent', { type: touchEvent[e.kind], touchPoints: e.kind === 'release' ? [] : [{ x: e.x, y: e.y, id: 1 }] });
      else send('Input.dispatchMouseEvent', { type: cdpEvent[e.kind], x: e.x, y: e.y, button: 'left', buttons: e.kind === 'release' ? 0 : 1, clickCount: 1 });
    }
  }
  await Promise.all(sent);
  await new Promise((r) => setTimeout(r, 3000));  // the last events' frames
  if (traceFile) {
    const done = new Promise((resolve) => cdp.once('Tracing.tracingComplete', resolve));
    await cdp.send('Tracing.end');
    const { stream } = await done;
    const parts = [];
    for (;;) {
      const r = await cdp.send('IO.read', { handle: stream, size: 1 << 20 });
      parts.push(r.base64Encoded ? Buffer.from(r.data, 'base64').toString() : r.data);
      if (r.eof) break;
    }
    await cdp.send('IO.close', { handle: stream });
    fs.writeFileSync(traceFile, parts.join(''));
    console.log(`latency: trace written to ${traceFile}`);
    explainTrace(JSON.parse(parts.join('')));
  }
  const lat = await page.evaluate(() => window.latency);
  if (floor) {
    served.delayMs = () => 0;
    reportFloor(lat, x11, box);
    await page.close();
    return;
  }
  const z = await page.evaluate(() => window.tessera.zarr());
  if (x11) {
    const offsets = explainX(x11, lat);
    // On the page's clock: stamped when the X server took the event (a
    // loaded server may take tens of ms now and then), not on another clock.
    const all = [...offsets.pointermove, ...offsets.wheel];
    const median = stats(all).median;
    check('latency: x11 input reached the page, its timeStamps on the page\'s clock (median within -2 to 5 ms of sending it)',
          offsets.pointermove.length >= 5 && offsets.wheel.length >= 6 && median >= -2 && median <= 5,
          `${offsets.pointermove.length} moves, ${offsets.wheel.length} wheel turns matched; median ${median.toFixed(1)} ms, ` +
          `from ${Math.min(...all).toFixed(1)} to ${Math.max(...all).toFixed(1)} ms`);
  }
  served.delayMs = () => 0;
  // TESSERA_LATENCY_DUMP=FILE: the page's events, frames and the store's calls as JSON.
  if (process.env.TESSERA_LATENCY_DUMP) fs.writeFileSync(process.env.TESSERA_LATENCY_DUMP, JSON.stringify({ lat, z }));
  // The store's own calls meanwhile (zarr-url.js): the work each did.
  const during = (z.calls || []).filter((c) => c.t > z.firstImageMs);
  const work = stats(during.map((c) => c.ms));
  const previews = stats(during.filter((c) => c.preview).map((c) => c.ms));
  const streaming = stats(during.filter((c) => !c.preview && c.stream_ms > 0).map((c) => c.ms));
  const stripCalls = stats(during.filter((c) => !c.preview && !(c.stream_ms > 0)).map((c) => c.ms));

  const latencies = { pointermove: [], pointerup: [], wheel: [] };
  const toCommit = { pointermove: [], pointerup: [], wheel: [] };
  const toHandled = { pointermove: [], pointerup: [], wheel: [] };
  let unanswered = 0, duringRefinement = 0, rawAnswered = 0;
  for (const { e, f, latency, toCommit: c } of answers(lat)) {
    if (!f) { unanswered++; continue; }
    latencies[e.type].push(latency);
    toCommit[e.type].push(c);
    toHandled[e.type].push(e.handled - e.stamp);
    if (f.raw) rawAnswered++;
    if (e.refining) duringRefinement++;
  }
  const all = stats([...latencies.pointermove, ...latencies.pointerup, ...latencies.wheel]);
  explainWorst(lat, z);
  const text = (s) => `median ${s.median.toFixed(1)} ms, 90th percentile ${s.p90.toFixed(1)} ms, worst ${s.worst.toFixed(1)} ms over ${s.n}`;
  const perType = Object.entries(latencies).map(([t, v]) => `${t}: ${text(stats(v))}`).join('; ');
  console.log(`latency: store refining at ${SIZE}x${SIZE}, budget ${BUDGET_MS} ms: all events ${text(all)}; ${perType}`);
  // A draw outside an animation frame reaches the compositor with the next
  // one: the time until then, per type (the same as above for frames drawn
  // in animation-frame callbacks).
  console.log(`latency: ${rawAnswered} events answered as they arrived (pointerrawupdate); until the frame that commits the answer: ` +
              Object.entries(toCommit).map(([t, v]) => `${t}: ${text(stats(v))}`).join('; '));
  console.log('latency: from the stamp until the page handled it (the way through the browser, and the task it waited for): ' +
              Object.entries(toHandled).map(([t, v]) => `${t}: ${text(stats(v))}`).join('; '));
  console.log(`latency: ${lat.frames.length} canvas frames; frame callbacks that drew took median ${stats(lat.frames.map((f) => f.end - f.start)).median.toFixed(1)} ms, ` +
              `worst ${stats(lat.frames.map((f) => f.end - f.start)).worst.toFixed(1)} ms; refined ${z.completeMs === null ? 'not yet' : `after ${z.completeMs.toFixed(0)} ms`}`);
  console.log(`latency: the store's calls while refining: ${work.n}, work median ${work.median.toFixed(1)} ms, worst ${work.worst.toFixed(1)} ms; ` +
              `previews ${previews.n}, median ${previews.median.toFixed(1)} ms, worst ${previews.worst.toFixed(1)} ms; ` +
              `streaming steps ${streaming.n}, median ${streaming.median.toFixed(1)} ms, worst ${streaming.worst.toFixed(1)} ms; ` +
              `strips ${stripCalls.n}, median ${stripCalls.median.toFixed(1)} ms, worst ${stripCalls.worst.toFixed(1)} ms`);
  // A preview drawn as its input arrived asks GL for no errors: each
  // getError waits for the GPU process (0.3-0.6 ms on SwiftShader), inside
  // the input's latency; the store's next query that waits anyway (a
  // strip's read-back, an upload's) reports them too (gpu::
  // leaveErrorsUnasked): asked at the next animation frame they waited for
  // the GPU process's composition of the page. Only a new render target's
  // texture, or a grown buffer of lines, checks its own allocation (clears,
  // then asks).
  const drawnAsArrived = (lat.handlerGl || []).filter((t) => t.drew);
  const asking = drawnAsArrived.filter((t) => t.getError !== 2 * t.made);
  check('latency: previews drawn as input arrived asked GL for no errors beyond a new texture\'s or buffer\'s allocation check, and the animation frames\' store calls asked',
        drawnAsArrived.length >= 5 && asking.length === 0 && lat.frameGetErrors > 0,
        `${drawnAsArrived.length} drawn as input arrived: getError ${drawnAsArrived.reduce((a, t) => a + t.getError, 0)} times, ` +
        `with ${drawnAsArrived.reduce((a, t) => a + t.made, 0)} textures or buffers made; ${asking.length} asked otherwise ` +
        `(${asking.slice(0, 3).map((t) => `${t.getError} for ${t.made}`).join(', ')}); in animation frames ${lat.frameGetErrors} times`);
  // A streaming step that uploaded nothing (no brick, and no tables rebuilt
  // for what changed) has nothing to wait for: a GL error query there waits
  // for the GPU process's composition of the page (asked there, a preview's
  // errors cost a median 5.5 ms, up to 23 ms, in the animation frame after
  // each input).
  const idleSteps = (z.calls || []).filter((c) => !c.preview && c.stream_ms > 0 && !c.shown && c.uploaded_now === 0 &&
    !c.tables_rebuilt);
  const waited = idleSteps.filter((c) => c.error_queries > 0);
  check('latency: streaming steps that uploaded nothing asked GL for no errors',
        idleSteps.length >= 5 && waited.length === 0,
        `${idleSteps.length} such steps, ${waited.length} asked (${waited.slice(0, 3).map((c) => `${c.error_queries} queries in ${c.ms.toFixed(1)} ms`).join(', ')})`);
  // Bricks that arrived (or the new view's levels) change the ray caster's
  // empty-space blocks: the streaming step that changed them rebuilds them,
  // so that no preview answering input pays for it (3-5 ms each in 2-3 of
  // 53 previews when a step of their own after the streaming did).
  const rebuilt = during.filter((c) => c.tables_rebuilt);
  const previewsRebuilding = rebuilt.filter((c) => c.preview);
  check('latency: no preview answering input rebuilt the ray caster\'s tables for bricks that changed (the streaming steps did)',
        previews.n > 0 && rebuilt.length > 0 && previewsRebuilding.length === 0,
        `${rebuilt.length} calls rebuilt them (${rebuilt.filter((c) => c.stream_ms > 0).length} streaming steps), ` +
        `${previewsRebuilding.length} previews (${previewsRebuilding.slice(0, 3).map((c) => `${c.tables_ms.toFixed(1)} ms`).join(', ')})`);
  check('latency: the drag and the wheel turns were handled while the store refined',
        latencies.pointermove.length >= 5 && latencies.wheel.length >= WHEELS / 2 && duringRefinement >= all.n / 2 && unanswered === 0,
        `${all.n} events answered (${duringRefinement} while refining), ${unanswered} without a frame after them`);
  // Issue 31's target, worst <= 2 frame budgets (24 ms), is reported, not
  // asserted: a speed target is shown by measurement, and this machine's
  // load decides the worst case (at a load of 19 on 2 cores a preview's own
  // code, with no GL call in it, took up to 199 ms now and then). What is
  // asserted is that no event waits for a stall: 250 ms (5x the quiet
  // machine's worst), scaled by the overload past 1.5 runnable threads per
  // core; one whole ray march per store frame answered input after 0.8-4.4 s.
  const load = os.loadavg()[0];
  const cores = os.cpus().length;
  const overload = Math.max(1, load / (1.5 * cores));
  console.log(`latency: target worst <= ${2 * BUDGET_MS} ms (2 frame budgets): ${all.worst <= 2 * BUDGET_MS ? 'met' : 'NOT met'} ` +
              `(worst ${all.worst.toFixed(1)} ms, median ${all.median.toFixed(1)} ms; load average ${load.toFixed(1)} on ${cores} cores)`);
  const guard = 250 * overload;
  check(`latency: no input waits for a stall while the store refines: worst input-to-frame time <= ${guard.toFixed(0)} ms ` +
        `(250 ms times the overload, load ${load.toFixed(1)} on ${cores} cores)`,
        all.n > 0 && all.worst <= guard, text(all));
  // The frame that answers input draws the preview and nothing else: the
  // new view's selection, requests, reads, uploads and page table come in
  // the steps after it (they cost 0.4-53 ms a step here, the preview's
  // tables rebuilt with them up to 22 ms).
  const busy = during.filter((c) => c.preview && (c.update_ms > 0 || c.upload_wait_ms > 0 || c.uploaded > 0));
  check('latency: every preview that answered input did no streaming (no update, no upload, no wait for one)',
        previews.n > 0 && busy.length === 0,
        `${previews.n} previews, ${busy.length} with streaming work (${busy.slice(0, 3).map((c) => `update ${c.update_ms.toFixed(1)} ms, ${c.uploaded} uploaded`).join('; ')})`);
  // Refined, the frame drawn in strips is the whole frame's, pixel for pixel.
  await page.waitForFunction(() => window.tessera.zarr().completeMs !== null, null, { timeout: 60000 });
  await page.evaluate(() => window.tessera.render());
  const strips = await snapshot(page);
  const whole = await page.evaluate(async () => {
    window.tessera.setProgressive(false);
    const ms = await window.tessera.render();
    window.tessera.setProgressive(true);
    return ms;
  });
  const wholePixels = await snapshot(page);
  // The drag's last answer (drawn as the move arrived, or by the animation
  // frame: the same tessera_zarr_frame call) is an image of the view the
  // refined frame shows (the wheel turns zoom in and out again): nearer to
  // it than the first view's image.
  const shot = lat.capture;
  const previewDb = shot ? psnrOf(shot.pixels, strips.pixels) : NaN;
  const firstDb = psnrOf(before.pixels, strips.pixels);
  // Its pixels' FNV-1a hash: the same for both ways of answering (?rawinput=0
  // and 1) when the preview's size is the same.
  const hash = shot ? shot.pixels.reduce((h, v) => Math.imul(h ^ v, 16777619) >>> 0, 2166136261).toString(16) : '';
  console.log(`latency: the drag's last answer (${shot ? (shot.raw ? 'drawn as the move arrived' : 'drawn by an animation frame') : 'not kept'}, ` +
              `pixels hash ${hash}) against the refined frame of its view: PSNR ${previewDb.toFixed(2)} dB (the first view's image: ${firstDb.toFixed(2)} dB)`);
  check('latency: the drag\'s last answer shows the view that the refined frame shows (PSNR at least 3 dB above the first view\'s image)',
        shot && shot.pixels.length === strips.pixels.length && previewDb >= firstDb + 3,
        `${previewDb.toFixed(1)} dB against ${firstDb.toFixed(1)} dB`);
  const calls = (await page.evaluate(() => window.tessera.zarr())).calls || [];
  const last = calls[calls.length - 1];
  const differing = differingPixels(strips.pixels, wholePixels.pixels, 0);
  check('latency: refined, the frame drawn in strips equals the whole frame (every pixel)',
        differing === 0 && last && !last.pending && strips.lit > 0.05,
        `${differing} pixels differ; whole frame ${whole.toFixed(0)} ms; ${(100 * strips.lit).toFixed(0)} % lit`);
  await new Promise((r) => setTimeout(r, 2200));  // requests still delayed
  const errors = logs.filter((l) => (l.startsWith('pageerror') || l.startsWith('error')) && !/status of 404/.test(l));
  check('latency: no script errors', errors.length === 0, errors.join(' | '));
  await page.close();
}
