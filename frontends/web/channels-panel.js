// The Channels panel (docs/channels.md): an OME-Zarr store with several
// channels is shown with all of them together. Its channels are read
// through the store's own fetch() storage (frontends/web/zarr-url.js fetches
// the keys the module wants), and every control marshals to one
// session::ChannelView call (frontends/web/src/WebExportsChannels.cpp): a
// visibility toggle, a colour swatch, the window in stored units per
// channel, and the mode. No state is kept here but what the module reports.
(function () {
  const hex = (c) => '#' + c.map((v) => Math.round(v * 255).toString(16).padStart(2, '0')).join('');
  const rgb = (h) => [1, 3, 5].map((i) => parseInt(h.slice(i, i + 2), 16) / 255);

  // `zarr`: the open store (zarr-url.js); `ui`: {requestRender, showError,
  // clearError, status}. Resolves to the panel, or null when the store has
  // one channel (or its channels could not be read: the error is shown).
  async function attach(M, zarr, ui) {
    const c = (name, ret, args) => M.cwrap(name, ret, args);
    const api = {
      lastError: c('tessera_last_error', 'string', []),
      openStep: c('tessera_channels_open_step', 'number', []),
      json: c('tessera_channels_json', 'string', []),
      setVisible: c('tessera_channels_set_visible', 'number', ['number', 'number']),
      setColor: c('tessera_channels_set_color', 'number', ['number', 'number', 'number', 'number']),
      setWindow: c('tessera_channels_set_window', 'number', ['number', 'number', 'number']),
      setMode: c('tessera_channels_set_mode', 'number', ['string']),
      frame: c('tessera_channels_frame', 'number', ['number', 'number']),
      close: c('tessera_channels_close', null, []),
    };
    for (;;) {
      const state = api.openStep();
      if (state === 1) break;
      if (state === 2) return null;
      const keys = state < 0 ? [] : await zarr.fetchWanted();
      if (keys.length === 0) {
        ui.showError(`channels: ${api.lastError() || 'the channels could not be read'}`);
        return null;
      }
    }
    const $ = (id) => document.getElementById(id);
    const fieldset = $('channels');
    const list = $('channel-list');
    let open = true;

    // Each control's call; a refused value shows the module's message and
    // the list shows the channels as they are.
    function call(ok) {
      if (ok) ui.clearError();
      else ui.showError(`channels: ${api.lastError()}`);
      draw();
      ui.requestRender();
    }

    function row(ch, i) {
      const r = document.createElement('div');
      r.className = 'row channel';
      r.innerHTML = '<input type="checkbox" class="visible"><input type="color" class="swatch">' +
        '<span class="label"></span><input type="number" class="lo" step="any">' +
        '<input type="number" class="hi" step="any">';
      const [visible, swatch, label, lo, hi] = r.children;
      visible.checked = ch.visible;
      visible.setAttribute('aria-label', `show ${ch.label}`);
      swatch.value = hex(ch.color);
      swatch.setAttribute('aria-label', `${ch.label} colour`);
      label.textContent = ch.label;
      lo.value = String(ch.window[0]);
      hi.value = String(ch.window[1]);
      lo.title = hi.title = `window (stored values ${ch.range[0]}..${ch.range[1]})`;
      lo.setAttribute('aria-label', `${ch.label} window low`);
      hi.setAttribute('aria-label', `${ch.label} window high`);
      visible.addEventListener('change', () => call(api.setVisible(i, visible.checked ? 1 : 0)));
      swatch.addEventListener('input', () => call(api.setColor(i, ...rgb(swatch.value))));
      const windowChanged = () => call(api.setWindow(i, parseFloat(lo.value), parseFloat(hi.value)));
      lo.addEventListener('change', windowChanged);
      hi.addEventListener('change', windowChanged);
      return r;
    }

    function draw() {
      const s = JSON.parse(api.json());
      if (!s.open) return;
      list.replaceChildren(...s.channels.map(row));
      $('channelMode').value = s.mode;
    }

    $('channelMode').onchange = () => call(api.setMode($('channelMode').value));
    draw();
    fieldset.hidden = false;

    function close() {
      if (!open) return;
      open = false;
      api.close();
      fieldset.hidden = true;
      list.replaceChildren();
    }

    return {
      // The channels are drawn (the store is open and no region is shown).
      active: () => {
        // Another volume replaced the store (not: it is being opened again
        // after a WebGL context loss; the module shows the channels again).
        if (open && !zarr.active() && !zarr.showingRegion() && !zarr.reopening()) close();
        return open && zarr.active();
      },
      // A frame on the canvas; its time in ms, or -1 on error.
      frame: (width, height) => {
        const t = performance.now();
        if (!api.frame(width, height)) {
          ui.showError(`channels: ${api.lastError()}`);
          return -1;
        }
        return performance.now() - t;
      },
      close,
      state: () => JSON.parse(api.json()),
    };
  }

  window.TesseraChannels = { attach };
})();
