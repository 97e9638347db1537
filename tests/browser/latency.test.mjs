// Browser test: the page answers input within its frame budget while an
// OME-Zarr store refines (fixture.mjs serves the site and launches
// Chromium). The store's finest chunks are served late, so bricks keep
// arriving while a drag and wheel turns are sent; each input event's
// latency is the time from the event (its timeStamp, the earliest of the
// pointer moves coalesced into it) to the end of the first animation-frame
// callback after it was handled that drew on the canvas (a preview, or a
// finished frame). Whole ray marches per frame (0.6-2.5 s on SwiftShader)
// hold input up that long; frames in strips of about the budget answer it
// with a preview, and the target is two budgets. The wait for the next
// animation frame (up to 16.7 ms: Chromium dispatches moves and wheel turns
// with it) is part of every latency, so nothing else may hold the main
// thread for long: chunks are inflated in slices in idle time, and the
// worst events are explained frame by frame (explainWorst). A wheel turn
// sent through DevTools, as here, waits for one frame more before it
// reaches the page (explainTrace): its latency is at least a frame
// interval plus the answering callback, whatever the page does.
// TESSERA_LATENCY_TRACE=FILE records a Chrome trace of the input sequence
// and prints each input's way through Chromium.
import { test } from 'node:test';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { CH2, check, served, browserSuite, snapshot, differingPixels } from './fixture.mjs';

const checks = browserSuite();

// The page's frame budget (app.js: ?budget=, 12 ms by default), stated here.
const BUDGET_MS = 12;
const SIZE = 256;

test('input during a store\'s refinement: every event answered by the next frame, none held by a stall (worst vs 2 frame budgets reported)', checks(storeInputLatency));

