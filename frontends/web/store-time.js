// An OME-Zarr store's t axis (frontends/web/src/WebSessionTime.cpp): a store
// whose level 0 fits the page's host budget plays back as a dropped 4-D
// NIfTI does (app.js's Time panel; the playback logic is the session's,
// session/TimeSeries.h); a larger one, or any with ?layout=bricks, plays
// over bricks, the store view drawing each time point through bricks of
// its own. Here only the keys the session asks for — the first time
// point's chunks, then those of the time points ahead — are fetched
// between frames through the store's own fetch() (zarr-url.js); the same
// for the channels of a store with a t axis (fetchAhead).
'use strict';

(function () {
  // `zarr`: the open store (zarr-url.js); `ui`: {showError}; `bricks`:
  // over bricks even when level 0 fits in core. Resolves to the store's
  // series ({bricks, stop()}: `bricks` when the store view draws it), or
  // null when the store has one time point or its first time point could
  // not be read (the error is shown).
  async function attach(M, zarr, ui, { bricks = false } = {}) {
    const openStep = M.cwrap('tessera_store_time_open_step', 'number', ['number']);
    const lastError = M.cwrap('tessera_last_error', 'string', []);
    let state = 0;
    for (;;) {
      state = openStep(bricks ? 1 : 0);
      if (state === 1 || state === 3) break;
      if (state === 2) return null;
      const keys = state < 0 ? [] : await zarr.fetchWanted();
      if (keys.length === 0) {
        ui.showError(`time series: ${lastError() || 'its first time point could not be read'}`);
        return null;
      }
    }
    return { ...fetchAhead(zarr), bricks: state === 3 };
  }

  // The keys of the time points ahead, as playback asks for them (a
  // frame's pump lists them), until the store is closed or stop(); also
  // while a region or grid block of it is shown (the session reads it again
  // from each time point once its chunks, asked for here, have arrived) and
  // while the store is opened again after a lost WebGL context (the
  // series plays on from the time point it showed).
  function fetchAhead(zarr) {
    let fetching = true;
    (async () => {
      while (fetching && (zarr.active() || zarr.showingRegion() || zarr.reopening())) {
        const keys = await zarr.fetchWanted();
        if (keys.length === 0) await new Promise((r) => setTimeout(r, 8));
      }
    })();
    return { stop: () => { fetching = false; } };
  }

  window.TesseraStoreTime = { attach, fetchAhead };
})();
