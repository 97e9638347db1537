// The page's overlay: a second volume (an atlas, a segmentation, a PET or
// statistical map) fused into the 3D view's ray march (docs/fusion.md). The
// "Overlay" panel (an "Add overlay…" picker, labels and their table or a
// colour map, alpha, window, remove), the offer made when a second file is
// dropped while a volume is open (replace it, or add it as the overlay),
// and the overlay's part of the crosshair's readout (value, label name).
// The session holds the logic (frontends/web/src/WebOverlay.h); this file
// marshals the controls to its C API and shows what comes back.

const TABLE_FILE = /\.(txt|lut|ctbl)$/i;  // label tables dropped beside an atlas
const COLOUR_MAPS = ['hot', 'grey', 'mr-default', 'ct-bone', 'bench'];

const PANEL = `
  <legend>Overlay (a second volume)</legend>
  <label class="button" title="A second volume over this one, aligned by world coordinates (an atlas, a segmentation, PET, a statistical map); read in this browser, never uploaded">
    Add overlay…<input type="file" id="overlayFile" multiple
      accept=".gz,.nii,.hdr,.img,.nrrd,.nhdr,.raw,.mha,.mhd,.zraw,.vti,.txt,.lut,.ctbl,application/gzip"></label>
  <label><input type="checkbox" id="overlayLabels"> label volume (atlas: region colours and names)</label>
  <label>label table <input type="file" id="overlayTable" accept=".json,.txt,.lut,.ctbl"></label>
  <label>colour map <select id="overlayTf" aria-label="Overlay colour map"></select></label>
  <label>alpha <input type="range" id="overlayAlpha" min="0.05" max="1" step="0.05" value="0.5"></label>
  <div class="row"><label>window <input type="number" id="overlayLo" step="any" aria-label="Overlay window low" style="width:6em"></label>
    <label>to <input type="number" id="overlayHi" step="any" aria-label="Overlay window high" style="width:6em"></label></div>
  <button id="overlayRemove" disabled>Remove overlay</button>
  <div class="note" id="overlayInfo" role="status" aria-live="polite"></div>`;

const PROMPT = `
  <p id="overlayPromptText"></p>
  <div class="row">
    <button id="overlayPromptAdd">Add as overlay</button>
    <button id="overlayPromptReplace">Replace</button>
    <button id="overlayPromptCancel">Cancel</button>
  </div>`;

