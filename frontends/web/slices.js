// Slice views and the bread-slice region (Schultz 2016
// §7.4), beside the 3D view of frontends/web/app.js:
//
// - Axial, coronal and sagittal slices of the loaded volume, drawn by the
//   wasm core (tessera_slice: core/SliceImage, the pixels and patient
//   letters of `tessera slice`, radiological convention) through the
//   viewer's window, grey or in the TF's colours, nearest voxel. The
//   crosshair is one voxel (x, y, z); each view shows the slice through it,
//   so moving it in one view moves the others, and the 3D view marks it
//   with a small 3D cross.
//   Slice index: wheel, vertical drag (mouse or one finger), arrow keys,
//   PageUp/PageDown, Home/End. Tap/click moves the crosshair.
// - "Pick region": drag a box in a slice view (or tap for a box of the
//   side set below, default what the profile allows, at most 256³) → that
//   box of the volume at native resolution becomes the 3D view
//   (tessera_region_show); "Overview" (or Esc) returns, and the overview
//   shows the region as a red box.
//
// - An OME-Zarr store (?url=): everything above is in level-0 voxels; each
//   slice is read at the finest level its panel can show, the coarsest
//   level standing in until that slab's chunks arrive (refinePending).
//
// The page (app.js) calls TesseraSlices.attach() once the module is up and
// frameShown() after every frame; window.tessera.slices is for tests.
'use strict';

