// Tessera in a web page: an ES module around the WebAssembly viewer core
// (tessera-core.js + tessera-core.wasm, built by scripts/web.sh). Each
// TesseraViewer owns its own module instance and WebGL context on the
// canvas it is given, so several viewers (or pages) never share state.
// The API is documented in docs/web-api.md.
//
//   import { TesseraViewer } from './tessera.js';
//   const viewer = await TesseraViewer.create(canvas);
//   await viewer.openUrl('head.nii.gz');
//   viewer.setTransferFunction('mr-default');
//   viewer.render();
import createTesseraModule from './tessera-core.js';

// pako inflates gzip/zlib inside the io readers (frontends/web/src/InflaterPako.js);
// loaded once per page, next to this module.
const PAKO_URL = new URL('./pako_inflate.min.js', import.meta.url).href;
let pakoLoading = null;
function loadPako() {
  if (globalThis.pako || typeof document === 'undefined') return Promise.resolve();
  if (!pakoLoading) {
    pakoLoading = new Promise((resolve, reject) => {
      const s = document.createElement('script');
      s.src = PAKO_URL;
      s.onload = resolve;
      s.onerror = () => reject(new Error(`${PAKO_URL}: cannot load the gzip inflater`));
      document.head.append(s);
    });
  }
  return pakoLoading;
}

// Makes the canvas's WebGL `version` context a low-latency one before the
// module adopts it (the module asks for the same context, and a canvas
// hands out the one it has; this emscripten's context attributes cannot ask
// for `desynchronized`). The other attributes are the module's
// (src/gpu/GlContextWebGL.cpp). Chromium presents a desynchronized canvas's
// frames as they are drawn, not with the page's next commit, and while a
// pointer pressed on the canvas is down it dispatches that pointer's moves
// as they arrive, not at the next animation frame. Not the default: the
// page answers a store's drag in pointerrawupdate, which Chromium sends as
// moves arrive anyway, and in alternating runs through the X server
// (bench/web_latency.py) a desynchronized context kept every input within
// two frame budgets no more often (5 of 9 runs either way) and its worst
// runs were worse (46 ms against 28). Browsers without it ignore it.
function lowLatencyContext(canvas, version) {
  canvas.getContext(version === 2 ? 'webgl2' : 'webgl', {
    alpha: false, depth: false, stencil: false, antialias: false, preserveDrawingBuffer: true,
    desynchronized: true,
  });
}

// The module's WebGL context is made on a canvas named by a CSS selector:
// a canvas without an id gets one.
let canvasCount = 0;
function selectorOf(canvas) {
  if (!canvas.id) canvas.id = `tessera-canvas-${++canvasCount}`;
  return `#${CSS.escape(canvas.id)}`;
}

function megabytes(n) { return (n / 1048576).toFixed(1); }

// GET `url` with progress (onProgress(received, total)); throws an Error
// whose message names the URL and what went wrong.
async function fetchBytes(url, onProgress) {
  let response;
  try {
    response = await fetch(url);
  } catch (e) {
    throw new Error(`${url}: cannot fetch it (${e.message}): the server is unreachable, ` +
                    'or it does not let this page read the file (CORS)');
  }
  if (!response.ok) throw new Error(`${url}: HTTP ${response.status} ${response.statusText}`.trim());
  const total = parseInt(response.headers.get('Content-Length') || '0', 10) || 0;
  if (!response.body) {
    const all = new Uint8Array(await response.arrayBuffer());
    onProgress(all.length, total);
    return all;
  }
  const reader = response.body.getReader();
  const chunks = [];
  let received = 0;
  for (;;) {
    const { done, value } = await reader.read();
    if (done) break;
    chunks.push(value);
    received += value.length;
    onProgress(received, total);
  }
  const all = new Uint8Array(received);
  let at = 0;
  for (const c of chunks) { all.set(c, at); at += c.length; }
  return all;
}

