// Grid view (Schultz 2016 §7.3) beside the slice
// views of frontends/web/slices.js: the loaded volume split into cubic cells, the
// user on a grid point (a cell corner), the 2x2x2 block of cells around it
// shown as the 3D view at native resolution, six moves relative to the view.
//
// Everything about the grid is the native core's lod::GridNavigator, through
// the tessera_grid_* exports of frontends/web/src/WebExportsExplore.cpp: the grid points and
// their class (corner/edge/face/interior), which index axis each of the six
// moves means for the current camera (the dominant axis of the view
// direction; of the screen's right and up for the others) and whether it is
// legal, with the reason when not. This file only shows that state and
// sends the user's moves.
//
// - "Grid view" (or G) enters at the grid point nearest the crosshair;
//   G or Esc or "Overview" returns (tessera_region_overview, the region's).
// - Moves: the pad under the 3D view (buttons labelled with the grid move
//   they mean now, e.g. "Forward +x"; big enough for a finger), arrow keys
//   (Up forward, Down back, Left, Right), PageUp / PageDown (up, down).
//   A move off the grid is refused and its reason shown under the pad.
// - The overview draws the last block as a cyan box (the region is red),
//   and the slice views outline it where they cut it.
//
// - "Zoom swaps levels and the native block" (or Z): viewer::ZoomSwap drives
//   the 3D view of a loaded file (coarse level, medium level, the native
//   block around the view's centre, chosen by the zoom, cross-faded;
//   docs/explore.md); its stages are shown under the checkbox.
//
// slices.js calls TesseraGrid.attach() and frameShown() after every frame.
'use strict';