window.TesseraSlices = (function () {
  // Slicer's colours: axial red, coronal green, sagittal yellow.
  const COLORS = { axial: '#e8574f', coronal: '#5cc45c', sagittal: '#e6c84a' };
  const PLANES = ['axial', 'coronal', 'sagittal'];
  const TAP_PX = 6;  // a pointer that moved less is a tap

  function attach(opts) {
    const { M, canvas, requestRender, showError, clearError } = opts;
    const $ = (id) => document.getElementById(id);
    const c = (name, ret, args) => M.cwrap(name, ret, args);
    const api = {
      slice: c('tessera_slice', 'string', ['number', 'number', 'number', 'number']),
      value: c('tessera_voxel_value', 'number', ['number', 'number', 'number']),
      explore: c('tessera_explore_json', 'string', []),
      regionShow: c('tessera_region_show', 'number', ['number', 'number', 'number', 'number', 'number', 'number']),
      regionOverview: c('tessera_region_overview', 'number', []),
      projection: c('tessera_projection_json', 'string', ['number', 'number']),
      markBox: c('tessera_set_mark_box', 'number', ['number', 'number', 'number', 'number', 'number', 'number', 'number']),
      lastError: c('tessera_last_error', 'string', []),
    };
    // The region's box in the overview is drawn by the viewer (slot 0), as
    // lines composed with the volume by depth like the bounding box; sent
    // when it changes, and a frame asked for.
    let sentMark = '';
    function syncMark(box) {
      const key = box ? `${box.begin.join(',')}:${box.end.join(',')}` : '';
      if (key === sentMark) return false;
      sentMark = key;
      if (box) api.markBox(0, box.begin[0], box.end[0], box.begin[1], box.end[1], box.begin[2], box.end[2]);
      else api.markBox(0, 0, 0, 0, 0, 0, 0);
      return true;
    }

    // Text that is redrawn after every frame is set only when it changed
    // (assigning the same text still replaces the node: layout and paint).
    const setText = (el, text) => { if (el.textContent !== text) el.textContent = text; };
    const setDisabled = (el, on) => { if (el.disabled !== on) el.disabled = on; };

    const views = $('views');
    views.classList.add('quad');
    const overlay3d = $('overlay3d');
    let explore = { has_volume: false };
    let volumeKey = '';
    let windowKey = '';
    let timeShown = -1;         // the time point the slices show (explore.time)
    let cross = [0, 0, 0];      // the crosshair voxel (the slices' voxels: a store's level 0)
    let region = null;          // the picked box {begin, end} (the slices' voxels, end exclusive)
    let picking = false;        // "Pick region" pressed
    let rubber = null;          // a box being dragged: {panel, a: [px, py], b: [px, py]} in image pixels
    const panels = {};          // by plane
    let grid = null;            // frontends/web/grid.js, the grid view (attached below)

    // The three panels; which index axis each shows is decided per volume
    // from the slice frames the core reports (the plane nearest each axis).
    for (const plane of PLANES) {
      const el = $(`slice-${plane}`);
      panels[plane] = {
        plane, el, axis: -1, frame: null,
        image: el.querySelector('.slice-image'),
        overlay: el.querySelector('.slice-overlay'),
        label: el.querySelector('.slice-label'),
        fit: { left: 0, top: 0, scale: 1 },
      };
    }

    // Grey (0), or the TF's colours (1, as `tessera slice --tf`).
    const colour = () => ($('sliceColour').checked ? 1 : 0);

    // ------------------------------------------------------------ geometry

    // Image pixel (continuous, raster units) <-> voxel along the column or
    // row axis, as core/SliceImage's sliceVoxelOf (nearest voxel centre).
    function voxelOfPixel(p, f, which) {
      const a = which === 'col' ? f.col_axis : f.row_axis;
      const rev = which === 'col' ? f.col_reversed : f.row_reversed;
      const n = explore.dims[a];
      const s = explore.spacing[a];
      const t = Math.min(n - 1, Math.max(0, Math.floor((Math.floor(p) + 0.5) * f.pixel_mm / s)));
      return rev ? n - 1 - t : t;
    }
    // Continuous voxel coordinate (voxel i spans [i, i+1]) -> image pixel.
    function pixelOfVoxel(v, f, which) {
      const a = which === 'col' ? f.col_axis : f.row_axis;
      const rev = which === 'col' ? f.col_reversed : f.row_reversed;
      const n = explore.dims[a];
      const t = rev ? n - v : v;
      return t * explore.spacing[a] / f.pixel_mm;
    }

    function fitPanel(p) {
      const f = p.frame;
      const W = p.el.clientWidth, H = p.el.clientHeight;
      if (!f || W === 0 || H === 0) return;
      const scale = Math.min(W / f.width, H / f.height);
      p.fit = { left: (W - f.width * scale) / 2, top: (H - f.height * scale) / 2, scale };
      Object.assign(p.image.style, {
        left: `${p.fit.left}px`, top: `${p.fit.top}px`,
        width: `${f.width * scale}px`, height: `${f.height * scale}px`,
      });
      const dpr = window.devicePixelRatio || 1;
      const bw = Math.round(W * dpr), bh = Math.round(H * dpr);
      if (p.overlay.width !== bw || p.overlay.height !== bh) {
        p.overlay.width = bw;
        p.overlay.height = bh;
        p.overlayKey = null;  // (resizing cleared it)
      }
    }

    // Pointer position -> image pixels of the panel's slice.
    function imagePos(p, e) {
      const r = p.overlay.getBoundingClientRect();
      return [(e.clientX - r.left - p.fit.left) / p.fit.scale, (e.clientY - r.top - p.fit.top) / p.fit.scale];
    }

    // ------------------------------------------------------------ drawing

    // The panel's backing pixels: an OME-Zarr store's slice is read at the
    // finest level with no more pixels than that (finer would not show). No
    // panel (the frames only, assignAxes): 1, the coarsest level in memory.
    let pixelsOverride = 0;  // tests: as if every panel had this many pixels
    function panelPixels(p) {
      if (!p) return 1;
      if (pixelsOverride > 0) return pixelsOverride;
      const dpr = window.devicePixelRatio || 1;
      return Math.max(1, p.el.clientWidth * dpr) * Math.max(1, p.el.clientHeight * dpr);
    }
    function sliceJson(axis, p) {
      return api.slice(axis, cross[axis], colour(), panelPixels(p));
    }

    function assignAxes() {
      // Each index axis's plane, from the core's slice frames.
      const frames = [0, 1, 2].map((a) => JSON.parse(sliceJson(a, null) || 'null'));
      if (frames.some((f) => !f)) { showError(api.lastError()); return false; }
      const byPlane = {};
      frames.forEach((f) => { byPlane[f.plane] = f.axis; });
      // An oblique volume may put two axes nearest one plane: then the
      // panels show z, y, x under the names the core gives them.
      const distinct = Object.keys(byPlane).length === 3;
      PLANES.forEach((plane, i) => {
        const axis = distinct ? byPlane[plane] : 2 - i;
        panels[plane].axis = axis;
        panels[plane].frame = frames[axis];
      });
      return true;
    }

    function drawSlice(p) {
      const json = sliceJson(p.axis, p);
      if (!json) { showError(api.lastError()); return; }
      const f = JSON.parse(json);
      p.frame = f;
      // The image's own pixels (a store's slice at the level read, or the
      // coarsest while that level's chunks arrive), shown stretched over
      // the frame's width x height.
      const iw = f.image_width, ih = f.image_height;
      const pixels = new Uint8ClampedArray(M.HEAPU8.slice(f.pixels, f.pixels + iw * ih * 4).buffer);
      if (p.image.width !== iw || p.image.height !== ih) {
        p.image.width = iw;
        p.image.height = ih;
      }
      p.image.getContext('2d').putImageData(new ImageData(pixels, iw, ih), 0, 0);
      p.el.classList.toggle('pending', !!f.pending);
      p.image.title = f.note || (f.pending ? 'a coarser level while the slice is fetched' : '');
      if (f.pending) refinePending();
      for (const edge of ['left', 'right', 'top', 'bottom']) {
        p.el.querySelector(`.orient-${edge}`).textContent = f.oriented ? f.edges[edge] : '';
      }
      p.label.textContent = `${f.plane} ${f.index}${f.pending ? ' · loading…' : ''}`;
      p.label.title = `index ${f.index} of 0–${f.count - 1} along the volume's ${'xyz'[f.axis]} axis`;
      fitPanel(p);
    }

    function drawAllSlices() {
      for (const plane of PLANES) drawSlice(panels[plane]);
    }

    // An OME-Zarr store's slices shown from a coarser level: their chunks
    // are fetched (ahead of the 3D view's refinement) and the slices drawn
    // again, refined in place; a few rounds at most per call (a slice moved
    // meanwhile asks for its own chunks).
    let refining = null;
    function refinePending() {
      if (refining || !opts.storeFetch) return refining;
      refining = (async () => {
        try {
          for (let round = 0; round < 4; round++) {
            const keys = await opts.storeFetch();
            const pending = PLANES.map((q) => panels[q]).filter((q) => q.frame && q.frame.pending);
            if (keys.length === 0 || pending.length === 0) break;
            // Drawn again, they list only what they still lack (zarr-url.js
            // never fetches a key twice).
            for (const q of pending) drawSlice(q);
            redrawOverlays();
          }
        } finally {
          refining = null;
        }
      })();
      return refining;
    }

    // In-plane rectangle (image pixels) of a voxel box, or null.
    function boxRect(p, box) {
      const f = p.frame;
      const x0 = pixelOfVoxel(box.begin[f.col_axis], f, 'col'), x1 = pixelOfVoxel(box.end[f.col_axis], f, 'col');
      const y0 = pixelOfVoxel(box.begin[f.row_axis], f, 'row'), y1 = pixelOfVoxel(box.end[f.row_axis], f, 'row');
      return [Math.min(x0, x1), Math.min(y0, y1), Math.abs(x1 - x0), Math.abs(y1 - y0)];
    }

    // Drawn again only when what it shows changed (it is redrawn after every
    // frame of the 3D view, and a canvas drawn on is raster and composite
    // work for the browser's GPU process, which the 3D view's next frame
    // then waits for).
    function drawPanelOverlay(p) {
      const f = p.frame;
      const dpr = window.devicePixelRatio || 1;
      const block = grid && grid.block();
      const shown = f && explore.has_volume;
      const key = JSON.stringify([p.overlay.width, p.overlay.height, dpr, shown && [f, p.fit, cross, region, block,
        rubber && rubber.panel === p ? rubberBox(p) : null]]);
      if (key === p.overlayKey) return;
      p.overlayKey = key;
      const ctx = p.overlay.getContext('2d');
      ctx.setTransform(1, 0, 0, 1, 0, 0);
      ctx.clearRect(0, 0, p.overlay.width, p.overlay.height);
      if (!shown) return;
      // Image pixels -> overlay pixels.
      ctx.setTransform(dpr * p.fit.scale, 0, 0, dpr * p.fit.scale, dpr * p.fit.left, dpr * p.fit.top);
      const px = 1 / p.fit.scale;  // one CSS pixel in image pixels
      // The region: filled where this slice cuts it, dashed where it does not.
      if (region) {
        const [x, y, w, h] = boxRect(p, region);
        const inside = cross[p.axis] >= region.begin[p.axis] && cross[p.axis] < region.end[p.axis];
        ctx.lineWidth = 2 * px;
        ctx.strokeStyle = '#ff3b3b';
        ctx.setLineDash(inside ? [] : [4 * px, 4 * px]);
        if (inside) {
          ctx.fillStyle = 'rgba(255, 40, 40, 0.22)';
          ctx.fillRect(x, y, w, h);
        }
        ctx.strokeRect(x, y, w, h);
        ctx.setLineDash([]);
      }
      // The grid view's block (frontends/web/grid.js), cyan, where this slice cuts it.
      if (block && cross[p.axis] >= block.begin[p.axis] && cross[p.axis] < block.end[p.axis]) {
        const [x, y, w, h] = boxRect(p, block);
        ctx.lineWidth = 2 * px;
        ctx.strokeStyle = '#3cd8f0';
        ctx.strokeRect(x, y, w, h);
      }
      if (rubber && rubber.panel === p) {
        const b = rubberBox(p);
        const [x, y, w, h] = boxRect(p, b);
        ctx.lineWidth = 1.5 * px;
        ctx.strokeStyle = '#ffffff';
        ctx.setLineDash([3 * px, 3 * px]);
        ctx.strokeRect(x, y, w, h);
        ctx.setLineDash([]);
      }
      // Crosshair: the other two planes' slices, in their colours, with a
      // gap around the point so the voxel under it stays visible.
      const cx = pixelOfVoxel(cross[f.col_axis] + 0.5, f, 'col');
      const cy = pixelOfVoxel(cross[f.row_axis] + 0.5, f, 'row');
      const gap = 6 * px;
      const colPlane = PLANES.find((q) => panels[q].axis === f.col_axis);
      const rowPlane = PLANES.find((q) => panels[q].axis === f.row_axis);
      ctx.lineWidth = px;
      ctx.strokeStyle = COLORS[colPlane];
      ctx.beginPath();
      ctx.moveTo(cx, 0); ctx.lineTo(cx, cy - gap);
      ctx.moveTo(cx, cy + gap); ctx.lineTo(cx, f.height);
      ctx.stroke();
      ctx.strokeStyle = COLORS[rowPlane];
      ctx.beginPath();
      ctx.moveTo(0, cy); ctx.lineTo(cx - gap, cy);
      ctx.moveTo(cx + gap, cy); ctx.lineTo(f.width, cy);
      ctx.stroke();
    }

    // The 3D view's marks, over its canvas: the crosshair as a small 3D
    // cross (x red, y green, z blue, as the axes). The picked region's red
    // box in the overview is drawn by the viewer (syncMark), by depth.
    // Like the panels' overlays, drawn again only when what it shows
    // changed: the crosshair follows the camera, and without it nothing is
    // drawn on a clear overlay.
    let overlay3dPlace = '';
    let overlay3dKey = null;
    function draw3dOverlay() {
      const dpr = window.devicePixelRatio || 1;
      const W = canvas.clientWidth, H = canvas.clientHeight;
      // Over the canvas's content box (inside its border).
      const place = [canvas.offsetLeft + canvas.clientLeft, canvas.offsetTop + canvas.clientTop, W, H];
      if (place.join() !== overlay3dPlace) {
        overlay3dPlace = place.join();
        Object.assign(overlay3d.style, { left: `${place[0]}px`, top: `${place[1]}px`, width: `${W}px`, height: `${H}px` });
      }
      const bw = Math.max(1, Math.round(W * dpr)), bh = Math.max(1, Math.round(H * dpr));
      if (overlay3d.width !== bw || overlay3d.height !== bh) {
        overlay3d.width = bw;
        overlay3d.height = bh;
        overlay3dKey = null;  // (resizing cleared it)
      }
      let shown = null;  // what the crosshair's drawing depends on, or null: a clear overlay
      let pj = null;
      let showing = null;
      if (explore.has_volume) {
        const text = api.projection(canvas.width, canvas.height) || '{}';
        pj = JSON.parse(text) || {};
        if (pj.mvp) {
          showing = explore.showing_region ? explore.region : null;
          if (syncMark(region && !showing ? region : null)) requestRender();
          const inside = $('crosshair3d').checked && (!showing || [0, 1, 2].every((a) => cross[a] >= showing.begin[a] && cross[a] < showing.end[a]));
          if (inside) shown = JSON.stringify([text, cross, showing, explore.dims, explore.spacing]);
        }
      }
      const key = `${bw}x${bh}@${dpr}|${shown}`;
      if (key === overlay3dKey) return;
      overlay3dKey = key;
      const ctx = overlay3d.getContext('2d');
      ctx.setTransform(1, 0, 0, 1, 0, 0);
      ctx.clearRect(0, 0, bw, bh);
      if (!shown) return;
      const m = pj.mvp;
      const project = (v) => {
        const p = v.map((x, a) => x * pj.spacing[a] + pj.offset[a]);
        const cx = m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12];
        const cy = m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13];
        const cw = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15];
        if (!(cw > 1e-9)) return null;
        return [(cx / cw + 1) / 2 * bw, (1 - cy / cw) / 2 * bh];
      };
      const line = (a, b) => {
        const pa = project(a), pb = project(b);
        if (!pa || !pb) return;
        ctx.moveTo(pa[0], pa[1]);
        ctx.lineTo(pb[0], pb[1]);
      };
      const dims = showing ? [0, 1, 2].map((a) => showing.end[a] - showing.begin[a]) : explore.dims;
      const arm = 0.08 * Math.max(...dims.map((d, a) => d * explore.spacing[a]));
      const centre = cross.map((v) => v + 0.5);
      ['#ff5050', '#50ff50', '#5c8cff'].forEach((color, a) => {
        const lo = centre.slice(), hi = centre.slice();
        lo[a] -= arm / explore.spacing[a];
        hi[a] += arm / explore.spacing[a];
        ctx.beginPath();
        line(lo, hi);
        ctx.strokeStyle = '#000';
        ctx.lineWidth = 4 * dpr;
        ctx.stroke();
        ctx.strokeStyle = color;
        ctx.lineWidth = 2 * dpr;
        ctx.stroke();
      });
    }

    // The crosshair voxel's position in RAS+ millimetres (the volume's affine).
    function crossMm() {
      const a = explore.index_to_world;
      if (!a) return '';
      const mm = a.map((r) => r[0] * cross[0] + r[1] * cross[1] + r[2] * cross[2] + r[3]);
      return ` at (${mm.map((v) => v.toFixed(1)).join(', ')}) mm RAS`;
    }

    function updateInfo() {
      const v = explore.has_volume ? api.value(cross[0], cross[1], cross[2]) : NaN;
      setText($('crosshairInfo'), explore.has_volume
        ? `crosshair voxel (${cross.join(', ')})${crossMm()}: value ${Number.isFinite(v) ? +v.toPrecision(6) : '–'}` +
          (opts.crosshairNote ? opts.crosshairNote(cross) : '') : '');
      const r = region;
      const text = r ? `region x ${r.begin[0]}:${r.end[0]}, y ${r.begin[1]}:${r.end[1]}, z ${r.begin[2]}:${r.end[2]} ` +
        `(${r.end.map((e, a) => e - r.begin[a]).join('×')} voxels, native resolution)` : 'no region picked';
      const gridShown = grid && grid.active();
      setText($('regionInfo'), explore.showing_region && !gridShown ? `3D view: ${text}` : text);
      setDisabled($('overview'), !explore.showing_region);
      setDisabled($('showRegion'), !region || !!explore.showing_region);
      if ($('pickRegion').getAttribute('aria-pressed') !== String(picking)) $('pickRegion').setAttribute('aria-pressed', String(picking));
      $('pickRegion').classList.toggle('pressed', picking);
      views.classList.toggle('picking', picking);
      views.classList.toggle('region-shown', !!explore.showing_region && !gridShown);
    }

    function redrawOverlays() {
      for (const plane of PLANES) drawPanelOverlay(panels[plane]);
      draw3dOverlay();
      updateInfo();
    }

    // ------------------------------------------------------------ state changes

    // After every frame of the 3D view (app.js): a new volume resets the
    // crosshair to its centre; a new window or time point redraws the slices; the 3D
    // marks follow the camera; in colour, a TF edit redraws them too.
    function frameShown(state) {
      explore = JSON.parse(api.explore());
      if (!explore.has_volume) { redrawOverlays(); if (grid) grid.frameShown(explore); return; }
      const key = `${explore.name}|${explore.dims.join('x')}`;
      let redraw = false;
      if (key !== volumeKey) {
        volumeKey = key;
        cross = explore.dims.map((d) => Math.floor(d / 2));
        region = null;
        picking = false;
        $('regionSide').value = explore.region_side;
        $('regionSide').max = Math.max(...explore.dims);
        $('regionSide').title = `default: ${explore.region_side_reason}`;
        if (!assignAxes()) return;
        redraw = true;
      }
      // (A label volume's slices are always in its label colours.)
      const wk = `${(state.window || []).join(',')}|${colour() || explore.labels ? explore.tf_revision : 'grey'}`;
      if (wk !== windowKey) { windowKey = wk; redraw = true; }
      // A series played: the slices show the 3D view's time point.
      if (explore.time !== timeShown) { timeShown = explore.time; redraw = true; }
      if (redraw) drawAllSlices();
      redrawOverlays();
      if (grid) grid.frameShown(explore);
    }

    function setCross(v) {
      if (!explore.has_volume) return false;
      const next = v.map((x, a) => Math.min(explore.dims[a] - 1, Math.max(0, Math.round(x))));
      const changed = [0, 1, 2].filter((a) => next[a] !== cross[a]);
      cross = next;
      for (const plane of PLANES) {
        const p = panels[plane];
        if (changed.includes(p.axis)) drawSlice(p);
      }
      redrawOverlays();
      return changed.length > 0;
    }

    function step(p, delta) {
      const v = cross.slice();
      v[p.axis] += delta;
      setCross(v);
    }

    // The box a drag (or tap) in panel p describes: in-plane from the drag,
    // at most `side` voxels (a tap: a square of the side around it), `side`
    // voxels deep around the slice, clamped to the volume.
    function rubberBox(p) {
      const f = p.frame;
      const side = Math.max(1, parseInt($('regionSide').value, 10) || explore.region_side);
      const begin = [0, 0, 0], end = [0, 0, 0];
      const span = (a, centre) => {
        const n = explore.dims[a], s = Math.min(side, n);
        begin[a] = Math.min(n - s, Math.max(0, Math.round(centre - s / 2)));
        end[a] = begin[a] + s;
      };
      span(p.axis, cross[p.axis] + 0.5);
      const [ax, ay] = rubber.a, [bx, by] = rubber.b;
      const tap = Math.hypot((bx - ax) * p.fit.scale, (by - ay) * p.fit.scale) < TAP_PX;
      for (const [which, a0, a1] of [['col', ax, bx], ['row', ay, by]]) {
        const a = which === 'col' ? f.col_axis : f.row_axis;
        if (tap) {
          span(a, voxelOfPixel(a0, f, which) + 0.5);
        } else {
          // From the voxel under the press towards the one under the
          // finger, at most `side` voxels (what the profile allows).
          const v0 = voxelOfPixel(a0, f, which), v1 = voxelOfPixel(a1, f, which);
          const length = Math.min(Math.abs(v1 - v0) + 1, side);
          begin[a] = v1 >= v0 ? v0 : v0 - length + 1;
          end[a] = begin[a] + length;
        }
      }
      return { begin, end };
    }

    async function showRegion(box) {
      if (explore.store) {
        // An OME-Zarr store: the box (level-0 voxels, as the slices) is read
        // with bounded reads (only its chunks fetched).
        try {
          await opts.storeRegion(box.begin, box.end);
        } catch (e) {
          showError(`region: ${e.message}`);
          return false;
        }
        clearError();
        explore = JSON.parse(api.explore());
        region = explore.region;
        return true;
      }
      if (!api.regionShow(box.begin[0], box.end[0], box.begin[1], box.end[1], box.begin[2], box.end[2])) {
        showError(`region: ${api.lastError()}`);
        return false;
      }
      clearError();
      region = JSON.parse(api.explore()).region;
      await requestRender();
      return true;
    }

    async function overview() {
      if (explore.store) {
        await opts.storeOverview();
        return true;
      }
      if (!api.regionOverview()) { showError(api.lastError()); return false; }
      syncMark(region);  // in the very frame that shows the overview
      await requestRender();
      return true;
    }

    // ------------------------------------------------------------ input

    for (const plane of PLANES) {
      const p = panels[plane];
      const el = p.overlay;
      let drag = null;  // {id, y, startX, start (the index), moved}
      el.addEventListener('contextmenu', (e) => e.preventDefault());
      el.addEventListener('pointerdown', (e) => {
        if (!explore.has_volume || drag) return;
        el.focus({ preventScroll: true });
        el.setPointerCapture(e.pointerId);
        drag = { id: e.pointerId, y: e.clientY, startX: e.clientX, start: cross[p.axis], moved: false };
        if (picking) {
          const at = imagePos(p, e);
          rubber = { panel: p, a: at, b: at };
          drawPanelOverlay(p);
        }
        e.preventDefault();
      });
      el.addEventListener('pointermove', (e) => {
        if (!drag || drag.id !== e.pointerId) return;
        const dy = e.clientY - drag.y, dx = e.clientX - drag.startX;
        if (Math.hypot(dx, dy) >= TAP_PX) drag.moved = true;
        if (picking) {
          rubber.b = imagePos(p, e);
          drawPanelOverlay(p);
        } else if (drag.moved) {
          // Vertical drag pages through the slices: the panel's height
          // spans the whole stack (at least one slice per 12 CSS px).
          const perPx = Math.max(1 / 12, p.frame.count / Math.max(1, el.clientHeight));
          const v = cross.slice();
          v[p.axis] = drag.start - Math.round(dy * perPx);
          setCross(v);
        }
      });
      const end = async (e, cancelled) => {
        if (!drag || drag.id !== e.pointerId) return;
        const moved = drag.moved;
        drag = null;
        if (picking && rubber) {
          const box = rubberBox(p);
          rubber = null;
          if (cancelled) { drawPanelOverlay(p); return; }
          picking = false;
          await showRegion(box);
        } else if (!moved && !cancelled) {
          // A tap or click moves the crosshair to that voxel.
          const [ix, iy] = imagePos(p, e);
          const f = p.frame;
          if (ix >= 0 && iy >= 0 && ix < f.width && iy < f.height) {
            const v = cross.slice();
            v[f.col_axis] = voxelOfPixel(ix, f, 'col');
            v[f.row_axis] = voxelOfPixel(iy, f, 'row');
            setCross(v);
          }
        }
      };
      el.addEventListener('pointerup', (e) => end(e, false));
      el.addEventListener('pointercancel', (e) => end(e, true));
      el.addEventListener('wheel', (e) => {
        if (!explore.has_volume) return;
        step(p, e.deltaY < 0 ? 1 : -1);
        e.preventDefault();
      }, { passive: false });
      el.addEventListener('keydown', (e) => {
        if (!explore.has_volume) return;
        const n = p.frame ? p.frame.count : 1;
        const moves = { ArrowUp: 1, ArrowRight: 1, ArrowDown: -1, ArrowLeft: -1, PageUp: 10, PageDown: -10 };
        if (e.key in moves) step(p, moves[e.key]);
        else if (e.key === 'Home') step(p, -n);
        else if (e.key === 'End') step(p, n);
        else return;
        e.preventDefault();
      });
      new ResizeObserver(() => { fitPanel(p); drawPanelOverlay(p); }).observe(p.el);
    }
    new ResizeObserver(() => draw3dOverlay()).observe(canvas);

    $('pickRegion').addEventListener('click', () => { picking = !picking; updateInfo(); });
    // An overlay added, restyled or removed (frontends/web/overlay-panel.js): the
    // slices mix it in (session::fuseSliceImage) and the readout reads it.
    window.addEventListener('tessera-overlay', () => { drawAllSlices(); redrawOverlays(); });
    $('showRegion').addEventListener('click', () => { if (region) showRegion(region); });
    $('overview').addEventListener('click', () => overview());
    $('crosshair3d').addEventListener('change', () => draw3dOverlay());
    $('sliceColour').addEventListener('change', () => { windowKey = ''; requestRender(); });
    $('regionSide').addEventListener('change', (e) => {
      const v = parseInt(e.target.value, 10);
      if (!(v >= 1)) e.target.value = explore.region_side;
    });
    window.addEventListener('keydown', (e) => {
      const t = e.target;
      if (t && (t.tagName === 'INPUT' || t.tagName === 'SELECT' || t.tagName === 'TEXTAREA')) return;
      if (e.key === 'Escape' && explore.showing_region) { overview(); e.preventDefault(); }
    });
    // Phone layout: one view at a time, chosen by the tabs.
    for (const b of document.querySelectorAll('#view-tabs button')) {
      b.addEventListener('click', () => {
        views.dataset.tab = b.dataset.tab;
        for (const o of document.querySelectorAll('#view-tabs button')) o.setAttribute('aria-selected', o === b ? 'true' : 'false');
        requestRender();
      });
    }

    // For tests: the page's slice images as shown (their canvases' pixels),
    // the letters at their edges, the crosshair and the region.
    const testApi = {
      state: () => ({
        cross: cross.slice(),
        region,
        showing_region: !!explore.showing_region,
        explore,
        panels: Object.fromEntries(PLANES.map((q) => {
          const p = panels[q];
          const letters = {};
          for (const edge of ['left', 'right', 'top', 'bottom']) letters[edge] = p.el.querySelector(`.orient-${edge}`).textContent;
          return [q, { axis: p.axis, index: cross[p.axis], frame: p.frame, letters, fit: p.fit }];
        })),
      }),
      imagePixels: (plane) => {
        const img = panels[plane].image;
        return Array.from(img.getContext('2d').getImageData(0, 0, img.width, img.height).data);
      },
      // RGBA pixels of the 3D view's overlay (the crosshair marker) and, as
      // frameRegionPixels, of the frame (the region's box, drawn by depth).
      overlayPixels: () => Array.from(overlay3d.getContext('2d').getImageData(0, 0, overlay3d.width, overlay3d.height).data),
      framePixels: () => Array.from(window.tessera.pixels()),
      setCross: (x, y, z) => setCross([x, y, z]),
      // As if each panel had `n` backing pixels (0: their own): the level a
      // store's slices are read at.
      setPanelPixels: (n) => { pixelsOverride = n; drawAllSlices(); redrawOverlays(); },
      setPicking: (on) => { picking = !!on; updateInfo(); },
      setRegionSide: (side) => { $('regionSide').value = side; },
      showRegion,
      overview,
    };
    // The grid view (frontends/web/grid.js) shares the 3D view, the crosshair and
    // the overview's return with the region.
    if (window.TesseraGrid) {
      grid = window.TesseraGrid.attach({
        M, canvas, requestRender, showError, clearError, slices: testApi, setText, setDisabled,
        storeRegion: opts.storeRegion, storeOverview: opts.storeOverview,
      });
      testApi.grid = grid.testApi;
    }
    return { frameShown, testApi };
  }

  return { attach };
})();