// Runs in the page before its scripts: which animation-frame callbacks drew
// on the canvas (a draw, clear or blit into the default framebuffer), and
// when input events were stamped and handled.
function instrument() {
  const lat = { frames: [], events: [], callbacks: [] };
  window.latency = lat;
  let drew = false;
  for (const Ctx of [window.WebGL2RenderingContext, window.WebGLRenderingContext]) {
    if (!Ctx) continue;
    const p = Ctx.prototype;
    const bind = p.bindFramebuffer;
    p.bindFramebuffer = function (target, fb) {
      if (target !== this.READ_FRAMEBUFFER) this.latencyDefault = fb === null;
      return bind.call(this, target, fb);
    };
    for (const name of ['drawArrays', 'drawElements', 'clear', 'blitFramebuffer']) {
      const f = p[name];
      if (!f) continue;
      p[name] = function (...args) {
        if (this.latencyDefault !== false) drew = true;
        return f.apply(this, args);
      };
    }
  }
  const raf = window.requestAnimationFrame.bind(window);
  window.requestAnimationFrame = (cb) => raf((ts) => {
    const start = performance.now();
    drew = false;
    try {
      cb(ts);
    } finally {
      const end = performance.now();
      if (drew) lat.frames.push({ start, end });
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
    `${c.preview ? ` at ${c.preview_size.join('x')}` : ''}, ${c.uploaded || 0} bricks uploaded)`);
  const decodeTasks = (z.decodeTasks || []).map((d) => ({ start: d.t + z.t0, end: d.t + z.t0 + d.ms }));
  const overlap = (list, a, b) => list.reduce((sum, x) => sum + Math.max(0, Math.min(b, x.end) - Math.max(a, x.start)), 0);
  const rows = [];
  for (const e of lat.events) {
    if (e.type === 'pointermove' && !e.buttons) continue;
    const f = lat.frames.find((fr) => fr.start >= e.handled);
    if (!f) continue;
    const held = lat.callbacks.filter((cb) => cb.end > e.stamp && cb.start < e.handled);
    const longest = held.reduce((a, b) => (!a || b.end - b.start > a.end - a.start ? b : a), null);
    rows.push({ e, f, latency: f.end - e.stamp, longest,
      frameMs: overlap(lat.callbacks, e.stamp, e.handled), decodeMs: overlap(decodeTasks, e.stamp, e.handled) });
  }
  rows.sort((a, b) => b.latency - a.latency);
  for (const r of rows.slice(0, 5)) {
    const wait = r.e.handled - r.e.stamp;
    const held = r.longest ? `; the longest ${(r.longest.end - r.longest.start).toFixed(1)} ms: ${parts(callAt(r.longest))}` : '';
    console.log(`latency: worst ${r.e.type} ${r.latency.toFixed(1)} ms = handled after ${wait.toFixed(1)} ms ` +
                `(frame callbacks ${r.frameMs.toFixed(1)}, chunk decodes ${r.decodeMs.toFixed(1)}, ` +
                `other tasks or the wait for a frame ${Math.max(0, wait - r.frameMs - r.decodeMs).toFixed(1)}${held}); ` +
                `answered ${(r.f.start - r.e.handled).toFixed(1)} ms later by a ${(r.f.end - r.f.start).toFixed(1)} ms frame: ${parts(callAt(r.f))}`);
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
  await page.waitForFunction(() => { const z = window.tessera.zarr(); return z && z.firstImageMs !== null; }, null, { timeout: 60000 });
  const box = await page.locator('#canvas').boundingBox();
  const cdp = await context.newCDPSession(page);
  const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
  // Sent on a clock, never awaiting the page (an acknowledgement waits for
  // the page's main thread), each stamped with its time of sending.
  const sent = [];
  const send = (type, params) => sent.push(cdp.send(type, { ...params, timestamp: Date.now() / 1000 }));
  const at = async (ms) => { const due = t0 + ms; if (Date.now() < due) await new Promise((r) => setTimeout(r, due - Date.now())); };
  // TESSERA_LATENCY_TRACE=FILE: a Chrome trace of the input sequence (input,
  // latencyInfo, scheduler, cc, viz and gpu categories) written to FILE, to
  // follow an event from the browser process to the frame that answered it.
  const traceFile = process.env.TESSERA_LATENCY_TRACE || '';
  if (traceFile) {
    await cdp.send('Tracing.start', { transferMode: 'ReturnAsStream', traceConfig: { recordMode: 'recordAsMuchAsPossible',
      includedCategories: ['input', 'latencyInfo', 'benchmark', 'devtools.timeline', 'toplevel', 'gpu', 'cc', 'viz',
        'blink', 'renderer.scheduler', 'disabled-by-default-devtools.timeline.frame', 'v8.execute'] } });
  }
  const t0 = Date.now();
  send('Input.dispatchMouseEvent', { type: 'mousePressed', x: cx, y: cy, button: 'left', buttons: 1, clickCount: 1 });
  const MOVES = 40;
  for (let i = 1; i <= MOVES; i++) {
    await at(i * 70);
    send('Input.dispatchMouseEvent', { type: 'mouseMoved', x: cx + 3 * i, y: cy + (i % 5), button: 'left', buttons: 1 });
  }
  await at((MOVES + 1) * 70);
  send('Input.dispatchMouseEvent', { type: 'mouseReleased', x: cx + 3 * MOVES, y: cy, button: 'left', buttons: 0, clickCount: 1 });
  const WHEELS = 12;
  for (let i = 0; i < WHEELS; i++) {
    await at((MOVES + 4) * 70 + i * 200);
    send('Input.dispatchMouseEvent', { type: 'mouseWheel', x: cx, y: cy, deltaX: 0, deltaY: i % 2 ? 100 : -100 });
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
  const z = await page.evaluate(() => window.tessera.zarr());
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
  let unanswered = 0, duringRefinement = 0;
  for (const e of lat.events) {
    if (e.type === 'pointermove' && !e.buttons) continue;  // a move without a drag asks for no frame
    const f = lat.frames.find((fr) => fr.start >= e.handled);
    if (!f) { unanswered++; continue; }
    latencies[e.type].push(f.end - e.stamp);
    if (e.refining) duringRefinement++;
  }
  const all = stats([...latencies.pointermove, ...latencies.pointerup, ...latencies.wheel]);
  explainWorst(lat, z);
  const text = (s) => `median ${s.median.toFixed(1)} ms, 90th percentile ${s.p90.toFixed(1)} ms, worst ${s.worst.toFixed(1)} ms over ${s.n}`;
  const perType = Object.entries(latencies).map(([t, v]) => `${t}: ${text(stats(v))}`).join('; ');
  console.log(`latency: store refining at ${SIZE}x${SIZE}, budget ${BUDGET_MS} ms: all events ${text(all)}; ${perType}`);
  console.log(`latency: ${lat.frames.length} canvas frames; frame callbacks that drew took median ${stats(lat.frames.map((f) => f.end - f.start)).median.toFixed(1)} ms, ` +
              `worst ${stats(lat.frames.map((f) => f.end - f.start)).worst.toFixed(1)} ms; refined ${z.completeMs === null ? 'not yet' : `after ${z.completeMs.toFixed(0)} ms`}`);
  console.log(`latency: the store's calls while refining: ${work.n}, work median ${work.median.toFixed(1)} ms, worst ${work.worst.toFixed(1)} ms; ` +
              `previews ${previews.n}, median ${previews.median.toFixed(1)} ms, worst ${previews.worst.toFixed(1)} ms; ` +
              `streaming steps ${streaming.n}, median ${streaming.median.toFixed(1)} ms, worst ${streaming.worst.toFixed(1)} ms; ` +
              `strips ${stripCalls.n}, median ${stripCalls.median.toFixed(1)} ms, worst ${stripCalls.worst.toFixed(1)} ms`);
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