window.TesseraGrid = (function () {
  const COLOR = '#3cd8f0';  // cyan: the desktop viewer's grid block colour
  const KEYS = { ArrowUp: 0, ArrowDown: 1, ArrowLeft: 2, ArrowRight: 3, PageUp: 4, PageDown: 5 };

  function attach(opts) {
    const { M, canvas, requestRender, showError, clearError, slices, storeRegion, storeOverview, setText, setDisabled } = opts;
    const $ = (id) => document.getElementById(id);
    const c = (name, ret, args) => M.cwrap(name, ret, args);
    const api = {
      enter: c('tessera_grid_enter', 'number', ['number', 'number', 'number', 'number']),
      move: c('tessera_grid_move', 'number', ['number']),
      json: c('tessera_grid_json', 'string', []),
      overview: c('tessera_region_overview', 'number', []),
      projection: c('tessera_projection_json', 'string', ['number', 'number']),
      markBox: c('tessera_set_mark_box', 'number', ['number', 'number', 'number', 'number', 'number', 'number', 'number']),
      lastError: c('tessera_last_error', 'string', []),
      storeShown: c('tessera_grid_store_shown', 'number', []),
      storeFailed: c('tessera_grid_store_failed', 'number', []),
      zoomSwap: c('tessera_zoom_swap', 'number', ['number', 'number', 'number', 'number']),
      zoomJson: c('tessera_zoom_json', 'string', []),
    };
    // An OME-Zarr store's block is read like its region (frontends/web/zarr-url.js:
    // only the level-0 chunks it overlaps are fetched, then one box read).
    async function readStoreBlock() {
      if (!grid.store_wanted) return true;
      try {
        await storeRegion(grid.block.begin, grid.block.end);
      } catch (e) {
        // Back to the grid point and block shown before (or none).
        api.storeFailed();
        refresh();
        showError(`grid view: ${e.message}`);
        return false;
      }
      if (!api.storeShown()) { showError(api.lastError()); return false; }
      refresh();
      return true;
    }
    // The last block's cyan box in the overview is drawn by the viewer
    // (slot 1), as lines composed with the volume by depth like the
    // bounding box; sent when it changes.
    let sentMark = '';
    function syncMark(box) {
      const key = box ? `${box.begin.join(',')}:${box.end.join(',')}` : '';
      if (key === sentMark) return false;
      sentMark = key;
      if (box) api.markBox(1, box.begin[0], box.end[0], box.begin[1], box.end[1], box.begin[2], box.end[2]);
      else api.markBox(1, 0, 0, 0, 0, 0, 0);
      return true;
    }
    const pad = $('grid-pad');
    const moveButtons = Array.from(pad.querySelectorAll('button[data-move]'));
    let grid = { has_volume: false };
    let volumeKey = '';
    let explore = { has_volume: false };  // slices.js's tessera_explore_json

    const refresh = () => { grid = JSON.parse(api.json()); return grid; };

    // ------------------------------------------------------------ drawing

    function updatePad() {
      // (After every frame: what did not change is left alone.)
      const active = !!grid.active;
      if (pad.hidden !== !active) pad.hidden = !active;
      setText($('gridEnter'), active ? 'Leave grid view (G)' : 'Grid view (G)');
      setDisabled($('gridEnter'), !grid.has_volume);
      $('views').classList.toggle('grid-shown', active);
      if (!grid.has_volume) { setText($('gridInfo'), ''); return; }
      for (const b of moveButtons) {
        const m = grid.moves[parseInt(b.dataset.move, 10)];
        setText(b.querySelector('.move-axis'), m.move);
        // Refused moves stay pressable (a tap shows why), marked.
        b.classList.toggle('illegal', !m.legal);
        const label = `${m.view}: ${m.move}${m.legal ? '' : ` (${m.reason})`}`;
        if (b.getAttribute('aria-label') !== label) b.setAttribute('aria-label', label);
        const title = m.legal ? `move the block one cell along ${m.move}` : m.reason;
        if (b.title !== title) b.title = title;
      }
      const cells = grid.cells.join('×');
      const cell = grid.cell_size.join('×');
      const where = grid.block ? `block ${grid.block_text} (overview voxels, native resolution)` : 'no block shown yet';
      setText($('gridInfo'), `${cells} cells of ${cell} voxels; point ${grid.describe}; ${where}`);
      const note = $('gridNote');
      setText(note, grid.note);
      note.classList.toggle('refused', !!grid.refused);
    }

    // The last block as a box in the 3D view while the overview shows
    // (drawn by the viewer; the 2D overlay canvas stays clear).
    function drawOverlay() {
      const want = grid.has_volume && grid.block && !grid.active && !explore.showing_region ? grid.block : null;
      if (syncMark(want)) requestRender();
    }

    // ------------------------------------------------------------ zoom swap
    // The zoom-driven level swap (viewer::ZoomSwap through tessera_zoom_*):
    // after a frame that starts or runs a cross-fade, or whose zoom asks for
    // another stage, the next frame is asked for at once.
    let zoom = { active: false };
    let zoomOpts = { overviewVoxels: 0, blockVoxels: 0 };
    function syncZoom() {
      zoom = JSON.parse(api.zoomJson());
      $('zoomSwap').checked = !!zoom.active;
      const info = $('zoomInfo');
      if (!zoom.active) { setText(info, ''); return; }
      const stages = zoom.stages.map((st, i) => {
        const what = st.native ? 'native block' : `${st.name} L${st.level}`;
        const text = `${what} from zoom ${st.enter_zoom.toFixed(2)}`;
        return i === zoom.shown_stage ? `[${text}]` : text;
      });
      setText(info, `zoom ${zoom.zoom.toFixed(2)}: ${stages.join(' · ')}${zoom.fading ? ' (fading)' : ''}`);
      if (zoom.fading || zoom.target !== zoom.shown_stage) requestRender();
    }
    async function setZoomSwap(on, opts) {
      if (opts) zoomOpts = { overviewVoxels: opts.overviewVoxels || 0, blockVoxels: opts.blockVoxels || 0 };
      if (!api.zoomSwap(on ? 1 : 0, canvas.height, zoomOpts.overviewVoxels, zoomOpts.blockVoxels)) {
        showError(api.lastError());
        syncZoom();
        return false;
      }
      clearError();
      syncZoom();
      await requestRender();
      return true;
    }
    $('zoomSwap').addEventListener('change', (e) => setZoomSwap(e.target.checked));

    // After every frame (slices.js): a new volume forgets the block.
    function frameShown(exploreNow) {
      explore = exploreNow;
      refresh();
      const key = grid.has_volume ? `${grid.cells.join('x')}|${grid.cell_size.join('x')}` : '';
      if (key !== volumeKey) {
        volumeKey = key;
        if (grid.has_volume && !$('gridCell').value) $('gridCell').placeholder = `auto (${grid.default_cell})`;
      }
      updatePad();
      drawOverlay();
      syncZoom();
    }

    // ------------------------------------------------------------ actions

    async function enter() {
      const cell = parseInt($('gridCell').value, 10);
      const cross = slices.state().cross;
      if (!api.enter(cell >= 1 ? cell : 0, cross[0], cross[1], cross[2])) {
        showError(api.lastError());
        return false;
      }
      clearError();
      refresh();
      if (!(await readStoreBlock())) return false;
      updatePad();
      await requestRender();
      return true;
    }

    async function leave() {
      if (refresh().store) await storeOverview();
      else if (!api.overview()) { showError(api.lastError()); return false; }
      syncMark(refresh().block);  // in the very frame that shows the overview
      await requestRender();
      return true;
    }

    // 0 forward, 1 back, 2 left, 3 right, 4 up, 5 down: 1 moved, 0 refused.
    async function move(i) {
      if (!refresh().active) return -1;
      const r = api.move(i);
      if (r < 0) { showError(api.lastError()); return r; }
      clearError();
      refresh();
      if (r === 1 && !(await readStoreBlock())) return -1;
      updatePad();
      await requestRender();
      return r;
    }

    $('gridEnter').addEventListener('click', () => (refresh().active ? leave() : enter()));
    $('gridLeave').addEventListener('click', () => leave());
    moveButtons.forEach((b) => b.addEventListener('click', () => move(parseInt(b.dataset.move, 10))));
    $('gridCell').addEventListener('change', () => { if (refresh().active) enter(); });
    window.addEventListener('keydown', (e) => {
      const t = e.target;
      if (t && (t.tagName === 'INPUT' || t.tagName === 'SELECT' || t.tagName === 'TEXTAREA')) return;
      if (e.ctrlKey || e.metaKey || e.altKey) return;
      if ((e.key === 'z' || e.key === 'Z') && grid.has_volume && !refresh().store) {
        setZoomSwap(!zoom.active);
        e.preventDefault();
      } else if (e.key === 'g' || e.key === 'G') {
        if (!grid.has_volume) return;
        refresh().active ? leave() : enter();
        e.preventDefault();
      } else if (e.key in KEYS && refresh().active && !(t && t.classList && t.classList.contains('slice-overlay'))) {
        // (A focused slice view keeps the arrows for its slices.)
        move(KEYS[e.key]);
        e.preventDefault();
      }
    });

    const testApi = {
      state: () => refresh(),
      enter: async (cell) => { if (cell !== undefined) $('gridCell').value = cell; return enter(); },
      move,
      leave,
      // The zoom swap: on/off (options: overviewVoxels, blockVoxels replace
      // the profile's budgets), and its state (tessera_zoom_json).
      zoomSwap: setZoomSwap,
      zoomState: () => JSON.parse(api.zoomJson()),
      // RGBA pixels of the 3D view's frame (the block's box, drawn by depth).
      framePixels: () => Array.from(window.tessera.pixels()),
    };
    return {
      frameShown,
      testApi,
      active: () => !!grid.active,
      block: () => (grid.has_volume ? grid.block : null),
    };
  }

  return { attach };
})();