export class TesseraViewer {
  // Loads a module instance and makes the WebGL context on `canvas`.
  // profile: 'auto' (WebGL 2, else WebGL 1), 'webgl2' or 'webgl1'.
  // Rejects with an Error saying why when the browser offers no WebGL.
  // lowLatency (default false): the context is a low-latency
  // ("desynchronized") one, see lowLatencyContext.
  static async create(canvas, { profile = 'auto', lowLatency = false } = {}) {
    if (!['auto', 'webgl2', 'webgl1'].includes(profile)) {
      throw new Error(`TesseraViewer.create: profile "${profile}" is not auto, webgl2 or webgl1`);
    }
    const [module] = await Promise.all([createTesseraModule({ canvas }), loadPako()]);
    const viewer = new TesseraViewer(module, canvas);
    const selector = selectorOf(canvas);
    const init = (version) => {
      if (lowLatency) lowLatencyContext(canvas, version);
      return viewer.#c.init(selector, version);
    };
    let ok = profile === 'webgl1' ? 0 : init(2);
    if (!ok && profile !== 'webgl2') ok = init(1);  // the ES 2.0 path
    if (!ok) throw new Error(viewer.#c.lastError());
    viewer.#watchContext();
    return viewer;
  }

  #module;
  #canvas;
  #c;  // the C API (frontends/web/src/WebExports*.cpp), cwrapped
  #listeners = new Map();
  #lost = false;
  #contextEvents = [];  // [type, handler] on the canvas

  constructor(module, canvas) {
    this.#module = module;
    this.#canvas = canvas;
    const c = (name, ret, args) => module.cwrap(name, ret, args);
    this.#c = {
      init: c('tessera_init', 'number', ['string', 'number']),
      dispose: c('tessera_dispose', null, []),
      contextRestored: c('tessera_context_restored', 'number', []),
      contextLost: c('tessera_context_lost', 'number', []),
      lastError: c('tessera_last_error', 'string', []),
      loadGenerated: c('tessera_load_generated', 'number', ['string']),
      addFile: c('tessera_add_file', null, ['string', 'number', 'number']),
      clearFiles: c('tessera_clear_files', null, []),
      loadFiles: c('tessera_load_files', 'number', []),
      render: c('tessera_render', 'number', ['number', 'number']),
      setCamera: c('tessera_set_camera', 'number', ['number', 'number', 'number']),
      setOverlays: c('tessera_set_overlays', null, ['number', 'number']),
      tfJson: c('tessera_tf_json', 'string', []),
      tfSetJson: c('tessera_tf_set_json', 'number', ['string']),
      tfPreset: c('tessera_tf_preset', 'number', ['string']),
      stateJson: c('tessera_state_json', 'string', ['number']),
      sessionState: c('tessera_session_state', 'string', []),
      sessionRestore: c('tessera_session_restore', 'number', ['string']),
      readPixels: c('tessera_read_pixels', 'number', ['number', 'number']),
      timeJson: c('tessera_time_json', 'string', []),
      timeShow: c('tessera_time_show', 'number', ['number']),
      playback: c('tessera_playback', 'number', ['number', 'number', 'number']),
      playbackStep: c('tessera_playback_step', 'number', ['number']),
    };
  }