// opts: { M, webgl (1 or 2), state() (the page's last state), openFiles(files)
// (replaces the volume), requestRender(), showError(m), clearError() }.
export function attachOverlayPanel(opts) {
  const { M } = opts;
  const $ = (id) => document.getElementById(id);
  const c = (name, ret, args) => M.cwrap(name, ret, args);
  const api = {
    lastError: c('tessera_last_error', 'string', []),
    addFile: c('tessera_add_file', null, ['string', 'number', 'number']),
    clearFiles: c('tessera_clear_files', null, []),
    open: c('tessera_overlay_open', 'number', ['number', 'string', 'string', 'string', 'number', 'number', 'number']),
    restyle: c('tessera_overlay_restyle', 'number', ['number', 'string', 'string', 'string', 'number', 'number', 'number']),
    clear: c('tessera_overlay_clear', null, []),
    json: c('tessera_overlay_json', 'string', []),
    probe: c('tessera_probe_json', 'string', ['number', 'number', 'number']),
    voxelAtWorld: c('tessera_voxel_at_world', 'string', ['number', 'number', 'number']),
  };

  const panel = $('overlay-controls');
  panel.innerHTML = PANEL;
  for (const n of COLOUR_MAPS) {
    const o = document.createElement('option');
    o.value = n;
    o.textContent = n;
    $('overlayTf').appendChild(o);
  }
  const prompt = document.createElement('div');
  prompt.id = 'overlay-prompt';
  prompt.setAttribute('role', 'dialog');
  prompt.setAttribute('aria-label', 'A second file dropped');
  prompt.hidden = true;
  prompt.innerHTML = PROMPT;
  prompt.style.cssText = 'position:fixed;left:50%;top:30%;transform:translateX(-50%);z-index:10;' +
    'background:#222;color:#eee;border:1px solid #888;padding:0.8em 1.2em;border-radius:6px';
  document.body.appendChild(prompt);

  let table = { text: '', name: '' };  // the label table's text, handed over with the options
  let info = { open: false };

  // The controls as the C API's arguments.
  function options() {
    const lo = parseFloat($('overlayLo').value);
    const hi = parseFloat($('overlayHi').value);
    const windowGiven = Number.isFinite(lo) && Number.isFinite(hi);
    return [$('overlayLabels').checked ? 1 : 0, table.text, table.name, $('overlayTf').value,
      +$('overlayAlpha').value, windowGiven ? lo : NaN, windowGiven ? hi : NaN];
  }

  function refresh() {
    info = JSON.parse(api.json());
    $('overlayRemove').disabled = !info.open;
    if (!info.open) {
      $('overlayInfo').textContent = opts.webgl < 2 ? 'an overlay needs WebGL 2 (3D textures)' : 'no overlay';
      return info;
    }
    $('overlayLabels').checked = info.labels;
    $('overlayAlpha').value = info.alpha;
    const what = info.labels ? `labels (${info.labels_table.length} named${info.label_table_name ? `, ${info.label_table_name}` : ''})` : `colour map ${info.tf}`;
    $('overlayInfo').textContent = `${info.file} ${info.dims.join('×')}: ${what}, alpha ${(+info.alpha).toFixed(2)}` +
      (info.note ? ` — ${info.note}` : '') + (info.fusion_note ? ` — ${info.fusion_note}` : '');
    return info;
  }

  async function handOver(files) {
    api.clearFiles();
    for (const f of files) {
      const bytes = new Uint8Array(await f.arrayBuffer());
      const p = M._malloc(Math.max(1, bytes.length));
      if (!p) throw new Error(`${f.name}: cannot allocate ${bytes.length} bytes for the file`);
      M.HEAPU8.set(bytes, p);
      api.addFile(f.name, p, bytes.length);  // owned by the module from here on
    }
  }

  // Opens `files` (a volume and what it names; a label table beside it turns
  // labels on with that table) as the overlay; false with the error shown.
  async function add(fileList) {
    const files = Array.from(fileList);
    const tables = files.filter((f) => TABLE_FILE.test(f.name));
    const volumes = files.filter((f) => !TABLE_FILE.test(f.name));
    if (volumes.length === 0) {
      opts.showError('no overlay volume among the files (only a label table)');
      return false;
    }
    if (tables.length) {
      table = { text: await tables[0].text(), name: tables[0].name };
      $('overlayLabels').checked = true;
    }
    await handOver(volumes);
    if (!api.open(...options())) {
      opts.showError(`overlay: ${api.lastError()}`);
      refresh();
      return false;
    }
    opts.clearError();
    refresh();
    await opts.requestRender();
    window.dispatchEvent(new Event('tessera-overlay'));  // the crosshair's readout follows
    return true;
  }

  async function restyle() {
    if (!info.open) return;
    if (!api.restyle(...options())) opts.showError(`overlay: ${api.lastError()}`);
    else opts.clearError();
    refresh();
    await opts.requestRender();
    window.dispatchEvent(new Event('tessera-overlay'));
  }

  async function remove() {
    api.clear();
    refresh();
    await opts.requestRender();
    window.dispatchEvent(new Event('tessera-overlay'));
  }

  // A file dropped while a volume from a file is open: the offer (resolves
  // with 'overlay', 'replace' or 'cancel' once chosen and done).
  let pending = null;
  function offer(fileList) {
    const files = Array.from(fileList);
    const s = opts.state();
    if (!s.has_volume || String(s.name || '').startsWith('gen:')) return opts.openFiles(files).then(() => 'replace');
    const names = files.map((f) => f.name).join(', ');
    $('overlayPromptText').textContent = `${s.name} is open. ${names}: add it over ${s.name} as an overlay, or replace ${s.name}?`;
    $('overlayPromptAdd').disabled = opts.webgl < 2;
    $('overlayPromptAdd').title = opts.webgl < 2 ? 'an overlay needs WebGL 2 (3D textures)' : '';
    prompt.hidden = false;
    return new Promise((resolve) => {
      pending = { files, resolve };
    });
  }
  async function choose(what) {
    prompt.hidden = true;
    const p = pending;
    pending = null;
    if (!p) return;
    if (what === 'overlay') await add(p.files);
    else if (what === 'replace') await opts.openFiles(p.files);
    p.resolve(what);
  }
  $('overlayPromptAdd').addEventListener('click', () => choose('overlay'));
  $('overlayPromptReplace').addEventListener('click', () => choose('replace'));
  $('overlayPromptCancel').addEventListener('click', () => choose('cancel'));

  $('overlayFile').addEventListener('change', async (e) => {
    const files = Array.from(e.target.files);
    e.target.value = '';
    if (files.length) await add(files);
  });
  $('overlayTable').addEventListener('change', async (e) => {
    const f = e.target.files[0];
    if (!f) return;
    table = { text: await f.text(), name: f.name };
    $('overlayLabels').checked = true;
    await restyle();
  });
  for (const id of ['overlayLabels', 'overlayTf', 'overlayLo', 'overlayHi']) $(id).addEventListener('change', restyle);
  $('overlayAlpha').addEventListener('input', restyle);
  $('overlayRemove').addEventListener('click', remove);
  if (opts.webgl < 2) {
    $('overlayFile').disabled = true;
    $('overlayFile').parentElement.title = 'an overlay needs WebGL 2 (3D textures); this page runs on WebGL 1';
  }
  refresh();

  // The overlay's part of the crosshair's readout at voxel (x, y, z) of the
  // slice views: '' without an overlay, else " · overlay aal.nii.gz: 58 Postcentral_R".
  function crosshairText(voxel) {
    if (!info.open) return '';
    const p = JSON.parse(api.probe(voxel[0], voxel[1], voxel[2]));
    if (!p || !p.overlay_text) return '';
    return ` · overlay ${info.file}: ${p.overlay_text}`;
  }

  return {
    add, offer, remove, refresh, crosshairText,
    // For tests: the probe at a voxel, and the voxel at a world position (mm).
    testApi: {
      info: () => refresh(),
      probe: (x, y, z) => JSON.parse(api.probe(x, y, z)),
      voxelAtWorld: (x, y, z) => JSON.parse(api.voxelAtWorld(x, y, z)),
      promptShown: () => !prompt.hidden,
      promptText: () => $('overlayPromptText').textContent,
      choose,
      setOptions: async ({ labels, tf, alpha, lo, hi } = {}) => {
        if (labels !== undefined) $('overlayLabels').checked = labels;
        if (tf !== undefined) $('overlayTf').value = tf;
        if (alpha !== undefined) $('overlayAlpha').value = alpha;
        if (lo !== undefined) $('overlayLo').value = lo;
        if (hi !== undefined) $('overlayHi').value = hi;
        await restyle();
        return refresh();
      },
    },
  };
}
