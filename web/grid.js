// Grid view (issue 15 items 3 and 6; Schultz 2016 §7.3) beside the slice
// views of web/slices.js: the loaded volume split into cubic cells, the
// user on a grid point (a cell corner), the 2x2x2 block of cells around it
// shown as the 3D view at native resolution, six moves relative to the view.
//
// Everything about the grid is the native core's lod::GridNavigator, through
// the tessera_grid_* exports of web/src/WebViewer.cpp: the grid points and
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
// slices.js calls TesseraGrid.attach() and frameShown() after every frame.
'use strict';

window.TesseraGrid = (function () {
  const COLOR = '#3cd8f0';  // cyan: the desktop viewer's grid block colour
  const KEYS = { ArrowUp: 0, ArrowDown: 1, ArrowLeft: 2, ArrowRight: 3, PageUp: 4, PageDown: 5 };

  function attach(opts) {
    const { M, canvas, requestRender, showError, clearError, slices } = opts;
    const $ = (id) => document.getElementById(id);
    const c = (name, ret, args) => M.cwrap(name, ret, args);
    const api = {
      enter: c('tessera_grid_enter', 'number', ['number', 'number', 'number', 'number']),
      move: c('tessera_grid_move', 'number', ['number']),
      json: c('tessera_grid_json', 'string', []),
      overview: c('tessera_region_overview', 'number', []),
      projection: c('tessera_projection_json', 'string', ['number', 'number']),
      lastError: c('tessera_last_error', 'string', []),
    };
    const pad = $('grid-pad');
    const overlay = $('overlayGrid');
    const moveButtons = Array.from(pad.querySelectorAll('button[data-move]'));
    let grid = { has_volume: false };
    let volumeKey = '';
    let explore = { has_volume: false };  // slices.js's tessera_explore_json

    const refresh = () => { grid = JSON.parse(api.json()); return grid; };

    // ------------------------------------------------------------ drawing

    function updatePad() {
      const active = !!grid.active;
      pad.hidden = !active;
      $('gridEnter').textContent = active ? 'Leave grid view (G)' : 'Grid view (G)';
      $('gridEnter').disabled = !grid.has_volume;
      $('views').classList.toggle('grid-shown', active);
      if (!grid.has_volume) { $('gridInfo').textContent = ''; return; }
      for (const b of moveButtons) {
        const m = grid.moves[parseInt(b.dataset.move, 10)];
        b.querySelector('.move-axis').textContent = m.move;
        // Refused moves stay pressable (a tap shows why), marked.
        b.classList.toggle('illegal', !m.legal);
        b.setAttribute('aria-label', `${m.view}: ${m.move}${m.legal ? '' : ` (${m.reason})`}`);
        b.title = m.legal ? `move the block one cell along ${m.move}` : m.reason;
      }
      const cells = grid.cells.join('×');
      const cell = grid.cell_size.join('×');
      const where = grid.block ? `block ${grid.block_text} (overview voxels, native resolution)` : 'no block shown yet';
      $('gridInfo').textContent = `${cells} cells of ${cell} voxels; point ${grid.describe}; ${where}`;
      const note = $('gridNote');
      note.textContent = grid.note;
      note.classList.toggle('refused', !!grid.refused);
    }

    // The last block as a box over the 3D view while the overview shows.
    function drawOverlay() {
      const dpr = window.devicePixelRatio || 1;
      const W = canvas.clientWidth, H = canvas.clientHeight;
      Object.assign(overlay.style, {
        left: `${canvas.offsetLeft + canvas.clientLeft}px`, top: `${canvas.offsetTop + canvas.clientTop}px`,
        width: `${W}px`, height: `${H}px`,
      });
      const bw = Math.max(1, Math.round(W * dpr)), bh = Math.max(1, Math.round(H * dpr));
      if (overlay.width !== bw || overlay.height !== bh) { overlay.width = bw; overlay.height = bh; }
      const ctx = overlay.getContext('2d');
      ctx.setTransform(1, 0, 0, 1, 0, 0);
      ctx.clearRect(0, 0, bw, bh);
      if (!grid.has_volume || !grid.block || grid.active) return;
      if (explore.showing_region) return;  // a region is shown: its own view
      const pj = JSON.parse(api.projection(canvas.width, canvas.height) || '{}');
      if (!pj.mvp) return;
      const m = pj.mvp;
      const project = (v) => {
        const p = v.map((x, a) => x * pj.spacing[a] + pj.offset[a]);
        const cx = m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12];
        const cy = m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13];
        const cw = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15];
        if (!(cw > 1e-9)) return null;
        return [(cx / cw + 1) / 2 * bw, (1 - cy / cw) / 2 * bh];
      };
      const b = grid.block.begin, e = grid.block.end;
      ctx.beginPath();
      for (let axis = 0; axis < 3; axis++) {
        const u = (axis + 1) % 3, w = (axis + 2) % 3;
        for (let i = 0; i < 4; i++) {
          const a = [0, 0, 0];
          a[u] = i & 1 ? e[u] : b[u];
          a[w] = i & 2 ? e[w] : b[w];
          const z = a.slice();
          a[axis] = b[axis];
          z[axis] = e[axis];
          const pa = project(a), pb = project(z);
          if (!pa || !pb) continue;
          ctx.moveTo(pa[0], pa[1]);
          ctx.lineTo(pb[0], pb[1]);
        }
      }
      ctx.strokeStyle = COLOR;
      ctx.lineWidth = 2.5 * dpr;
      ctx.setLineDash([8 * dpr, 5 * dpr]);
      ctx.stroke();
    }

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
      updatePad();
      await requestRender();
      return true;
    }

    async function leave() {
      if (!api.overview()) { showError(api.lastError()); return false; }
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
      if (e.key === 'g' || e.key === 'G') {
        if (!grid.has_volume) return;
        refresh().active ? leave() : enter();
        e.preventDefault();
      } else if (e.key in KEYS && refresh().active && !(t && t.classList && t.classList.contains('slice-overlay'))) {
        // (A focused slice view keeps the arrows for its slices.)
        move(KEYS[e.key]);
        e.preventDefault();
      }
    });
    new ResizeObserver(() => drawOverlay()).observe(canvas);

    const testApi = {
      state: () => refresh(),
      enter: async (cell) => { if (cell !== undefined) $('gridCell').value = cell; return enter(); },
      move,
      leave,
      // RGBA pixels of the grid's overlay over the 3D view (the block's box).
      overlayPixels: () => Array.from(overlay.getContext('2d').getImageData(0, 0, overlay.width, overlay.height).data),
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