  // The emscripten module, for the page's own panels (frontends/web/slices.js,
  // grid.js, zarr-url.js call the rest of the C API through it).
  get module() { return this.#module; }
  get canvas() { return this.#canvas; }

  // on('loaded', (state) => …) after a volume is loaded; on('frame',
  // ({ms}) => …) after each render(); on('error', (error) => …) when a call
  // fails (it also throws); on('contextlost', () => …) when the browser
  // takes the WebGL context away, on('contextrestored', ({error, state}) =>
  // …) once the viewer is back on it (error: what could not be brought
  // back, else ''). Returns a function that removes the listener.
  on(event, callback) {
    const events = ['loaded', 'frame', 'error', 'contextlost', 'contextrestored'];
    if (!events.includes(event)) {
      throw new Error(`TesseraViewer.on: no event "${event}" (${events.join(', ')})`);
    }
    if (!this.#listeners.has(event)) this.#listeners.set(event, new Set());
    this.#listeners.get(event).add(callback);
    return () => this.#listeners.get(event).delete(callback);
  }

  #emit(event, value) {
    for (const cb of this.#listeners.get(event) || []) cb(value);
  }

  // Throws (and reports) `message`.
  #fail(message) {
    const e = new Error(message);
    this.#emit('error', e);
    throw e;
  }

  #check(ok) {
    if (!ok) this.#fail(this.#c.lastError());
  }

  // A lost WebGL context (a phone sends the page to the background, the GPU
  // resets): render() draws nothing until the browser restores it; then the
  // session is made again on it with the same volume and state. The loss's
  // preventDefault is what lets the browser restore the context at all.
  #watchContext() {
    const lost = (e) => {
      e.preventDefault();
      this.#lost = true;
      this.#emit('contextlost', {});
    };
    const restored = () => {
      this.#lost = false;
      const error = this.#c.contextRestored() ? '' : this.#c.lastError();
      this.#emit('contextrestored', { error, state: this.state() });
    };
    this.#contextEvents = [['webglcontextlost', lost], ['webglcontextrestored', restored]];
    for (const [type, handler] of this.#contextEvents) this.#canvas.addEventListener(type, handler);
  }

  // True between the loss of the WebGL context and its restoration: from
  // the moment the browser takes it away (a task before its
  // webglcontextlost event, when a frame would only fail with an error).
  get contextLost() { return this.#lost || this.#c.contextLost() === 1; }

  // The viewer's state (volume, dims, geometry, camera, sampling, …) as the
  // C API's tessera_state_json reports it.
  state({ logHistogram = false } = {}) {
    return JSON.parse(this.#c.stateJson(logHistogram ? 1 : 0));
  }

  // The session's state to save (settings, camera, transfer function,
  // window, crosshair, region, grid): versioned JSON that restoreSession,
  // `tessera render --state` and `tessera view --state` take.
  sessionState() {
    return JSON.parse(this.#c.sessionState());
  }

  // Restores a saved session state (an object or its JSON text) on the
  // volume loaded now. Throws with what is wrong in it.
  restoreSession(state) {
    this.#check(this.#c.sessionRestore(typeof state === 'string' ? state : JSON.stringify(state)));
  }

  // A procedural volume of `tessera render` ("gen:shepp-logan:96").
  loadGenerated(spec) {
    this.#check(this.#c.loadGenerated(spec));
    this.#emit('loaded', this.state());
  }

  // Files picked or dropped together (File objects, or {name, bytes}
  // entries): a header and its data, or one self-contained file; read by
  // the same io readers as the CLI's. Throws with the reader's message (the
  // previous volume stays).
  async openFiles(files, { explain = (message) => message } = {}) {
    const list = Array.from(files);
    if (list.length === 0) this.#fail('no files to open');
    const entries = await Promise.all(list.map(async (f) => (f.bytes
      ? f : { name: f.name, bytes: new Uint8Array(await f.arrayBuffer()) })));
    const M = this.#module;
    for (const { name, bytes } of entries) {
      const p = M._malloc(Math.max(1, bytes.length));
      if (!p) {
        this.#c.clearFiles();  // drops the files handed over so far
        this.#fail(explain(`${name}: cannot allocate ${bytes.length} bytes for the file`));
      }
      M.HEAPU8.set(bytes, p);
      this.#c.addFile(name, p, bytes.length);  // owned by the module from here on
    }
    if (!this.#c.loadFiles()) this.#fail(explain(this.#c.lastError()));
    const state = this.state();
    this.#emit('loaded', state);
    return state;
  }

  // A volume file at `url` (or several: a header and its data), fetched with
  // onProgress({url, received, total}) and read like picked files. Errors
  // name the URL.
  async openUrl(urls, { onProgress = () => {} } = {}) {
    const list = Array.isArray(urls) ? urls : [urls];
    const entries = [];
    for (const u of list) {
      let resolved;
      try {
        resolved = new URL(u, location.href);
      } catch {
        this.#fail(`${u}: not a valid URL`);
      }
      const name = decodeURIComponent(resolved.pathname.split('/').pop() || '') || 'volume';
      let bytes;
      try {
        bytes = await fetchBytes(resolved.href,
          (received, total) => onProgress({ url: resolved.href, received, total }));
      } catch (e) {
        this.#fail(e.message);
      }
      entries.push({ name, bytes, url: resolved.href });
    }
    return this.openFiles(entries, { explain: (message) => {
      // Name the URL of the file the reader complains about (or all of them).
      for (const e of entries) if (message.startsWith(e.name)) return `${e.url}: ${message}`;
      return `${entries.map((e) => e.url).join(', ')}: ${message}`;
    } });
  }

  // A preset's name ("mr-default", "ct-bone", …), or a transfer function
  // in the CLI's JSON format (a string or an object).
  setTransferFunction(nameOrJson) {
    if (typeof nameOrJson === 'object') nameOrJson = JSON.stringify(nameOrJson);
    const json = nameOrJson.trimStart().startsWith('{');
    this.#check(json ? this.#c.tfSetJson(nameOrJson) : this.#c.tfPreset(nameOrJson));
  }

  // The transfer function in the CLI's JSON format, parsed.
  transferFunction() { return JSON.parse(this.#c.tfJson()); }

  // Degrees around the volume and above it, and the zoom (1 frames the
  // volume); a field left out keeps its value. The projection stays.
  setCamera({ azimuth, elevation, zoom } = {}) {
    const c = this.state().camera || {};
    this.#check(this.#c.setCamera(azimuth ?? c.azimuth ?? 0, elevation ?? c.elevation ?? 0, zoom ?? c.zoom ?? 1));
  }

  // The bounding box and the axes drawn with the volume (both on at first).
  setOverlays({ box = true, axes = true } = {}) {
    this.#c.setOverlays(box ? 1 : 0, axes ? 1 : 0);
  }

  // Renders a frame at the canvas's size; returns its time in ms (0, and
  // nothing drawn, while the WebGL context is lost).
  render() {
    if (this.#lost) return 0;
    const ms = this.#c.render(this.#canvas.width, this.#canvas.height);
    if (ms < 0) this.#fail(this.#c.lastError());
    this.#emit('frame', { ms });
    return ms;
  }

  // A time series (a 4-D NIfTI opened with openFiles/openUrl): {count,
  // shown, playing, fps, late, advances}; {count: 1} for a single volume.
  timeSeries() { return JSON.parse(this.#c.timeJson()); }

  // Shows time point t when it has been read (true); else asks for it,
  // reads one time point ahead and returns false (call again on a later
  // frame). Throws for t out of range.
  showTimePoint(t) {
    const r = this.#c.timeShow(t);
    if (r < 0) this.#fail(this.#c.lastError());
    return r === 1;
  }

  // Playback at `fps` time points per second: every time point in order,
  // one that is not read in time shown late, never skipped. Call
  // stepPlayback() once per animation frame and render() when the time
  // point it returns changed.
  play({ fps = 10 } = {}) { this.#check(this.#c.playback(1, fps, performance.now())); }
  pause() { this.#check(this.#c.playback(0, this.timeSeries().fps || 10, performance.now())); }
  stepPlayback(nowMs = performance.now()) {
    const shown = this.#c.playbackStep(nowMs);
    if (shown < 0) this.#fail(this.#c.lastError());
    return shown;
  }

  // The canvas's RGBA pixels, top row first.
  pixels() {
    const { width, height } = this.#canvas;
    const p = this.#c.readPixels(width, height);
    return this.#module.HEAPU8.slice(p, p + width * height * 4);
  }

  // Ends the session: the WebGL context, the volume and every GPU object go.
  dispose() {
    if (!this.#c) return;
    for (const [type, handler] of this.#contextEvents) this.#canvas.removeEventListener(type, handler);
    this.#c.dispose();
    this.#listeners.clear();
  }
}
