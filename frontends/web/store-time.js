// An OME-Zarr store's t axis (frontends/web/src/WebSessionTime.cpp): a store
// whose level 0 fits the page's host budget plays back as a dropped 4-D
// NIfTI does (app.js's Time panel; the playback logic is the session's,
// session/TimeSeries.h). Here only the keys the session asks for — the
// first time point's chunks, then those of the time points ahead — are
// fetched between frames through the store's own fetch() (zarr-url.js).
'use strict';

(function () {
  // `zarr`: the open store (zarr-url.js); `ui`: {showError}. Resolves to
  // the store's series ({stop()}), or null when the store is not played
  // (one time point, or too large: it streams bricks at its first time
  // point) or its first time point could not be read (the error is shown).
  async function attach(M, zarr, ui) {
    const openStep = M.cwrap('tessera_store_time_open_step', 'number', []);
    const lastError = M.cwrap('tessera_last_error', 'string', []);
    for (;;) {
      const state = openStep();
      if (state === 1) break;
      if (state === 2) return null;
      const keys = state < 0 ? [] : await zarr.fetchWanted();
      if (keys.length === 0) {
        ui.showError(`time series: ${lastError() || 'its first time point could not be read'}`);
        return null;
      }
    }
    // The keys of the time points ahead, as playback asks for them (a
    // frame's pump lists them), until the store is closed.
    let fetching = true;
    (async () => {
      while (fetching && zarr.active()) {
        const keys = await zarr.fetchWanted();
        if (keys.length === 0) await new Promise((r) => setTimeout(r, 8));
      }
    })();
    return { stop: () => { fetching = false; } };
  }

  window.TesseraStoreTime = { attach };
})();
