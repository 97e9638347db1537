// The page around the WebAssembly viewer core: a TesseraViewer (tessera.js,
// the module other pages embed) for the context, volumes, frames, camera
// and transfer function, and the rest of the C API (frontends/web/src/WebExports*.cpp)
// for the page's controls; input events, the transfer-function editor
// canvas, file opening (read here, never uploaded: the bytes go to the same
// io readers as the CLI's, whose gzip/zlib the page's pako inflates) and
// error messages. window.tessera exposes the same operations to tests.
import { TesseraViewer } from './tessera.js';
import { attachStacks } from './dicom-stacks.js';
import { attachOverlayPanel } from './overlay-panel.js';

(function () {
  const params = new URLSearchParams(location.search);
  const forceWebgl1 = params.get('webgl') === '1';
  // ?size=N: a fixed N x N canvas (tests compare it with native images);
  // otherwise the canvas fills its box at the screen's pixel density.
  const fixedSize = params.has('size')
    ? Math.max(16, Math.min(2048, parseInt(params.get('size'), 10) || 512)) : 0;
  // The volume is rendered at most this many pixels and upscaled; lines and
  // compositing keep the canvas's full backing size (?maxvolume=PIXELS).
  const maxVolumePixels = Math.max(0, parseInt(params.get('maxvolume') || String(640 * 640), 10) || 0);
  const MAX_BACKING = 4096;  // per side
  const defaultVolume = params.get('volume') || 'gen:shepp-logan:96';
  // Full-quality frames in strips of about this many ms per animation frame,
  // so that input is handled during slow frames (?progressive=0: one piece).
  const progressive = params.get('progressive') !== '0';
  const frameBudgetMs = Math.max(1, parseFloat(params.get('budget') || '12') || 12);
  const volumeUrls = params.getAll('url').filter((u) => u.length);
  // ?layout=bricks: a store's t axis plays over bricks even when its level
  // 0 would fit in core (as `tessera render --layout bricks`).
  const storeBricks = params.get('layout') === 'bricks';
  // ?zarrcache=MiB: the chunks a store keeps fetched (default 48).
  const zarrCacheMiB = parseFloat(params.get('zarrcache') || '0') || 0;
  // ?stripshare=S: the share of the frame budget a store's strips take
  // (default 0.25; for comparisons).
  const stripShare = parseFloat(params.get('stripshare') || '0') || 0;
  // ?dicomweb=ROOT: a DICOMweb archive's studies and series to open
  // (frontends/web/dicomweb.js).
  const dicomwebRoot = params.get('dicomweb') || '';
  // Axial, coronal and sagittal views beside the 3D view (frontends/web/slices.js;
  // ?slices=0: the 3D view alone).
  const withSlices = params.get('slices') !== '0' && !!window.TesseraSlices;
  // ?dragdensity=device: camera drags keep the full pixel density (see
  // backingRatio; for comparisons).
  const dragAtDeviceDensity = params.get('dragdensity') === 'device';
  // The viewer's frame time goal while dragging (?dragms=MS): below its own
  // 66 ms, since the browser composes the page after each frame (on a
  // phone's software GL, about 30 ms more at 390x844 ratio 3).
  const dragGoalMs = Math.max(5, parseFloat(params.get('dragms') || '40') || 40);
  // A store's camera drag is answered as each move arrives (pointerrawupdate:
  // secure contexts, localhost included), not at the next animation frame
  // as pointermove is dispatched (?rawinput=0: at the animation frame).
  const rawInput = params.get('rawinput') !== '0' && 'onpointerrawupdate' in window;
  // ?lowlatency=1: the 3D view's WebGL context is a low-latency one
  // (tessera.js: lowLatencyContext; for comparisons).
  const lowLatency = params.get('lowlatency') === '1';

  const $ = (id) => document.getElementById(id);
  const canvas = $('canvas');
  if (fixedSize) {
    canvas.classList.add('fixed');
    canvas.width = fixedSize;
    canvas.height = fixedSize;
    $('views').classList.add('fixed');
    $('views').style.setProperty('--cell', `${fixedSize + 2}px`);  // the canvas and its border
  } else {
    canvas.classList.add('responsive');
    $('view').classList.add('responsive');
  }

  // While the camera is dragged the canvas has one pixel per CSS pixel (at
  // ratio 3 a ninth of its pixels): the box, the axes and the compositing
  // then cost what the interactive volume does, not the screen's full
  // density; full density again once released.
  let cameraDragged = false;
  function backingRatio() {
    const dpr = window.devicePixelRatio || 1;
    return cameraDragged && !dragAtDeviceDensity ? Math.min(dpr, 1) : dpr;
  }

  // Backing size = CSS size x devicePixelRatio (capped per side); returns
  // true when it changed (the canvas is cleared then and needs a frame).
  function fitCanvas() {
    if (fixedSize) return false;
    const dpr = backingRatio();
    let w = Math.max(1, Math.round(canvas.clientWidth * dpr));
    let h = Math.max(1, Math.round(canvas.clientHeight * dpr));
    const s = Math.min(1, MAX_BACKING / Math.max(w, h));
    w = Math.max(1, Math.round(w * s));
    h = Math.max(1, Math.round(h * s));
    if (canvas.width === w && canvas.height === h) return false;
    canvas.width = w;
    canvas.height = h;
    return true;
  }
  fitCanvas();

  let viewer = null;  // the TesseraViewer (tessera.js)
  let M = null;       // its emscripten module
  let api = null;     // cwrapped functions the viewer does not cover
  let state = {};   // last tessera_state_json
  let tf = null;    // parsed TF JSON
  let needsRender = true;
  let frames = 0;
  let renderWaiters = [];
  let refineNotBefore = 0;  // performance.now() before which no strip is rendered
  // The store's preview drawn by an input handler as the input arrived
  // (answerStoreInput), and when the last animation frame began: at most
  // one preview per frame interval.
  let frameBeganAt = 0;
  let inputDrawnAt = -Infinity;
  let storeDrawnAt = -Infinity;  // the last store frame or preview drawn in an animation frame
  // The time stamp of the oldest input on a store's view that no preview
  // has answered yet (the earliest of the moves coalesced into an event):
  // the preview that answers it is due within two budgets of it
  // (tessera_zarr_frame's inputWaitedMs; noteStoreInput, storeViewFrame).
  let storeInputStamp = Infinity;
  let slices = null;        // frontends/web/slices.js, once the module is up
  let zarr = null;  // an open OME-Zarr store (frontends/web/zarr-url.js)
  let storeTime = null;  // its t axis played as a time series (frontends/web/store-time.js)
  let channelList = null;  // its channels shown together (frontends/web/channels-panel.js)
  let dicomStacks = null;  // the series/stack chooser (frontends/web/dicom-stacks.js)
  let dicomweb = null;  // the DICOMweb browser (frontends/web/dicomweb.js), with ?dicomweb=
  let overlayPanel = null;  // the second volume (frontends/web/overlay-panel.js)

  function showError(message) {
    const e = $('error');
    e.textContent = message;
    e.hidden = false;
  }
  // What a failed load leaves on screen.
  const keeps = () => (state.has_volume ? ' — the previous volume stays' : '');
  function clearError() {
    $('error').hidden = true;
    $('error').textContent = '';
  }

  function wrap(M) {
    const c = (name, ret, args) => M.cwrap(name, ret, args);
    return {
      lastError: c('tessera_last_error', 'string', []),
      pointerViewport: c('tessera_pointer_viewport', null, ['number', 'number']),
      pointerDown: c('tessera_pointer_down', null, ['number', 'number', 'number', 'number']),
      pointerMove: c('tessera_pointer_move', null, ['number', 'number', 'number']),
      pointerUp: c('tessera_pointer_up', null, ['number']),
      wheel: c('tessera_wheel', null, ['number']),
      interacting: c('tessera_interacting', 'number', []),
      setProjection: c('tessera_set_projection', null, ['number']),
      tfJson: c('tessera_tf_json', 'string', []),
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
      setSampling: c('tessera_set_sampling', null, ['number', 'number']),
      setOverlays: c('tessera_set_overlays', null, ['number', 'number']),
      setQuality: c('tessera_set_quality', null, ['number']),
      setMaxVolumePixels: c('tessera_set_max_volume_pixels', null, ['number']),
      setInteractionGoal: c('tessera_set_interaction_goal', null, ['number']),
      setProgressive: c('tessera_set_progressive', null, ['number', 'number']),
      refining: c('tessera_refining', 'number', []),
      refine: c('tessera_refine', 'number', []),
      setTechnique: c('tessera_set_technique', 'number', ['string']),
      stateJson: c('tessera_state_json', 'string', ['number']),
      setGradientOpacity: c('tessera_set_gradient_opacity', 'number', ['number', 'number', 'number']),
      setLight: c('tessera_set_light', 'number', ['number', 'number', 'number', 'number', 'number', 'number', 'number', 'number']),
      setCrop: c('tessera_set_crop', 'number', ['number', 'number', 'number', 'number', 'number', 'number']),
      showCropBox: c('tessera_show_crop_box', null, ['number']),
      cropJson: c('tessera_crop_json', 'string', ['number', 'number']),
      cropDown: c('tessera_crop_pointer_down', 'number', ['number', 'number', 'number', 'number', 'number']),
      cropMove: c('tessera_crop_pointer_move', 'number', ['number', 'number']),
      cropUp: c('tessera_crop_pointer_up', null, []),
      setFollowingPlane: c('tessera_set_following_plane', null, ['number', 'number']),
      setLabels: c('tessera_set_labels', 'number', ['number', 'string', 'string']),
      labelsJson: c('tessera_labels_json', 'string', []),
      setLabelVisible: c('tessera_set_label_visible', null, ['number', 'number']),
    };
  }

  // The crop sliders follow the box (dragged handles, reset).
  function syncCropControls() {
    const c = JSON.parse(api.cropJson(canvas.width, canvas.height));
    if (!c.min) return;
    ['X', 'Y', 'Z'].forEach((a, i) => {
      $('crop' + a + '0').value = c.min[i];
      $('crop' + a + '1').value = c.max[i];
    });
  }

  // One row per label: swatch, visibility box, value and name.
  function drawLabelList() {
    const t = JSON.parse(api.labelsJson());
    const list = $('labelList');
    list.replaceChildren();
    $('labelsAll').hidden = !t.on;
    for (const l of t.labels) {
      const row = document.createElement('label');
      const swatch = document.createElement('span');
      swatch.className = 'swatch';
      swatch.style.background = `rgb(${l.color.map((c) => Math.round(255 * c)).join(',')})`;
      const box = document.createElement('input');
      box.type = 'checkbox';
      box.checked = l.visible;
      box.dataset.value = l.value;
      box.addEventListener('change', () => { api.setLabelVisible(l.value, box.checked ? 1 : 0); requestRender(); });
      row.append(box, swatch, ` ${l.value} ${l.name}`);
      list.append(row);
    }
  }

  function showAllLabels(on) {
    api.setLabelVisible(-1, on ? 1 : 0);
    drawLabelList();
    requestRender();
  }

  function refreshState() {
    state = JSON.parse(api.stateJson($('logHist').checked ? 1 : 0));
    tf = JSON.parse(api.tfJson());
    // The session's choice (a CT or MR series opens with its modality's
    // default, session/ModalityDefault.h) shows in the preset menu.
    const menu = $('preset');
    if (menu.value !== tf.name && [...menu.options].some((o) => o.value === tf.name)) {
      menu.value = tf.name;
    }
    if ($('labels').checked !== !!state.labels) {  // a new volume leaves label mode
      $('labels').checked = !!state.labels;
      drawLabelList();
    }
    return state;
  }

  function requestRender() {
    needsRender = true;
    return new Promise((resolve) => renderWaiters.push(resolve));
  }

  function renderNow() {
    fitCanvas();
    let ms = -1;
    try {
      ms = viewer.render();
    } catch (e) {
      showError(e.message);
    }
    frames++;
    refreshState();
    updateStatus();
    updateOrientationLabels();
    if (slices) slices.frameShown(state);
    return ms;
  }

  // A strip of the pending full-quality frame (about frameBudgetMs).
  function refineNow() {
    const ms = api.refine();
    if (ms < 0) showError(api.lastError());
    if (!api.refining()) {
      frames++;
      refreshState();
      updateStatus();
    }
    return ms;
  }

  // One animation frame: a new frame when something changed, else a strip
  // of the pending full-quality one; render() promises resolve once the
  // frame is complete.
  function loop() {
    const previousFrameAt = frameBeganAt;
    frameBeganAt = performance.now();
    if (viewer && viewer.contextLost) {
      requestAnimationFrame(loop);  // nothing to draw on until it is restored
      return;
    }
    // An input's stamp is the store's view's until a store frame answers
    // it; any other frame forgets it.
    if (!storeDrawn()) storeInputStamp = Infinity;
    if (api && channelList && channelList.active()) {
      if (time.count > 1) timeStep();  // a store's channels with a t axis
      channelFrameStep();
    } else if (api && zarr && zarr.active() && (!storeTime || storeTime.bricks)) {
      if (storeTime && time.count > 1) timeStep();
      storeFrameStep(inputDrawnAt >= previousFrameAt);
    } else if (api) {
      let ms = -1;
      if (time.count > 1) timeStep();
      if (needsRender) {
        needsRender = false;
        ms = renderNow();
      } else if (api.refining() && performance.now() >= refineNotBefore) {
        // The per-animation-frame cap: a strip that cost more than the budget
        // (a technique's fixed cost per pass can exceed it) is followed by
        // as much idle time, so input and the page keep at least half.
        ms = refineNow();
        refineNotBefore = ms > frameBudgetMs ? performance.now() + ms : 0;
      }
      if (!needsRender && !api.refining() && renderWaiters.length) {
        const waiters = renderWaiters;
        renderWaiters = [];
        waiters.forEach((w) => w(ms));
      }
    }
    requestAnimationFrame(loop);
  }

  // A store's channels (frontends/web/channels-panel.js): a whole frame when
  // something changed.
  function channelFrameStep() {
    let ms = -1;
    if (needsRender) {
      needsRender = false;
      fitCanvas();
      ms = channelList.frame(canvas.width, canvas.height);
      frames++;
    }
    if (!needsRender && renderWaiters.length) {
      const waiters = renderWaiters;
      renderWaiters = [];
      waiters.forEach((w) => w(ms));
    }
  }

  // An OME-Zarr store (frontends/web/zarr-url.js): frames while bricks arrive,
  // about frameBudgetMs of work per animation frame as for in-core volumes:
  // a changed view shows a preview at once and its full frame follows
  // (bricks that arrived streamed first, then strips of the ray march);
  // render() promises resolve once the full frame is on the canvas.
  // `answered`: a move drew its preview since the last animation frame
  // (storeMoved), which is this frame's work when no input came after it.
  function storeFrameStep(answered) {
    let f = null;
    if (needsRender || (!zarr.refining() && zarr.wantsFrame())) {
      const viewChanged = needsRender;
      needsRender = false;
      fitCanvas();
      f = viewChanged ? storeViewFrame() : zarr.frame(canvas.width, canvas.height, false);
      if (viewChanged) storeDrawnAt = performance.now();
    } else if (answered) {
      // The preview drawn as the move arrived is on the canvas: its full
      // frame follows from the next animation frame.
    } else if (zarr.refining() && performance.now() >= refineNotBefore) {
      f = zarr.refine();
      // As for in-core strips: one that cost more than the budget is
      // followed by as much idle time.
      refineNotBefore = f && f.ms > frameBudgetMs ? performance.now() + f.ms : 0;
    }
    if (f && f.shown) {
      frames++;
      if (slices) slices.frameShown(refreshState());  // the store's slice views
    }
    if (!needsRender && !zarr.refining() && renderWaiters.length) {
      const waiters = renderWaiters;
      renderWaiters = [];
      waiters.forEach((w) => w(f ? f.ms : -1));
    }
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
    const what = s.refining ? 'preview' : 'frame';
    $('status').textContent = `${vol} · ${api} · ${what} ${s.render_size[0]}×${s.render_size[1]} in ${s.frame_ms.toFixed(0)} ms` +
      (s.refining ? ' · refining…' : '') + (contextNote ? ` · ${contextNote}` : '');
  }

  // ---------------------------------------------------------------- context loss

  // A phone that sends the page to the background (or a GPU reset) takes
  // the WebGL context away: TesseraViewer (tessera.js) stops drawing, and
  // when the browser gives it back makes the session again on it (same
  // volume and state); the page says so and shows the restored frame.
  let contextNote = '';  // on the status line until the next load or drag
  function watchContext() {
    viewer.on('contextlost', () => {
      contextNote = '';
      $('status').textContent = 'WebGL context lost — waiting';
    });
    viewer.on('contextrestored', ({ error }) => {
      contextNote = 'WebGL context restored';
      if (error) {
        if (zarr) { zarr.close(); zarr = null; }  // the store's GPU side is gone
        showError(error);
      }
      volumeChanged();
      $('status').textContent = contextNote;
      // A store's view was made again on the new context: its GPU side is
      // rebuilt from the chunks the page holds (zarr-url.js), and the region
      // or channels it showed are shown again (the module's).
      if (zarr && !error) {
        zarr.reopen().then(() => {
          volumeChanged();
          $('status').textContent = contextNote;
          requestRender();
        });
      }
      // The zoom swap (grid.js) ended with the old context: on again.
      if ($('zoomSwap').checked) $('zoomSwap').dispatchEvent(new Event('change'));
      requestRender();
    });
  }

  // ---------------------------------------------------------------- files

  // Reads files picked or dropped together (a header and its data: .nhdr +
  // .raw, .mhd + .raw/.zraw, .hdr + .img, .json sidecar + .raw; or one
  // self-contained file); the reader picks the one that names the others.
  // On failure shows why and keeps the current volume.
  async function openFiles(fileList) {
    const files = Array.from(fileList);
    if (files.length === 0) return false;
    const entries = await Promise.all(files.map(async (f) => ({ name: f.name, bytes: new Uint8Array(await f.arrayBuffer()) })));
    return openEntries(entries, (message) => message);
  }

  // A dropped or picked folder (a DICOM series; frontends/web/dicom-drop.js walks it):
  // every file read with progress, then the series opened.
  async function openFolder(named) {
    const progress = $('progress');
    if (named.length === 0) {
      showError('the folder has no files' + keeps());
      return false;
    }
    let entries;
    try {
      progress.hidden = false;
      progress.max = named.length;
      entries = await TesseraFolders.readAll(named, (done, total, bytes) => {
        progress.value = done;
        $('status').textContent = `reading ${done} of ${total} files (${megabytes(bytes)} MB)`;
      });
    } catch (e) {
      progress.hidden = true;
      showError(e.message + keeps());
      updateStatus();
      return false;
    }
    entries = TesseraFolders.forReading(entries);
    $('status').textContent = `opening ${entries.length} files…`;
    await new Promise((r) => requestAnimationFrame(() => setTimeout(r, 0)));  // paint it first
    progress.hidden = true;
    return openEntries(entries, (message) => message);
  }

  // Hands {name, bytes} entries to the io readers; `explain` turns a
  // failure's message into what the page shows.
  async function openEntries(entries, explain, dicomSelection = '') {
    try {
      entries = await TesseraFolders.decodeCompressed(entries, (done, total) => { $('status').textContent = `decoding ${done} of ${total} files`; });
      dicomStacks?.select(dicomSelection);  // a series or stack chosen (dicom-stacks.js)
      await viewer.openFiles(entries, { explain });
      dicomStacks?.opened(entries, viewer.state().name);
    } catch (e) {
      showError(e.message + keeps());
      return false;
    }
    if (zarr) zarr.close();  // the files' volume replaces the store
    clearError();
    contextNote = '';
    volumeChanged();
    await requestRender();
    return true;
  }

  function megabytes(n) { return (n / 1048576).toFixed(1); }

  // ?url=… (repeat it for a header and its data file): fetched with a
  // progress bar (TesseraViewer.openUrl), then read like picked files;
  // errors name the URL.
  let lastLoad = null;  // for tests: what the last ?url= load fetched
  async function openUrls(urls) {
    const progress = $('progress');
    lastLoad = { urls, bytes: 0, total: 0, updates: 0 };
    const sizes = new Map();  // per URL: [received, total]
    progress.hidden = false;
    progress.removeAttribute('value');
    try {
      await viewer.openUrl(urls, { onProgress: ({ url, received, total }) => {
        lastLoad.updates++;
        sizes.set(url, [received, total]);
        if (total > 0) {
          progress.max = total;
          progress.value = Math.min(received, total);
        }
        $('status').textContent = `loading ${url}: ${megabytes(received)}` +
          (total > 0 ? ` of ${megabytes(total)} MB (${Math.round(100 * Math.min(1, received / total))} %)` : ' MB');
      } });
    } catch (e) {
      progress.hidden = true;
      showError(e.message + keeps());
      updateStatus();
      return false;
    } finally {
      for (const [received, total] of sizes.values()) {
        lastLoad.bytes += received;
        lastLoad.total += total;
      }
    }
    progress.hidden = true;
    if (zarr) zarr.close();  // the files' volume replaces the store
    clearError();
    volumeChanged();
    await requestRender();
    return true;
  }

  function volumeChanged() {
    refreshState();
    if (overlayPanel) overlayPanel.refresh();
    timeChanged();
    syncWindowControls();
    drawTf();
  }

  // ---------------------------------------------------------------- time series
  // A dropped 4-D NIfTI plays back (session/TimeSeries.h): the slider shows
  // a time point once it is read, Play steps through every time point in
  // order at the chosen rate (a late one shown late, never skipped).
  const time = { count: 1, shown: 0, asked: null, log: [], since: 0 };

  function timeChanged() {
    const t = viewer.timeSeries();
    time.count = t.count;
    time.shown = t.shown || 0;
    time.asked = null;
    time.log = time.count > 1 ? [time.shown] : [];
    $('time-controls').hidden = time.count <= 1;
    $('timePoint').max = Math.max(0, time.count - 1);
    $('timePoint').value = time.shown;
    $('timePlay').textContent = t.playing ? 'Pause' : 'Play';  // (playing on after a context loss)
    timeStatus();
  }

  function timeStatus() {
    $('timeText').textContent = `${time.shown} of ${time.count}`;
    const t = time.count > 1 ? viewer.timeSeries() : null;
    if (!t || !t.playing) {
      $('timeStatus').textContent = '';
      return;
    }
    const seconds = (performance.now() - time.since) / 1000;
    const rate = seconds > 0 ? t.advances / seconds : 0;
    $('timeStatus').textContent = `${rate.toFixed(1)} time points/s of ${t.fps}, ${t.late} late frames`;
  }

  // Once per animation frame: playback's next time point, or the one the
  // slider asked for once it is read.
  function timeStep() {
    try {
      if (time.asked !== null) {
        if (viewer.showTimePoint(time.asked)) {
          time.shown = time.asked;
          time.asked = null;
          time.log.push(time.shown);
          needsRender = true;
        }
      } else if (viewer.timeSeries().playing) {
        const shown = viewer.stepPlayback(performance.now());
        if (shown !== time.shown) {
          time.shown = shown;
          time.log.push(shown);
          $('timePoint').value = shown;
          needsRender = true;
        }
      }
    } catch (e) {
      showError(e.message);  // playback has stopped (a time point could not be read)
      time.asked = null;
      $('timePlay').textContent = 'Play';
    }
    timeStatus();
  }

  function timePlay(play) {
    try {
      if (play) {
        viewer.play({ fps: parseFloat($('timeFps').value) || 10 });
        time.since = performance.now();
      } else {
        viewer.pause();
      }
      $('timePlay').textContent = play ? 'Pause' : 'Play';
    } catch (e) {
      showError(e.message);
    }
  }

  $('timePoint').addEventListener('input', () => {
    time.asked = parseInt($('timePoint').value, 10);
  });
  $('timePlay').addEventListener('click', () => timePlay(!viewer.timeSeries().playing));
  $('timeFps').addEventListener('change', () => {
    if (viewer.timeSeries().playing) timePlay(true);
  });

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
  // Camera input in CSS pixels over the view's CSS size: a drag turns the
  // view by the same angle per CSS pixel at every devicePixelRatio.
  function cameraPos(e) {
    const r = canvas.getBoundingClientRect();
    api.pointerViewport(r.width, r.height);
    return [e.clientX - r.left, e.clientY - r.top];
  }
  function setCameraDragged(on) {
    if (cameraDragged === on) return;
    cameraDragged = on;
    requestRender();  // at the new backing size
  }
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
  // A left press on a crop box handle drags that face instead of the camera.
  let cropPointer = null;
  const cameraPointers = new Set();  // pressed on the view, moving the camera
  canvas.addEventListener('pointerdown', (e) => {
    if (!api) return;
    const [x, y] = canvasPos(e);
    const handleRadius = (e.pointerType === 'touch' ? 24 : 12) * canvas.width / canvas.getBoundingClientRect().width;
    if (cropPointer === null && e.button === 0 && !e.shiftKey &&
        api.cropDown(x, y, canvas.width, canvas.height, handleRadius)) {
      cropPointer = e.pointerId;
      canvas.setPointerCapture(e.pointerId);
      e.preventDefault();
      requestRender();
      return;
    }
    contextNote = '';
    api.pointerDown(e.pointerId, ...cameraPos(e), e.button === 2 || e.shiftKey ? 1 : 0);
    cameraPointers.add(e.pointerId);
    canvas.setPointerCapture(e.pointerId);
    e.preventDefault();
  });
  canvas.addEventListener('pointermove', (e) => {
    if (!api) return;
    const [x, y] = canvasPos(e);
    if (e.pointerId === cropPointer) {
      if (api.cropMove(x, y)) { syncCropControls(); requestRender(); }
      return;
    }
    if (rawPointers.has(e.pointerId)) return;  // moved the camera as it arrived (storeMoved)
    api.pointerMove(e.pointerId, ...cameraPos(e));
    if (api.interacting()) {
      noteStoreInput(e);
      setCameraDragged(true);
      requestRender();
    }
  });
  // Input on a store's view (a move as it arrives, a release, a wheel turn)
  // is answered at once: the first in a frame interval draws the store's
  // preview in its handler (tessera_zarr_frame, as the animation frame
  // would), so that it is on the canvas at the next frame, not a frame
  // later; a later one in the same interval, or one that comes while a
  // frame is pending (`pending`: needsRender before the input), is drawn by
  // the next animation frame. The full frame follows from there.
  function storeDrawn() {
    return api && zarr && zarr.active() && (!storeTime || storeTime.bricks) && !(channelList && channelList.active());
  }
  function noteStoreInput(e) {
    if (!storeDrawn()) return;
    const coalesced = e.getCoalescedEvents ? e.getCoalescedEvents() : [];
    storeInputStamp = Math.min(storeInputStamp, e.timeStamp, ...coalesced.map((c) => c.timeStamp));
  }
  // A store frame that shows a changed view: it answers the inputs noted.
  function storeViewFrame() {
    const waited = Number.isFinite(storeInputStamp) ? Math.max(0, performance.now() - storeInputStamp) : -1;
    storeInputStamp = Infinity;
    return zarr.frame(canvas.width, canvas.height, true, waited);
  }
  function answerStoreInput(pending, e) {
    noteStoreInput(e);
    if (pending || !storeDrawn() || (viewer && viewer.contextLost) ||
        inputDrawnAt >= frameBeganAt || storeDrawnAt >= frameBeganAt) {
      requestRender();
      return;
    }
    needsRender = false;
    fitCanvas();
    const f = storeViewFrame();
    inputDrawnAt = performance.now();
    if (f && f.shown) {
      frames++;
      if (slices) slices.frameShown(refreshState());
    }
  }
  // rawInput: a camera drag over a store moves the camera as each move
  // arrives (answerStoreInput). Pointers whose moves come here skip
  // pointermove (it follows with the same position).
  const rawPointers = new Set();
  function storeMoved(e) {
    if (!cameraPointers.has(e.pointerId) || !storeDrawn() || (viewer && viewer.contextLost)) {
      rawPointers.delete(e.pointerId);  // its pointermove moves the camera
      return;
    }
    rawPointers.add(e.pointerId);
    api.pointerMove(e.pointerId, ...cameraPos(e));
    const pending = needsRender;
    setCameraDragged(true);  // (asks for a frame at the drag's backing size: drawn here)
    answerStoreInput(pending, e);
  }
  if (rawInput) canvas.addEventListener('pointerrawupdate', storeMoved);
  const forgetRaw = (e) => {
    rawPointers.delete(e.pointerId);
    cameraPointers.delete(e.pointerId);
  };
  const viewEnd = (e) => {
    if (!api) return;
    if (e.pointerId === cropPointer) {
      cropPointer = null;
      api.cropUp();
      requestRender();
      return;
    }
    const pending = needsRender;
    api.pointerUp(e.pointerId);
    forgetRaw(e);
    if (!api.interacting()) setCameraDragged(false);
    answerStoreInput(pending, e);  // full quality once released (in-core: at the next frame)
  };
  canvas.addEventListener('pointerup', viewEnd);
  canvas.addEventListener('pointercancel', viewEnd);
  canvas.addEventListener('wheel', (e) => {
    if (!api) return;
    const pending = needsRender;
    api.wheel(Math.sign(e.deltaY));
    answerStoreInput(pending, e);
    e.preventDefault();
  }, { passive: false });

  // Drag and drop of files anywhere on the page (the 3D view shows the
  // hint); a visible file input keeps its own drops.
  const view = $('view');
  // Files or folders: the 'Files' type, or (where a browser leaves types
  // empty) a file item or file.
  const carriesFiles = (e) => {
    const dt = e.dataTransfer;
    if (!dt || (e.target instanceof Element && e.target.closest('input[type=file]'))) return false;
    return Array.from(dt.types || []).includes('Files') ||
      Array.from(dt.items || []).some((i) => i.kind === 'file') || (dt.files && dt.files.length > 0);
  };
  let dragDepth = 0;  // dragenter/dragleave pairs of the elements crossed
  document.addEventListener('dragenter', (e) => {
    if (!carriesFiles(e)) return;
    dragDepth++;
    view.classList.add('dragover');
  });
  document.addEventListener('dragover', (e) => {
    if (!carriesFiles(e)) return;
    e.preventDefault();
    view.classList.add('dragover');
  });
  document.addEventListener('dragleave', (e) => {
    if (!carriesFiles(e)) return;
    dragDepth = Math.max(0, dragDepth - 1);
    if (dragDepth === 0) view.classList.remove('dragover');
  });
  document.addEventListener('drop', (e) => {
    if (!carriesFiles(e)) return;
    e.preventDefault();
    dragDepth = 0;
    view.classList.remove('dragover');
    const folder = TesseraFolders.droppedFolderEntries(e.dataTransfer);
    if (folder) {
      TesseraFolders.walk(folder).then(openFolder, (err) => showError(`cannot read the dropped folder: ${err.message}`));
    } else if (e.dataTransfer.files.length) {
      // A second file while one is open: offered as the overlay.
      if (overlayPanel) overlayPanel.offer(e.dataTransfer.files); else openFiles(e.dataTransfer.files);
    }
  });

  // ---------------------------------------------------------------- controls

  function bindControls() {
    $('file').addEventListener('change', async (e) => {
      const files = Array.from(e.target.files);
      e.target.value = '';
      if (files.length) await openFiles(files);
    });
    $('folder').addEventListener('change', async (e) => {
      const named = TesseraFolders.pickedFiles(e.target.files);
      e.target.value = '';
      await openFolder(named);
    });
    // TransferFunction::presetNames(): the window presets, then the clinical
    // ones (HU for CT, percentiles for MR; core/ClinicalPresets.h).
    ['grey', 'mr-default', 'ct-bone', 'ct-muscle', 'bench',
      'ct-soft-tissue', 'ct-lung', 'ct-angio', 'mr-percentile'].forEach((n) => {
      const o = document.createElement('option');
      o.value = n;
      o.textContent = n;
      $('preset').appendChild(o);
    });
    $('preset').value = 'mr-default';
    $('preset').addEventListener('change', (e) => {
      try { viewer.setTransferFunction(e.target.value); } catch (err) { showError(err.message); }
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
      try {
        viewer.setTransferFunction(await f.text());
        clearError();
      } catch (err) {
        showError(`${f.name}: ${err.message}`);
      }
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
    const sampling = () => { api.setSampling($('preint').checked ? 1 : 0, $('adaptive').checked ? 1 : 0); requestRender(); };
    $('preint').addEventListener('change', sampling);
    $('adaptive').addEventListener('change', sampling);
    $('opacity').addEventListener('input', (e) => { api.setOpacityScale(+e.target.value); requestRender(); });
    $('shade').addEventListener('change', (e) => { api.setShading(e.target.checked ? 1 : 0); requestRender(); });
    const overlays = () => { api.setOverlays($('box').checked ? 1 : 0, $('axes').checked ? 1 : 0); requestRender(); };
    $('box').addEventListener('change', overlays);
    $('axes').addEventListener('change', overlays);
    $('resetView').addEventListener('click', () => { viewer.setCamera({ azimuth: 0, elevation: 0, zoom: 1 }); requestRender(); });
    // Light: a headlight or a fixed light (patient frame), and the Blinn-Phong terms.
    const applyLight = () => {
      const dir = $('lightDir').value.split(',').map(Number);
      if (!api.setLight($('headlight').checked ? 1 : 0, +$('ambient').value, +$('diffuse').value,
        +$('specular').value, +$('shininess').value, dir[0], dir[1], dir[2])) showError(api.lastError());
      $('lightDir').disabled = $('headlight').checked;
      requestRender();
    };
    ['headlight', 'lightDir'].forEach((id) => $(id).addEventListener('change', applyLight));
    // Gradient-magnitude opacity (with or without the light): the sliders
    // keep low below high.
    const applyGradientOpacity = (e) => {
      const lo = $('gradLow'), hi = $('gradHigh');
      if (+lo.value >= +hi.value) {
        if (e && e.target === lo) hi.value = Math.min(+hi.max, +lo.value + 0.005);
        else lo.value = Math.max(0, +hi.value - 0.005);
      }
      if (!api.setGradientOpacity($('gradOpacity').checked ? 1 : 0, +lo.value, +hi.value)) showError(api.lastError());
      requestRender();
    };
    $('gradOpacity').addEventListener('change', applyGradientOpacity);
    ['gradLow', 'gradHigh'].forEach((id) => $(id).addEventListener('input', applyGradientOpacity));
    ['ambient', 'diffuse', 'specular', 'shininess'].forEach((id) => $(id).addEventListener('input', applyLight));
    // Clipping: the crop box (sliders and handles) and the camera-facing plane.
    const applyCrop = (e) => {
      const v = (id) => +$(id).value;
      // Keep min below max: the slider being moved pushes its partner.
      for (const a of ['X', 'Y', 'Z']) {
        const lo = $('crop' + a + '0'), hi = $('crop' + a + '1');
        if (+lo.value > +hi.value - 0.02) {
          if (e && e.target === lo) lo.value = Math.max(0, +hi.value - 0.02);
          else hi.value = Math.min(1, +lo.value + 0.02);
        }
      }
      if (!api.setCrop(v('cropX0'), v('cropX1'), v('cropY0'), v('cropY1'), v('cropZ0'), v('cropZ1'))) showError(api.lastError());
      requestRender();
    };
    ['X', 'Y', 'Z'].forEach((a) => ['0', '1'].forEach((k) => $('crop' + a + k).addEventListener('input', applyCrop)));
    $('cropShow').addEventListener('change', (e) => { api.showCropBox(e.target.checked ? 1 : 0); requestRender(); });
    $('resetCrop').addEventListener('click', () => { api.setCrop(0, 1, 0, 1, 0, 1); syncCropControls(); requestRender(); });
    const applyPlane = () => {
      // Depth: a fraction of half the volume's diagonal, towards the viewer.
      api.setFollowingPlane($('followPlane').checked ? 1 : 0, +$('planeDepth').value);
      requestRender();
    };
    $('followPlane').addEventListener('change', applyPlane);
    // Labels: the volume as a label volume, a table file, visibility per label.
    let labelTable = { text: '', name: '' };
    const applyLabels = () => {
      if (!api.setLabels($('labels').checked ? 1 : 0, labelTable.text, labelTable.name)) {
        showError(api.lastError());
        $('labels').checked = false;
      }
      drawLabelList();
      requestRender();
    };
    $('labels').addEventListener('change', applyLabels);
    $('labelFile').addEventListener('change', async (e) => {
      const f = e.target.files[0];
      if (!f) return;
      labelTable = { text: await f.text(), name: f.name };
      $('labels').checked = true;
      applyLabels();
    });
    $('planeDepth').addEventListener('input', applyPlane);
    $('labelsShow').addEventListener('click', () => showAllLabels(true));
    $('labelsHide').addEventListener('click', () => showAllLabels(false));
    window.addEventListener('resize', drawTf);
  }

  // ---------------------------------------------------------------- start

  const ready = (async () => {
    try {
      viewer = await TesseraViewer.create(canvas, { profile: forceWebgl1 ? 'webgl1' : 'auto', lowLatency });
    } catch (e) {
      showError(e.message);
      throw e;
    }
    M = viewer.module;
    api = wrap(M);
    bindControls();
    watchContext();
    if (withSlices) {
      slices = window.TesseraSlices.attach({ M, canvas, requestRender, showError, clearError,
        storeRegion: zarrRegion, storeOverview: zarrOverview,
        storeFetch: () => (zarr ? zarr.fetchWanted() : Promise.resolve([])),
        crosshairNote: (voxel) => (overlayPanel ? overlayPanel.crosshairText(voxel) : '') });
      window.tessera.slices = slices.testApi;
    } else {
      $('slice-controls').hidden = true;
    }
    refreshState();
    overlayPanel = attachOverlayPanel({ M, webgl: state.webgl, state: () => state, openFiles,
      requestRender, showError, clearError });
    window.tessera.overlay = overlayPanel.testApi;
    dicomStacks = attachStacks({ module: M, reopen: (entries, selection) => openEntries(entries, (m) => m, selection) });
    window.tessera.dicomStacks = dicomStacks;
    state.techniques.forEach((n) => {
      const o = document.createElement('option');
      o.value = n;
      o.textContent = n;
      $('technique').appendChild(o);
    });
    $('preint').checked = state.sampling.preintegrate;  // webDefaultSampling()
    $('adaptive').checked = state.sampling.adaptive;
    api.setMaxVolumePixels(maxVolumePixels);
    api.setInteractionGoal(dragGoalMs);
    api.setProgressive(progressive ? 1 : 0, frameBudgetMs);
    new ResizeObserver(() => { if (fitCanvas()) requestRender(); }).observe(canvas);
    window.addEventListener('resize', () => { if (fitCanvas()) requestRender(); });
    requestAnimationFrame(loop);
    if (volumeUrls.length === 1 && window.TesseraZarr && TesseraZarr.isStoreUrl(volumeUrls[0])) {
      // (A size refused is said once the store is open with the default.)
      const cacheRefused = zarrCacheMiB && !M.ccall('tessera_zarr_set_cache_mib', 'number', ['number'], [zarrCacheMiB])
        ? api.lastError() : '';
      const shareRefused = stripShare && !M.ccall('tessera_zarr_set_strip_share', 'number', ['number'], [stripShare])
        ? api.lastError() : '';
      zarr = TesseraZarr.create(M, { showError, clearError,
        status: (t) => { $('status').textContent = contextNote ? `${t} · ${contextNote}` : t; },
        progress: (v, max) => { $('progress').hidden = !(max > 0); if (max > 0) { $('progress').max = max; $('progress').value = v; } } });
      if (await zarr.open(volumeUrls[0]) && window.TesseraChannels) {
        channelList = await TesseraChannels.attach(M, zarr, { requestRender, showError, clearError });
      }
      if (zarr.active() && !channelList && window.TesseraStoreTime) {
        storeTime = await TesseraStoreTime.attach(M, zarr, { showError }, { bricks: storeBricks });
      } else if (channelList && window.TesseraStoreTime && viewer.timeSeries().count > 1) {
        storeTime = TesseraStoreTime.fetchAhead(zarr);  // the channels' time points ahead
      }
      volumeChanged();
      if (cacheRefused || shareRefused) showError([cacheRefused, shareRefused].filter((t) => t).join('; '));
    } else if (volumeUrls.length) {
      if (!(await openUrls(volumeUrls))) volumeChanged();
    } else {
      try { viewer.loadGenerated(defaultVolume); } catch (e) { showError(e.message); }
      volumeChanged();
    }
    if (dicomwebRoot) await attachDicomWeb();
    await requestRender();
    return state;
  })();

  // The archive's series in a table above the view; a series chosen there
  // is read into {name, bytes} entries and opened by openEntries().
  async function attachDicomWeb() {
    const { attach } = await import('./dicomweb.js');
    dicomweb = attach({ root: dicomwebRoot, openEntries, showError, clearError, keeps,
      status: (t) => { $('status').textContent = t; },
      progress: (v, max) => { $('progress').hidden = !(max > 0); if (max > 0) { $('progress').max = max; $('progress').value = v; } } });
    window.tessera.dicomweb = dicomweb;
    try { await dicomweb.list(); } catch { /* shown; the page stays usable */ }
    updateStatus();
  }

  // The bread-slice region [begin, end) of an open store's level 0 at
  // native resolution (bounded reads: only its chunks are fetched), shown
  // by the viewer; resolves to the keys fetched for it. zarrOverview()
  // returns to the store.
  async function zarrRegion(begin, end) {
    if (!zarr) throw new Error('no OME-Zarr store is open');
    const keys = await zarr.showRegion(begin, end);
    volumeChanged();
    await requestRender();
    return keys;
  }
  function zarrOverview() {
    if (zarr) zarr.overview();
    volumeChanged();
    return requestRender();
  }

  // For tests and the console.
  window.tessera = {
    ready,
    state: () => refreshState(),
    tf: () => JSON.parse(api.tfJson()),
    frames: () => frames,
    render: () => requestRender(),
    openFiles,
    openFile: (file) => openFiles([file]),
    // Time series: {count, shown, playing, fps, late, advances}, the time
    // points drawn so far in order, play(fps) / pause(), and one time point
    // shown (resolves once it is drawn).
    time: () => ({ ...viewer.timeSeries(), log: time.log.slice() }),
    play: (fps) => {
      $('timeFps').value = String(fps);
      timePlay(true);
    },
    pause: () => timePlay(false),
    showTime: (t) => {
      time.asked = t;
      return new Promise((resolve) => {
        const drawn = () => time.asked === null && !needsRender && !api.refining();
        const wait = () => (drawn() ? resolve(time.shown) : setTimeout(wait, 10));
        wait();
      });
    },
    openUrls,
    lastLoad: () => lastLoad,
    zarr: () => (zarr ? zarr.stats() : null),
    zarrHolds: (key) => (zarr ? zarr.holds(key) : false),
    // The channels shown together ({open, name, mode, channels}), or null.
    channels: () => (channelList ? channelList.state() : null),
    // The bread-slice region [begin, end) of an open store's level 0 at
    // native resolution (bounded reads: only its chunks are fetched); the
    // keys fetched for it. zarrOverview() returns to the store.
    zarrRegion,
    zarrOverview,
    setProgressive: (on) => { api.setProgressive(on ? 1 : 0, frameBudgetMs); },
    setCamera: (az, el, zoom) => { viewer.setCamera({ azimuth: az, elevation: el, zoom }); return requestRender(); },
    crop: () => JSON.parse(api.cropJson(canvas.width, canvas.height)),
    setProjection: (orthographic) => { api.setProjection(orthographic ? 1 : 0); return requestRender(); },
    setTfJson: (json) => {
      let ok = 1;
      try { viewer.setTransferFunction(json); } catch { ok = 0; }  // tessera_last_error says why
      tfEdited();
      return ok;
    },
    error: () => ($('error').hidden ? '' : $('error').textContent),
    // The canvas's RGBA pixels, top row first.
    pixels: () => viewer.pixels(),
    viewer: () => viewer,
    // n whole frames of the current view as the page renders them, each
    // timed here up to its 1-pixel read-back (bench/web-peers).
    timeFrames: (n) => {
      const times = [];
      api.setProgressive(0, 0);
      for (let i = 0; i < n; i++) {
        const t = performance.now();
        renderNow();
        times.push(performance.now() - t);
      }
      api.setProgressive(progressive ? 1 : 0, frameBudgetMs);
      return times;
    },
    // Median frame time over n frames turning 10 degrees each (a frame ends
    // with a 1-pixel read-back, since glFinish does not wait in browsers).
    benchmark: (n) => {
      const times = [];
      api.setProgressive(0, 0);  // whole frames, timed one by one
      for (let i = 0; i < n; i++) {
        viewer.setCamera({ azimuth: i * 10, elevation: 0, zoom: 1 });
        times.push(renderNow());
      }
      api.setProgressive(progressive ? 1 : 0, frameBudgetMs);
      times.sort((a, b) => a - b);
      return { median: times[Math.floor(times.length / 2)], min: times[0], max: times[times.length - 1], times };
    },
  };
})();
