// The page around the WebAssembly viewer core (web/src/WebViewer.cpp): input
// events, the transfer-function editor canvas, file opening (read here,
// never uploaded: the bytes go to the same io readers as the CLI's, whose
// gzip/zlib the page's pako inflates) and error messages. window.tessera
// exposes the same operations to tests.
'use strict';

(function () {
  const params = new URLSearchParams(location.search);
  const forceWebgl1 = params.get('webgl') === '1';
  const size = Math.max(16, Math.min(2048, parseInt(params.get('size') || '512', 10) || 512));
  const defaultVolume = params.get('volume') || 'gen:shepp-logan:96';

  const $ = (id) => document.getElementById(id);
  const canvas = $('canvas');
  canvas.width = size;
  canvas.height = size;

  let M = null;     // the emscripten module
  let api = null;   // cwrapped functions
  let state = {};   // last tessera_state_json
  let tf = null;    // parsed TF JSON
  let needsRender = true;
  let frames = 0;
  let renderWaiters = [];

  function showError(message) {
    const e = $('error');
    e.textContent = message;
    e.hidden = false;
  }
  function clearError() {
    $('error').hidden = true;
    $('error').textContent = '';
  }

  function wrap(M) {
    const c = (name, ret, args) => M.cwrap(name, ret, args);
    return {
      init: c('tessera_init', 'number', ['number']),
      lastError: c('tessera_last_error', 'string', []),
      loadGenerated: c('tessera_load_generated', 'number', ['string']),
      addFile: c('tessera_add_file', null, ['string', 'number', 'number']),
      loadFiles: c('tessera_load_files', 'number', []),
      clearFiles: c('tessera_clear_files', null, []),
      render: c('tessera_render', 'number', ['number', 'number']),
      pointerDown: c('tessera_pointer_down', null, ['number', 'number', 'number', 'number']),
      pointerMove: c('tessera_pointer_move', null, ['number', 'number', 'number']),
      pointerUp: c('tessera_pointer_up', null, ['number']),
      wheel: c('tessera_wheel', null, ['number']),
      interacting: c('tessera_interacting', 'number', []),
      setCamera: c('tessera_set_camera', 'number', ['number', 'number', 'number']),
      tfJson: c('tessera_tf_json', 'string', []),
      tfSetJson: c('tessera_tf_set_json', 'number', ['string']),
      tfPreset: c('tessera_tf_preset', 'number', ['string']),
      tfDown: c('tessera_tf_pointer_down', null, ['number', 'number', 'number', 'number', 'number']),
      tfMove: c('tessera_tf_pointer_move', null, ['number', 'number']),
      tfUp: c('tessera_tf_pointer_up', null, ['number', 'number']),
      tfRemoveSelected: c('tessera_tf_remove_selected', 'number', []),
      tfSetSelectedColor: c('tessera_tf_set_selected_color', null, ['number', 'number', 'number']),
      setWindow: c('tessera_set_window', 'number', ['number', 'number']),
      resetWindow: c('tessera_reset_window', null, []),
      setMode: c('tessera_set_mode', null, ['number']),
      setStep: c('tessera_set_step', 'number', ['number']),
      setOpacityScale: c('tessera_set_opacity_scale', null, ['number']),
      setShading: c('tessera_set_shading', null, ['number']),
      setOverlays: c('tessera_set_overlays', null, ['number', 'number']),
      setQuality: c('tessera_set_quality', null, ['number']),
      setTechnique: c('tessera_set_technique', 'number', ['string']),
      stateJson: c('tessera_state_json', 'string', ['number']),
      readPixels: c('tessera_read_pixels', 'number', ['number', 'number']),
    };
  }

  function refreshState() {
    state = JSON.parse(api.stateJson($('logHist').checked ? 1 : 0));
    tf = JSON.parse(api.tfJson());
    return state;
  }

  function requestRender() {
    needsRender = true;
    return new Promise((resolve) => renderWaiters.push(resolve));
  }

  function renderNow() {
    const ms = api.render(canvas.width, canvas.height);
    if (ms < 0) showError(api.lastError());
    frames++;
    refreshState();
    updateStatus();
    updateOrientationLabels();
    return ms;
  }

  function loop() {
    if (needsRender && api) {
      needsRender = false;
      const ms = renderNow();
      const waiters = renderWaiters;
      renderWaiters = [];
      waiters.forEach((w) => w(ms));
    }
    requestAnimationFrame(loop);
  }

  // Patient directions at the view's edges; blank when the file has no orientation.
  function updateOrientationLabels() {
    const l = state.orientation_labels || {};
    for (const edge of ['left', 'right', 'top', 'bottom']) $(`orient-${edge}`).textContent = l[edge] || '';
  }

  function updateStatus() {
    const s = state;
    if (!s.webgl) return;
    const api = `WebGL ${s.webgl} (${s.api})`;
    const vol = s.has_volume ? s.description : 'no volume';
    $('status').textContent = `${vol} · ${api} · ${s.render_size[0]}×${s.render_size[1]} in ${s.frame_ms.toFixed(0)} ms`;
  }

  // ---------------------------------------------------------------- files

  // Reads files picked or dropped together (a header and its data: .nhdr +
  // .raw, .mhd + .raw/.zraw, .hdr + .img, .json sidecar + .raw; or one
  // self-contained file); the reader picks the one that names the others.
  // On failure shows why and keeps the current volume.
  async function openFiles(fileList) {
    const files = Array.from(fileList);
    if (files.length === 0) return false;
    const contents = await Promise.all(files.map(async (f) => new Uint8Array(await f.arrayBuffer())));
    for (let i = 0; i < files.length; i++) {
      const bytes = contents[i];
      const p = M._malloc(Math.max(1, bytes.length));
      if (!p) {
        showError(`${files[i].name}: cannot allocate ${bytes.length} bytes for the file; the previous volume stays`);
        api.clearFiles();  // drops the files handed over so far
        return false;
      }
      M.HEAPU8.set(bytes, p);
      api.addFile(files[i].name, p, bytes.length);  // owned by the module from here on
    }
    if (!api.loadFiles()) {
      showError(`${api.lastError()} — the previous volume stays`);
      return false;
    }
    clearError();
    volumeChanged();
    await requestRender();
    return true;
  }

  function volumeChanged() {
    refreshState();
    syncWindowControls();
    drawTf();
  }

  // ---------------------------------------------------------------- window/level

  function syncWindowControls() {
    if (!state.has_volume) return;
    const [lo, hi] = state.range;
    const [wmin, wmax] = state.window;
    const span = Math.max(hi - lo, 1e-12);
    const w = $('winWidth'), l = $('winLevel');
    w.min = span / 1000; w.max = span; w.step = span / 1000;
    l.min = lo; l.max = hi; l.step = span / 1000;
    w.value = wmax - wmin;
    l.value = 0.5 * (wmin + wmax);
  }

  function applyWindow() {
    const w = parseFloat($('winWidth').value), l = parseFloat($('winLevel').value);
    if (!api.setWindow(l - 0.5 * w, l + 0.5 * w)) showError(api.lastError());
    refreshState();
    drawTf();
    requestRender();
  }

  // ---------------------------------------------------------------- TF editor

  const tfCanvas = $('tf');
  const STRIP = 30, GAP = 8, PAD = 10, POINT = 7;
  const HIT_PX = 18;  // finger-sized

  function tfGeometry() {
    const dpr = window.devicePixelRatio || 1;
    const w = tfCanvas.clientWidth, h = tfCanvas.clientHeight;
    if (tfCanvas.width !== Math.round(w * dpr) || tfCanvas.height !== Math.round(h * dpr)) {
      tfCanvas.width = Math.round(w * dpr);
      tfCanvas.height = Math.round(h * dpr);
    }
    const plotW = w - 2 * PAD;
    const areaH = h - STRIP - GAP - 2 * PAD;
    return { dpr, w, h, plotW, areaH, stripY: PAD + areaH + GAP };
  }

  const toPx = (g, x, a) => [PAD + x * g.plotW, PAD + (1 - a) * g.areaH];
  const rgbCss = (c) => `rgb(${c.map((v) => Math.round(v * 255)).join(',')})`;

  function tfColorAt(x) {
    const c = tf.color;
    if (!c.length) return [0, 0, 0];
    if (x <= c[0].x) return c[0].rgb;
    for (let i = 1; i < c.length; i++) {
      if (x <= c[i].x) {
        const t = (x - c[i - 1].x) / Math.max(c[i].x - c[i - 1].x, 1e-12);
        return c[i].rgb.map((v, k) => c[i - 1].rgb[k] + t * (v - c[i - 1].rgb[k]));
      }
    }
    return c[c.length - 1].rgb;
  }

  function drawTf() {
    if (!tf) return;
    const g = tfGeometry();
    const ctx = tfCanvas.getContext('2d');
    ctx.setTransform(g.dpr, 0, 0, g.dpr, 0, 0);
    ctx.clearRect(0, 0, g.w, g.h);
    // Histogram of the volume over its window.
    const hist = state.histogram || [];
    ctx.fillStyle = '#3a3f4a';
    const bw = g.plotW / Math.max(hist.length, 1);
    hist.forEach((v, i) => {
      const bh = v * g.areaH;
      ctx.fillRect(PAD + i * bw, PAD + g.areaH - bh, Math.max(bw, 1), bh);
    });
    ctx.strokeStyle = '#555';
    ctx.strokeRect(PAD, PAD, g.plotW, g.areaH);
    // Opacity curve, filled with the TF colours.
    const op = tf.opacity;
    if (op.length) {
      const grad = ctx.createLinearGradient(PAD, 0, PAD + g.plotW, 0);
      for (let i = 0; i <= 16; i++) grad.addColorStop(i / 16, rgbCss(tfColorAt(i / 16)));
      ctx.beginPath();
      ctx.moveTo(...toPx(g, 0, 0));
      ctx.lineTo(...toPx(g, 0, op[0].alpha));
      op.forEach((p) => ctx.lineTo(...toPx(g, p.x, p.alpha)));
      ctx.lineTo(...toPx(g, 1, op[op.length - 1].alpha));
      ctx.lineTo(...toPx(g, 1, 0));
      ctx.closePath();
      ctx.globalAlpha = 0.35;
      ctx.fillStyle = grad;
      ctx.fill();
      ctx.globalAlpha = 1;
      ctx.beginPath();
      ctx.moveTo(...toPx(g, 0, op[0].alpha));
      op.forEach((p) => ctx.lineTo(...toPx(g, p.x, p.alpha)));
      ctx.lineTo(...toPx(g, 1, op[op.length - 1].alpha));
      ctx.strokeStyle = '#f0f0f0';
      ctx.lineWidth = 1.5;
      ctx.stroke();
    }
    const sel = state.selection || { channel: 0, index: -1 };
    op.forEach((p, i) => {
      const [x, y] = toPx(g, p.x, p.alpha);
      ctx.beginPath();
      ctx.arc(x, y, POINT, 0, 2 * Math.PI);
      ctx.fillStyle = rgbCss(tfColorAt(p.x));
      ctx.fill();
      ctx.lineWidth = sel.channel === 0 && sel.index === i ? 3 : 1.5;
      ctx.strokeStyle = sel.channel === 0 && sel.index === i ? '#ffd54a' : '#fff';
      ctx.stroke();
    });
    // Colour strip with its points.
    for (let i = 0; i < g.plotW; i++) {
      ctx.fillStyle = rgbCss(tfColorAt(i / g.plotW));
      ctx.fillRect(PAD + i, g.stripY, 1, STRIP);
    }
    tf.color.forEach((c, i) => {
      const x = PAD + c.x * g.plotW;
      ctx.beginPath();
      ctx.moveTo(x, g.stripY + STRIP - 12);
      ctx.lineTo(x - 7, g.stripY + STRIP);
      ctx.lineTo(x + 7, g.stripY + STRIP);
      ctx.closePath();
      ctx.fillStyle = rgbCss(c.rgb);
      ctx.fill();
      ctx.lineWidth = sel.channel === 1 && sel.index === i ? 3 : 1.5;
      ctx.strokeStyle = sel.channel === 1 && sel.index === i ? '#ffd54a' : '#fff';
      ctx.stroke();
    });
    $('deletePoint').disabled = sel.index < 0;
    $('pointColor').disabled = !(sel.channel === 1 && sel.index >= 0);
    if (sel.channel === 1 && sel.index >= 0 && tf.color[sel.index]) {
      $('pointColor').value = '#' + tf.color[sel.index].rgb
        .map((v) => Math.round(v * 255).toString(16).padStart(2, '0')).join('');
    }
  }

  // Editor units of a pointer event: x in [0,1], y = opacity (may leave [0,1]).
  function tfUnits(e) {
    const g = tfGeometry();
    const r = tfCanvas.getBoundingClientRect();
    const px = e.clientX - r.left, py = e.clientY - r.top;
    return { g, px, py, x: (px - PAD) / g.plotW, y: 1 - (py - PAD) / g.areaH };
  }

  let tfActive = null;
  tfCanvas.addEventListener('pointerdown', (e) => {
    if (!api) return;
    const u = tfUnits(e);
    const channel = u.py >= u.g.stripY - GAP / 2 ? 1 : 0;
    api.tfDown(channel, Math.min(1, Math.max(0, u.x)), Math.min(1, Math.max(0, u.y)),
               HIT_PX / u.g.plotW, HIT_PX / u.g.areaH);
    tfActive = e.pointerId;
    tfCanvas.setPointerCapture(e.pointerId);
    tfEdited();
    e.preventDefault();
  });
  tfCanvas.addEventListener('pointermove', (e) => {
    if (tfActive !== e.pointerId) return;
    const u = tfUnits(e);
    api.tfMove(u.x, u.y);
    tfEdited();
  });
  const tfEnd = (e) => {
    if (tfActive !== e.pointerId) return;
    const u = tfUnits(e);
    api.tfUp(u.x, u.y);
    tfActive = null;
    tfEdited();
  };
  tfCanvas.addEventListener('pointerup', tfEnd);
  tfCanvas.addEventListener('pointercancel', tfEnd);

  function tfEdited() {
    refreshState();
    drawTf();
    requestRender();
  }

  // ---------------------------------------------------------------- view input

  function canvasPos(e) {
    const r = canvas.getBoundingClientRect();
    return [(e.clientX - r.left) * canvas.width / r.width, (e.clientY - r.top) * canvas.height / r.height];
  }
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
  canvas.addEventListener('pointerdown', (e) => {
    if (!api) return;
    const [x, y] = canvasPos(e);
    api.pointerDown(e.pointerId, x, y, e.button === 2 || e.shiftKey ? 1 : 0);
    canvas.setPointerCapture(e.pointerId);
    e.preventDefault();
  });
  canvas.addEventListener('pointermove', (e) => {
    if (!api) return;
    const [x, y] = canvasPos(e);
    api.pointerMove(e.pointerId, x, y);
    if (api.interacting()) requestRender();
  });
  const viewEnd = (e) => {
    if (!api) return;
    api.pointerUp(e.pointerId);
    requestRender();  // full quality once released
  };
  canvas.addEventListener('pointerup', viewEnd);
  canvas.addEventListener('pointercancel', viewEnd);
  canvas.addEventListener('wheel', (e) => {
    if (!api) return;
    api.wheel(Math.sign(e.deltaY));
    requestRender();
    e.preventDefault();
  }, { passive: false });

  // Drag and drop of files onto the view.
  const view = $('view');
  ['dragenter', 'dragover'].forEach((t) => view.addEventListener(t, (e) => {
    e.preventDefault();
    view.classList.add('dragover');
  }));
  ['dragleave', 'drop'].forEach((t) => view.addEventListener(t, () => view.classList.remove('dragover')));
  view.addEventListener('drop', (e) => {
    e.preventDefault();
    if (e.dataTransfer && e.dataTransfer.files.length) openFiles(e.dataTransfer.files);
  });

  // ---------------------------------------------------------------- controls

  function bindControls() {
    $('file').addEventListener('change', async (e) => {
      const files = Array.from(e.target.files);
      e.target.value = '';
      if (files.length) await openFiles(files);
    });
    ['grey', 'mr-default', 'ct-bone', 'ct-muscle', 'bench'].forEach((n) => {
      const o = document.createElement('option');
      o.value = n;
      o.textContent = n;
      $('preset').appendChild(o);
    });
    $('preset').value = 'mr-default';
    $('preset').addEventListener('change', (e) => {
      if (!api.tfPreset(e.target.value)) showError(api.lastError());
      tfEdited();
    });
    $('logHist').addEventListener('change', () => { refreshState(); drawTf(); });
    $('deletePoint').addEventListener('click', () => { api.tfRemoveSelected(); tfEdited(); });
    $('pointColor').addEventListener('input', (e) => {
      const v = e.target.value;
      api.tfSetSelectedColor(...[1, 3, 5].map((i) => parseInt(v.substr(i, 2), 16) / 255));
      tfEdited();
    });
    $('saveTf').addEventListener('click', () => {
      const a = document.createElement('a');
      a.href = URL.createObjectURL(new Blob([api.tfJson()], { type: 'application/json' }));
      a.download = 'transfer-function.json';
      a.click();
      URL.revokeObjectURL(a.href);
    });
    $('loadTf').addEventListener('change', async (e) => {
      const f = e.target.files[0];
      e.target.value = '';
      if (!f) return;
      if (!api.tfSetJson(await f.text())) showError(`${f.name}: ${api.lastError()}`);
      else clearError();
      tfEdited();
    });
    $('winWidth').addEventListener('input', applyWindow);
    $('winLevel').addEventListener('input', applyWindow);
    $('resetWindow').addEventListener('click', () => {
      api.resetWindow();
      refreshState();
      syncWindowControls();
      drawTf();
      requestRender();
    });
    $('mode').addEventListener('change', (e) => { api.setMode(+e.target.value); requestRender(); });
    $('quality').addEventListener('change', (e) => { api.setQuality(+e.target.value); requestRender(); });
    $('technique').addEventListener('change', (e) => {
      if (!api.setTechnique(e.target.value)) showError(api.lastError());
      requestRender();
    });
    $('step').addEventListener('input', (e) => {
      if (!api.setStep(+e.target.value)) showError(api.lastError());
      requestRender();
    });
    $('opacity').addEventListener('input', (e) => { api.setOpacityScale(+e.target.value); requestRender(); });
    $('shade').addEventListener('change', (e) => { api.setShading(e.target.checked ? 1 : 0); requestRender(); });
    const overlays = () => { api.setOverlays($('box').checked ? 1 : 0, $('axes').checked ? 1 : 0); requestRender(); };
    $('box').addEventListener('change', overlays);
    $('axes').addEventListener('change', overlays);
    $('resetView').addEventListener('click', () => { api.setCamera(0, 0, 1); requestRender(); });
    window.addEventListener('resize', drawTf);
  }

  // ---------------------------------------------------------------- start

  const ready = (async () => {
    M = await createTesseraModule({ canvas });
    api = wrap(M);
    let ok = forceWebgl1 ? 0 : api.init(2);
    if (!ok) ok = api.init(1);  // the ES 2.0 path
    if (!ok) {
      showError(api.lastError());
      throw new Error(api.lastError());
    }
    bindControls();
    refreshState();
    state.techniques.forEach((n) => {
      const o = document.createElement('option');
      o.value = n;
      o.textContent = n;
      $('technique').appendChild(o);
    });
    if (!api.loadGenerated(defaultVolume)) showError(api.lastError());
    volumeChanged();
    requestAnimationFrame(loop);
    await requestRender();
    return state;
  })();

  // For tests and the console.
  window.tessera = {
    ready,
    state: () => refreshState(),
    tf: () => JSON.parse(api.tfJson()),
    frames: () => frames,
    render: () => requestRender(),
    openFiles,
    openFile: (file) => openFiles([file]),
    setCamera: (az, el, zoom) => { api.setCamera(az, el, zoom); return requestRender(); },
    setTfJson: (json) => { const ok = api.tfSetJson(json); tfEdited(); return ok; },
    error: () => ($('error').hidden ? '' : $('error').textContent),
    // The canvas's RGBA pixels, top row first.
    pixels: () => {
      const p = api.readPixels(canvas.width, canvas.height);
      return M.HEAPU8.slice(p, p + canvas.width * canvas.height * 4);
    },
    // Median frame time over n frames turning 10 degrees each (a frame ends
    // with a 1-pixel read-back, since glFinish does not wait in browsers).
    benchmark: (n) => {
      const times = [];
      for (let i = 0; i < n; i++) {
        api.setCamera(i * 10, 0, 1);
        times.push(renderNow());
      }
      times.sort((a, b) => a - b);
      return { median: times[Math.floor(times.length / 2)], min: times[0], max: times[times.length - 1], times };
    },
  };
})();
