// OME-Zarr stores in the page (?url=http://host/NAME.ome.zarr): the store is
// read with fetch(), key by key, as the wasm side asks for keys
// (frontends/web/src/ZarrFetchStorage.cpp), and rendered coarse to fine through the
// bricks layout (frontends/web/src/ZarrStoreView.cpp): first the coarsest level, then
// finer bricks as their chunks arrive, nearest first. Nothing here waits on
// the network inside a frame: fetches run beside the animation frames, and
// each frame uploads what has arrived.
//
// Fetching as the native HTTP storage does (io/HttpStorage.h): a few
// requests at a time, up to 4 attempts with back-off (100 ms doubling, with
// jitter) for network errors, timeouts, 5xx, 408 and 429, the body checked
// against Content-Length; a 404 is a missing key (a chunk reads as
// fill_value, as Zarr defines); a key that keeps failing is handed over as
// an error naming its URL (the coarser level stays on screen; it is fetched
// again later).
//
// Zarr v3 shards are read with Range requests, as the native reader reads
// them: the module asks for "KEY#bytes=A-B" (an inner chunk) or
// "KEY#bytes=-N" (an index at the shard's end), never the whole shard. A
// server that ignores Range (200 with the whole body) still works: from its
// first such answer on, each shard is fetched whole once, kept a while
// (WHOLE_BUDGET) and the ranges cut out of it here.
'use strict';

(function () {
  const CONNECTIONS = 6;
  const ATTEMPTS = 4;
  const TIMEOUT_MS = 60000;
  // Whole shards held for a server that ignores Range.
  const WHOLE_BUDGET = 64 * 1048576;

  // A URL whose path ends in .zarr (NAME.zarr, NAME.ome.zarr, with or
  // without a trailing slash).
  function isStoreUrl(u) {
    try {
      return /\.zarr\/?$/i.test(new URL(u, location.href).pathname);
    } catch {
      return false;
    }
  }

  const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
  const retryable = (status) => status >= 500 || status === 408 || status === 429;

  // {bytes, status, total} or {missing: true}; throws an Error naming the
  // URL (and the range). `range`: a Range header's value ("bytes=0-99"),
  // or none; `total` is the value's size a 206 states (Content-Range), or
  // null.
  async function fetchKey(url, range) {
    const label = range ? `${url} (${range})` : url;
    let why = '';
    for (let attempt = 1; attempt <= ATTEMPTS; attempt++) {
      if (attempt > 1) await sleep(100 * 2 ** (attempt - 2) * (0.75 + 0.5 * Math.random()));
      const abort = new AbortController();
      const timer = setTimeout(() => abort.abort(), TIMEOUT_MS);
      try {
        const r = await fetch(url, { signal: abort.signal, headers: range ? { Range: range } : {} });
        if (r.status === 404) return { missing: true };
        if (r.status === 416) {
          why = 'HTTP 416: the range lies outside the value (a shard index that lies about its chunks?)';
          break;
        }
        if (!r.ok) {
          why = `HTTP ${r.status} ${r.statusText}`.trim();
          if (retryable(r.status)) continue;
          break;
        }
        const bytes = new Uint8Array(await r.arrayBuffer());
        const declared = r.headers.get('Content-Length');
        if (declared !== null && !r.headers.get('Content-Encoding') && parseInt(declared, 10) !== bytes.length) {
          why = `truncated body (${bytes.length} of ${declared} bytes)`;
          continue;
        }
        const m = /\/(\d+)\s*$/.exec(r.headers.get('Content-Range') || '');
        return { bytes, status: r.status, total: m ? parseInt(m[1], 10) : null };
      } catch (e) {
        why = e.name === 'AbortError' ? `no answer in ${TIMEOUT_MS / 1000} s`
          : `cannot fetch it (${e.message}): the server is unreachable, or it does not let this page read it (CORS)`;
      } finally {
        clearTimeout(timer);
      }
    }
    throw new Error(`${label}: ${why} (after at most ${ATTEMPTS} attempts)`);
  }

  // crc32c (Castagnoli) of bytes, as Zarr v3's crc32c codec writes it.
  const CRC32C = (() => {
    const t = new Uint32Array(256);
    for (let n = 0; n < 256; n++) {
      let c = n;
      for (let k = 0; k < 8; k++) c = c & 1 ? 0x82f63b78 ^ (c >>> 1) : c >>> 1;
      t[n] = c >>> 0;
    }
    return t;
  })();
  function crc32c(bytes) {
    let c = 0xffffffff;
    for (let i = 0; i < bytes.length; i++) c = CRC32C[(c ^ bytes[i]) & 0xff] ^ (c >>> 8);
    return (c ^ 0xffffffff) >>> 0;
  }

  // A v3 array's zarr.json as the page decodes its chunks: the compressor
  // (the first bytes-to-bytes codec; only crc32c may follow it), the
  // decoded chunk's bytes, and for a sharded array its index's place and
  // size. null: nothing for the page to decode.
  const V3_SIZES = { bool: 1, int8: 1, uint8: 1, int16: 2, uint16: 2, float16: 2, int32: 4, uint32: 4,
    float32: 4, int64: 8, uint64: 8, float64: 8 };
  function v3Array(meta) {
    if (!meta || meta.node_type !== 'array' || !Array.isArray(meta.codecs)) return null;
    let codecs = meta.codecs;
    let chunk = meta.chunk_grid && meta.chunk_grid.configuration && meta.chunk_grid.configuration.chunk_shape;
    let shard = null;
    const sharding = codecs.find((c) => c && c.name === 'sharding_indexed');
    if (sharding) {
      const cfg = sharding.configuration || {};
      if (!Array.isArray(cfg.chunk_shape) || !Array.isArray(chunk) || !Array.isArray(cfg.codecs)) return null;
      const n = chunk.reduce((k, c, i) => k * Math.ceil(c / cfg.chunk_shape[i]), 1);
      const crc = (cfg.index_codecs || []).some((c) => c && c.name === 'crc32c');
      shard = { atEnd: (cfg.index_location || 'end') === 'end', indexBytes: n * 16 + (crc ? 4 : 0) };
      chunk = cfg.chunk_shape;
      codecs = cfg.codecs;
    }
    const at = codecs.findIndex((c) => c && c.name === 'bytes');
    if (at < 0 || !Array.isArray(chunk)) return null;
    const chain = codecs.slice(at + 1).map((c) => c && c.name);
    const id = chain[0];
    if (!['gzip', 'zstd', 'blosc'].includes(id) || chain.slice(1).some((c) => c !== 'crc32c')) {
      return { shard, id: null };
    }
    const size = V3_SIZES[meta.data_type] || 0;
    return { shard, id, crcs: chain.length - 1, chunkBytes: chunk.reduce((k, c) => k * c, size) };
  }
  // Whether "A-B" or "-N" of a sharded array's shard is its index.
  const isIndexRange = (shard, range) => (shard.atEnd ? range.startsWith('-')
    : range === `0-${shard.indexBytes - 1}`);

  // Chunks are decoded here as they arrive, once each (a brick read with
  // its apron touches up to 27 chunks: decoding them in every read cost
  // most of the refinement): zlib and gzip with the page's pako, blosc and
  // zstd — Debian's libraries are native only — with numcodecs' WebAssembly
  // builds of them (npm numcodecs, MIT, pinned in frontends/web/package-lock.json,
  // copied into the site's numcodecs/), loaded when a store needs them. The
  // wasm side checks each decoded chunk's size.
  const PAGE_CODECS = new Set(['zlib', 'gzip', 'blosc', 'zstd']);
  const codecModules = {};
  const codecErrors = {};
  // Inflated here, on the page's thread, in slices of about a millisecond
  // run in the page's idle time (requestIdleCallback: after an animation
  // frame's work, before the next), so that no decode holds up input: a
  // 64³ chunk inflated whole took 3 ms, and up to 100 ms on a loaded
  // machine, in one task; input that arrived meanwhile waited for it. A
  // worker was tried and measured worse on a 2-core machine: its inflating
  // competed with the GPU process for the cores during the preview that
  // answers input (previews 76-89 ms against 19-38 ms in the page).
  const SLICE_MS = 1;
  let sliceBytes = 2048;  // compressed bytes per push, fed back to about SLICE_MS
  const idleSlice = (f) => (window.requestIdleCallback
    ? window.requestIdleCallback(f, { timeout: 250 }) : setTimeout(() => f({ timeRemaining: () => 0 }), 0));
  // Each idle task's start and length (performance.now()), for the tests.
  const decodeTasks = [];
  const noteTask = (at) => {
    decodeTasks.push({ at, ms: performance.now() - at });
    if (decodeTasks.length > 4000) decodeTasks.splice(0, 1000);
  };
  // Resolves to {raw, busyMs, sliceMs (the longest slice), slices}.
  function inflateSliced(bytes) {
    const inflater = new globalThis.pako.Inflate();
    let pos = 0;
    const out = { busyMs: 0, sliceMs: 0, slices: 0 };
    return new Promise((resolve, reject) => {
      const step = (deadline) => {
        const taskAt = performance.now();
        do {
          const at = performance.now();
          const end = Math.min(bytes.length, pos + sliceBytes);
          inflater.push(bytes.subarray(pos, end), end === bytes.length);
          pos = end;
          const ms = performance.now() - at;
          out.busyMs += ms;
          out.sliceMs = Math.max(out.sliceMs, ms);
          out.slices++;
          if (ms > SLICE_MS) sliceBytes = Math.max(256, sliceBytes >> 1);
          else if (ms < SLICE_MS / 4) sliceBytes = Math.min(1 << 16, sliceBytes << 1);
          if (inflater.err) {
            reject(new Error(inflater.msg || `zlib error ${inflater.err}`));
            return;
          }
        } while (pos < bytes.length && deadline.timeRemaining() > SLICE_MS);
        noteTask(taskAt);
        if (pos < bytes.length) idleSlice(step);
        else if (!inflater.ended || !inflater.result) reject(new Error('truncated stream'));
        else resolve({ raw: inflater.result, ...out });
      };
      idleSlice(step);
    });
  }
  // Other codecs (numcodecs' wasm builds) decode a chunk in one call: in
  // idle time too, whole.
  const inIdleTime = (decode) => (bytes) => new Promise((resolve, reject) => idleSlice(() => {
    const at = performance.now();
    Promise.resolve(decode(bytes)).then((raw) => {
      const ms = performance.now() - at;
      noteTask(at);
      resolve({ raw, busyMs: ms, sliceMs: ms, slices: 1 });
    }, reject);
  }));
  const pakoCodec = { fromConfig: () => ({ decode: inflateSliced }) };
  function loadCodec(id) {
    if (id === 'zlib' || id === 'gzip') return Promise.resolve(globalThis.pako ? pakoCodec : null);
    if (!codecModules[id]) {
      codecModules[id] = import(`./numcodecs/${id}.js`).then((m) => m.default, (e) => {
        codecErrors[id] = e.message;
        return null;
      });
    }
    return codecModules[id];
  }

  // Bytes per chunk of a .zarray (shape of a chunk x the dtype's size).
  function chunkBytesOf(meta) {
    const size = parseInt(String(meta.dtype).replace(/^[<>|=]?[a-zA-Z]/, ''), 10) || 1;
    return meta.chunks.reduce((n, c) => n * c, size);
  }

  // The store view of one page: M is the emscripten module; ui has
  // status(text), progress(value, max) (max 0 hides it), showError(text),
  // clearError().
  function create(M, ui) {
    const c = (name, ret, args) => M.cwrap(name, ret, args);
    // The status line and progress of a frame: the last frame's (refined,
    // or no more to come) at once, the others' at most every STATUS_MS,
    // in the task that drew them. Each change repaints the page beside the
    // canvas; written with every preview, a wheel spun fast (a turn 25 ms
    // apart) had its worst input-to-frame time at 31-57 ms through the X
    // server, and written by a timer of its own, the drag's moves met the
    // GPU process busy with the extra frame (worst 22-27 ms against 8-13).
    // Any other status comes at once and lets the next frame's through.
    const STATUS_MS = 250;
    let frameLineAt = -Infinity;
    const frameStatus = (text, progress, last) => {
      const now = performance.now();
      if (!last && now - frameLineAt < STATUS_MS) return;
      frameLineAt = now;
      ui.status(text);
      ui.progress(...progress);
    };
    const status = (text) => {
      frameLineAt = -Infinity;  // the next frame's line at once
      ui.status(text);
    };
    const api = {
      begin: c('tessera_zarr_begin', 'number', ['string']),
      openStep: c('tessera_zarr_open_step', 'number', []),
      wanted: c('tessera_zarr_wanted', 'string', []),
      holds: c('tessera_zarr_holds', 'number', ['string']),
      put: c('tessera_zarr_put', null, ['string', 'number', 'number']),
      putMissing: c('tessera_zarr_put_missing', null, ['string']),
      putFailed: c('tessera_zarr_put_failed', null, ['string', 'string']),
      putRange: c('tessera_zarr_put_range', null, ['string', 'number', 'number', 'number', 'number']),
      frame: c('tessera_zarr_frame', 'string', ['number', 'number', 'number', 'number']),
      refine: c('tessera_zarr_refine', 'string', []),
      refining: c('tessera_zarr_refining', 'number', []),
      info: c('tessera_zarr_info', 'string', []),
      close: c('tessera_zarr_close', null, []),
      regionPrefetch: c('tessera_zarr_region_prefetch', 'number', Array(6).fill('number')),
      regionShow: c('tessera_zarr_region_show', 'number', Array(6).fill('number')),
      regionOverview: c('tessera_zarr_region_overview', null, []),
      regionShown: c('tessera_zarr_region_shown', 'number', []),
      lastError: c('tessera_last_error', 'string', []),
      pageDecodes: c('tessera_zarr_page_decodes', 'number', ['string']),
    };

    let base = '';
    let name = '';
    let open = false;
    let t0 = 0;
    let queue = [];          // keys wanted and not started, most urgent first
    const inFlight = new Set();
    let idleWaiters = [];
    let arrived = false;     // a key arrived since the last frame
    let last = null;         // the last frame's JSON
    let lastFrameAt = 0;
    let bricksRead = 0;
    let regionShown = false;  // the viewer shows a region read from the store
    let pinned = [];          // a region's chunk keys not arrived yet: fetched first
    const arrays = new Map();  // array path ('' for a root array) -> {id, codec, chunkBytes, crcs, shard}
    let rangesIgnored = false;  // the server answered a Range request with the whole body
    const wholes = new Map();   // key -> Promise of its whole body ({bytes} or {missing}), oldest first
    const wholeSizes = new Map();  // key -> bytes of a whole body arrived
    let wholeBytes = 0;
    const record = { url: '', requests: 0, bytes: 0, timeline: [], calls: [], firstImageMs: null, completeMs: null,
      openMs: null, info: null, errors: [], decodes: [], tasks: [], rangeRequests: 0, wholeBodies: 0 };

    // `r`: {missing}, or {bytes} of a key, or of a range key {bytes, total,
    // decoded}.
    function put(key, r) {
      if (r.missing) {
        api.putMissing(key);
        return;
      }
      const p = M._malloc(Math.max(1, r.bytes.length));
      if (!p) {
        api.putFailed(key, `${base}/${key}: cannot allocate ${r.bytes.length} bytes for it`);
        return;
      }
      M.HEAPU8.set(r.bytes, p);
      // Owned (and freed) by the module.
      if (r.total !== undefined) api.putRange(key, p, r.bytes.length, r.total, r.decoded ? 1 : 0);
      else api.put(key, p, r.bytes.length);
    }

    const isMeta = (key) => /(^|\/)(\.zarray|\.zattrs|\.zgroup|zarr\.json)$/.test(key);

    // The whole value of `key` (a shard, for a server that ignores Range):
    // fetched once while it is held.
    function wholeBody(key, url) {
      let p = wholes.get(key);
      if (!p) {
        p = fetchKey(url).then((r) => {
          record.requests++;
          record.wholeBodies++;
          if (r.bytes) record.bytes += r.bytes.length;
          return r;
        });
        keepWhole(key, p);
      }
      return p;
    }
    function keepWhole(key, p) {
      wholes.set(key, p);
      p.then((r) => {
        if (wholes.get(key) !== p || !r.bytes) return;
        wholeSizes.set(key, r.bytes.length);
        wholeBytes += r.bytes.length;
        // The oldest out while over the budget; this one stays.
        for (const k of wholes.keys()) {
          if (wholeBytes <= WHOLE_BUDGET || k === key) break;
          wholes.delete(k);
          wholeBytes -= wholeSizes.get(k) || 0;
          wholeSizes.delete(k);
        }
      }, () => {
        if (wholes.get(key) === p) wholes.delete(key);
      });
    }

    // Bytes `range` ("A-B" or "-N") of `key`: {bytes, total} or {missing}.
    async function fetchRange(key, url, range) {
      const [a, b] = range.split('-');
      const length = a === '' ? parseInt(b, 10) : parseInt(b, 10) - parseInt(a, 10) + 1;
      let whole;
      if (!rangesIgnored && !wholes.has(key)) {
        const r = await fetchKey(url, `bytes=${range}`);
        record.requests++;
        record.rangeRequests++;
        if (r.missing) return r;
        record.bytes += r.bytes.length;
        if (r.status === 206) {
          if (r.total === null) {
            throw new Error(`${url} (bytes ${range}): HTTP 206 without a readable Content-Range total ` +
              '(a server on another origin must expose it: Access-Control-Expose-Headers: Content-Range)');
          }
          if (r.bytes.length !== length) {
            throw new Error(`${url}: range ${range} answered with ${r.bytes.length} bytes, expected ${length}`);
          }
          return { bytes: r.bytes, total: r.total };
        }
        // 200: the server ignores Range; the whole body is here.
        rangesIgnored = true;
        record.wholeBodies++;
        whole = r;
        if (!wholes.has(key)) keepWhole(key, Promise.resolve(r));
      } else {
        whole = await wholeBody(key, url);
        if (whole.missing) return whole;
      }
      const total = whole.bytes.length;
      const begin = a === '' ? total - length : parseInt(a, 10);
      if (begin < 0 || begin + length > total) {
        throw new Error(`${url}: bytes ${range} asked of a value of ${total} bytes`);
      }
      return { bytes: whole.bytes.slice(begin, begin + length), total };
    }

    async function start(key) {
      inFlight.add(key);
      const hash = key.indexOf('#bytes=');
      const path = hash < 0 ? key : key.slice(0, hash);
      const range = hash < 0 ? '' : key.slice(hash + '#bytes='.length);
      const url = `${base}/${path}`;
      try {
        let r;
        if (range) {
          r = await fetchRange(path, url, range);
          const array = r.bytes ? arrayOf(path) : null;
          if (array && array.shard && array.codec && !isIndexRange(array.shard, range)) {
            r = { ...(await decodeInPage(path, `${url} (bytes ${range})`, r)), total: r.total, decoded: true };
          }
        } else {
          r = await fetchKey(url);
          record.requests++;
          if (r.bytes) {
            record.bytes += r.bytes.length;
            if (key === '.zarray' || key.endsWith('/.zarray') || key === 'zarr.json' || key.endsWith('/zarr.json')) {
              await noteArray(key, r.bytes);
            } else if (!isMeta(key)) {
              const array = arrayOf(key);
              if (!array || !array.shard) r = await decodeInPage(key, url, r);
            }
            r = { bytes: r.bytes };
          }
        }
        const putAt = performance.now();
        if (base) put(key, r);
        record.tasks.push({ t: putAt - t0, put_ms: performance.now() - putAt, bytes: r.bytes ? r.bytes.length : 0 });
        if (record.tasks.length > 4000) record.tasks.splice(0, 1000);
      } catch (e) {
        record.errors.push(e.message);
        if (base) api.putFailed(key, e.message);
      } finally {
        inFlight.delete(key);
        pinned = pinned.filter((k) => k !== key);
        arrived = true;
        pump();
      }
    }

    // A .zarray's compressor, or a v3 zarr.json's (its shard's inner
    // chunks'): blosc and zstd chunks are decoded here when numcodecs loads
    // (the wasm side is told so), gzip and zlib with pako; otherwise its
    // decoder says that it cannot decode them. A v3 chunk's crc32c is
    // checked here before it is decoded.
    async function noteArray(key, bytes) {
      let meta;
      try {
        meta = JSON.parse(new TextDecoder().decode(bytes));
      } catch {
        return;  // the store reader reports it
      }
      const v3 = key === 'zarr.json' || key.endsWith('/zarr.json');
      const path = key.slice(0, key.length - (v3 ? 'zarr.json' : '.zarray').length).replace(/\/$/, '');
      const a3 = v3 ? v3Array(meta) : null;
      if (v3 && !a3) return;  // a group, or not read (the store reader says why)
      const id = v3 ? a3.id : meta && meta.compressor && meta.compressor.id;
      const Codec = PAGE_CODECS.has(id) && (v3 || Array.isArray(meta.chunks)) ? await loadCodec(id) : null;
      const codec = Codec ? Codec.fromConfig(v3 ? {} : meta.compressor) : null;
      arrays.set(path, { id, codec: codec && (Codec === pakoCodec ? codec : { decode: inIdleTime((b) => codec.decode(b)) }),
        chunkBytes: Codec ? (v3 ? a3.chunkBytes : chunkBytesOf(meta)) : 0, crcs: v3 ? a3.crcs || 0 : 0,
        shard: v3 ? a3.shard : null });
      if (Codec && base) api.pageDecodes(id);
    }

    // The array a chunk key belongs to: the longest array path before it.
    function arrayOf(key) {
      let best = null;
      let bestLength = -1;
      for (const [path, a] of arrays) {
        if ((path === '' || key.startsWith(`${path}/`)) && path.length > bestLength) {
          best = a;
          bestLength = path.length;
        }
      }
      return best;
    }

    async function decodeInPage(key, url, r) {
      const array = arrayOf(key);
      if (!array || !array.codec) return r;
      let raw;
      let stored = r.bytes;
      for (let k = 0; k < array.crcs; k++) {
        // crc32c codecs after the compressor: the last one applied first.
        if (stored.length < 4) throw new Error(`${url}: chunk of ${stored.length} bytes has no room for its crc32c`);
        const body = stored.subarray(0, stored.length - 4);
        const tail = stored.subarray(stored.length - 4);
        const want = (tail[0] | (tail[1] << 8) | (tail[2] << 16) | (tail[3] << 24)) >>> 0;
        const got = crc32c(body);
        if (got !== want) {
          throw new Error(`${url}: crc32c mismatch (stored ${want.toString(16).padStart(8, '0')}, ` +
            `computed ${got.toString(16).padStart(8, '0')})`);
        }
        stored = body;
      }
      const decodeAt = performance.now();
      try {
        const d = await array.codec.decode(stored);
        raw = d.raw;
        // busy: the decoder's own time; slice_ms: its longest task; ms: until done.
        record.decodes.push({ t: decodeAt - t0, ms: performance.now() - decodeAt, busy_ms: d.busyMs,
          slice_ms: d.sliceMs, slices: d.slices });
        if (record.decodes.length > 4000) record.decodes.splice(0, 1000);
      } catch (e) {
        throw new Error(`${url}: corrupt ${array.id} chunk (${e.message})`);
      }
      if (raw.length !== array.chunkBytes) {
        throw new Error(`${url}: ${array.id} chunk decoded to ${raw.length} bytes, expected ${array.chunkBytes}`);
      }
      return { bytes: raw };
    }

    function pump() {
      while (inFlight.size < CONNECTIONS && queue.length) {
        const key = queue.shift();
        if (base && api.holds(key)) {
          // Arrived since it was asked for (listed again while in flight):
          // never fetched twice.
          pinned = pinned.filter((k) => k !== key);
          continue;
        }
        start(key);
      }
      if (inFlight.size === 0 && queue.length === 0) {
        const w = idleWaiters;
        idleWaiters = [];
        w.forEach((f) => f());
      }
    }

    // The wasm side's wanted keys replace the queue (the view changed what
    // is urgent); keys being fetched stay in flight.
    function takeWanted() {
      const keys = JSON.parse(api.wanted());
      queue = [...new Set([...pinned, ...keys])].filter((k) => !inFlight.has(k));
      pump();
      return keys.length;
    }

    const idle = () => (inFlight.size === 0 && queue.length === 0 ? Promise.resolve()
      : new Promise((resolve) => idleWaiters.push(resolve)));

    // Metadata, then the coarsest level; true when the store is open.
    async function openStore(url) {
      close();
      const resolved = new URL(url, location.href).href.replace(/\/+$/, '');
      base = resolved;
      name = decodeURIComponent(resolved.split('/').pop() || 'store');
      Object.assign(record, { url: resolved, requests: 0, bytes: 0, timeline: [], calls: [], firstImageMs: null,
        completeMs: null, openMs: null, info: null, errors: [], decodes: [], tasks: [], rangeRequests: 0,
        wholeBodies: 0 });
      t0 = performance.now();
      status(`opening ${resolved}…`);
      ui.progress(0, 0);
      if (!api.begin(resolved)) {
        ui.showError(`${resolved}: ${api.lastError()}`);
        return false;
      }
      for (;;) {
        const state = api.openStep();
        if (state === 1) break;
        if (state < 0 || takeWanted() === 0) {
          const message = api.lastError() || 'the store could not be opened';
          ui.showError(message.includes(resolved) ? message : `${resolved}: ${message}`);
          close();
          return false;
        }
        status(`opening ${resolved}: ${record.requests} keys, ${(record.bytes / 1048576).toFixed(2)} MB`);
        await idle();
      }
      open = true;
      record.openMs = performance.now() - t0;
      record.info = JSON.parse(api.info());
      ui.clearError();
      return true;
    }

    // After the WebGL context was lost and restored (the module made the
    // store's view again on the new context: tessera_context_restored): its
    // atlas, page table and ray caster are built again, the coarsest level
    // and then the bricks read again from the chunks the module holds (only
    // those it let go are fetched again). A region or grid block the view
    // showed is shown again by the module (its chunks fetched like the
    // store's). Resolves to true when the store is open.
    let reopening = false;
    async function reopen() {
      if (!base) return false;
      reopening = true;
      try {
        return await reopenSteps();
      } finally {
        reopening = false;
      }
    }
    async function reopenSteps() {
      open = false;
      regionShown = false;
      last = null;
      bricksRead = 0;
      t0 = performance.now();
      const requestsBefore = record.requests;
      Object.assign(record, { firstImageMs: null, completeMs: null, timeline: [], calls: [],
        reopened: (record.reopened || 0) + 1, reopenMs: null });
      for (;;) {
        const state = api.openStep();
        if (state === 1) break;
        if (state < 0 || takeWanted() === 0) {
          const message = api.lastError() || 'the store could not be opened again';
          ui.showError(message.includes(base) ? message : `${base}: ${message}`);
          return false;
        }
        status(`${name}: WebGL context restored: reading the store again…`);
        await idle();
      }
      open = true;
      regionShown = api.regionShown() === 1;
      record.reopenMs = performance.now() - t0;
      record.reopenRequests = record.requests - requestsBefore;
      return true;
    }

    // The bread-slice region [begin, end) of level 0 (voxels x, y, z) at
    // native resolution with bounded reads: the chunks overlapping it are
    // fetched (ahead of the bricks' refinement; frames go on meanwhile),
    // then read as one box and shown by the viewer in place of the store.
    // Resolves to the keys fetched for it; throws an Error naming the store.
    async function showRegion(begin, end) {
      if (!open) throw new Error('no OME-Zarr store is open');
      const box = [begin[0], end[0], begin[1], end[1], begin[2], end[2]];
      const fetched = [];
      for (;;) {
        const state = api.regionPrefetch(...box);
        if (state === 1) break;
        const keys = state < 0 ? [] : JSON.parse(api.wanted());
        if (keys.length === 0) {
          const message = api.lastError() || 'the region could not be read';
          throw new Error(message.includes(base) ? message : `${base}: ${message}`);
        }
        status(`${name}: region ${box.join(',')}: fetching ${keys.length} chunks of level 0`);
        fetched.push(...(await fetchPinned(keys)));
      }
      if (!api.regionShow(...box)) {
        const message = api.lastError();
        throw new Error(message.includes(base) ? message : `${base}: ${message}`);
      }
      regionShown = true;
      record.region = { box, keys: fetched };
      return fetched;
    }

    // Fetches `keys` ahead of the bricks' refinement (pinned at the head of
    // the queue; frames go on meanwhile). Resolves, to the keys it pinned,
    // once all of them have arrived or failed (a failure reaches the
    // module, which reports it on the next read).
    async function fetchPinned(keys) {
      const fresh = keys.filter((k) => !pinned.includes(k));
      pinned.push(...fresh);
      queue = [...new Set([...pinned, ...queue])].filter((k) => !inFlight.has(k));
      pump();
      await new Promise((resolve) => {
        const wait = () => (keys.every((k) => !pinned.includes(k)) ? resolve() : setTimeout(wait, 20));
        wait();
      });
      return fresh;
    }

    // The keys the module wants now (a slice view's slab: tessera_slice
    // asked for them), fetched like a region's; resolves to them.
    async function fetchWanted() {
      if (!open) return [];
      const keys = JSON.parse(api.wanted());
      if (keys.length > 0) await fetchPinned(keys);
      return keys;
    }

    function close() {
      regionShown = false;
      pinned = [];
      arrays.clear();
      wholes.clear();
      wholeSizes.clear();
      wholeBytes = 0;
      rangesIgnored = false;
      if (base) api.close();
      base = '';
      open = false;
      queue = [];
      last = null;
      bricksRead = 0;
    }

    // Whether a frame now would show something new: keys arrived, or bricks
    // were read last frame (uploaded by the next), or a refinement waits on
    // nothing in flight (bricks backing off after errors: every 250 ms). While
    // fetches are under way a frame waits until they are done or twice the
    // last frame's time has passed: fetches are answered only between frames,
    // and a slow frame (SwiftShader: a second) would otherwise hold them up.
    function wantsFrame() {
      if (!open) return false;
      if (!last) return true;
      const since = performance.now() - lastFrameAt;
      const fetching = inFlight.size > 0 || queue.length > 0;
      const paced = !fetching || since >= 2 * last.ms;
      if (last.complete) return arrived ? paced : last.failing > 0 && since > 3000;
      if (arrived || last.uploaded > 0 || last.bricks_read !== bricksRead) return paced;
      return !fetching && since > 250;
    }

    function levelsText(f) {
      const cells = f.cells_per_level;
      const parts = [];
      cells.forEach((n, l) => {
        if (n > 0) parts.push(l === cells.length - 1 ? `${n} empty` : `L${l}: ${n}`);
      });
      return parts.join(', ');
    }

    // A frame of the view on the canvas, paced as the viewer's progressive
    // frames: a preview at once when `viewChanged` (else the canvas keeps
    // its image), then the full frame through refine() while refining().
    // `inputWaitedMs`: how long the input it answers has waited since its
    // time stamp (omitted or negative: none; its preview is due within two
    // budgets of it). Returns {ms, shown, pending}, or null on error.
    function frame(width, height, viewChanged, inputWaitedMs = -1) {
      if (!open) return null;  // being opened again after a context loss
      return handle(api.frame(width, height, viewChanged ? 1 : 0, inputWaitedMs));
    }

    // About a budget of the pending frame (streaming what arrived, then a
    // strip); the frame is on the canvas once `shown` and not `pending`.
    function refine() {
      return handle(api.refine());
    }

    function handle(text) {
      if (!text) {
        lastFrameAt = performance.now();
        ui.showError(`${base}: ${api.lastError()}`);
        return null;
      }
      const f = JSON.parse(text);
      if (f.streamed) arrived = false;  // what arrived until now is on the GPU
      takeWanted();
      // Every call's work: the pacing the tests check.
      record.calls.push({ t: performance.now() - t0, ms: f.ms, stream_ms: f.stream_ms, shown: f.shown, pending: f.pending,
        preview: f.preview_size[0] > 0, uploaded: f.uploaded, update_ms: f.update_ms, upload_wait_ms: f.upload_wait_ms,
        tables_ms: f.tables_ms, preview_ms: f.preview_ms, setup_ms: f.setup_ms, preview_size: f.preview_size,
        strip_rows: f.strip_rows, uploaded_now: f.uploaded_now, tables_rebuilt: f.tables_rebuilt, error_queries: f.error_queries });
      if (record.calls.length > 4000) record.calls.splice(0, 1000);
      if (!f.shown && !f.pending) {
        // Streamed, and nothing new to draw: the canvas shows these bricks.
        lastFrameAt = performance.now();
        bricksRead = last ? last.bricks_read : 0;
        last = { ...f, ms: last ? last.ms : f.ms };
        if (f.complete && record.completeMs === null) record.completeMs = performance.now() - t0;
      }
      if (!f.shown) return f;
      lastFrameAt = performance.now();
      const prevRead = last ? last.bricks_read : 0;
      bricksRead = prevRead;
      last = f;
      const t = lastFrameAt - t0;
      if (record.firstImageMs === null) record.firstImageMs = t;
      if (f.complete && !f.pending && record.completeMs === null) record.completeMs = t;
      record.timeline.push({ t, ms: f.ms, complete: f.complete, preview: f.pending, missing: f.missing, wanted: f.wanted,
        uploaded: f.uploaded, cells: f.cells_per_level, fetched: record.bytes });
      if (record.timeline.length > 2000) record.timeline.splice(1, 1);
      const mb = (record.bytes / 1048576).toFixed(2);
      frameStatus(`${name} (OME-Zarr, bricks) · cells ${levelsText(f)} · ` +
        (f.complete ? 'refined' : `${f.missing} of ${f.wanted} bricks coming`) +
        ` · ${record.requests} requests, ${mb} MB · ${f.pending ? 'preview' : 'frame'} ${f.ms.toFixed(0)} ms` +
        (f.pending ? ' · refining…' : '') +
        (f.failing ? ` · ${f.failing} bricks failing: ${f.last_error}` : ''),
      [f.complete ? 0 : f.wanted - f.missing, f.complete ? 0 : f.wanted], !f.pending);
      return f;
    }

    return {
      open: openStore,
      reopen,
      close,
      // The store is drawn (not a region read from it, which the viewer draws).
      active: () => open && !regionShown,
      showRegion,
      fetchWanted,
      overview: () => {
        regionShown = false;
        if (base) api.regionOverview();
      },
      showingRegion: () => regionShown,
      // Being opened again on a restored WebGL context (reopen()).
      reopening: () => reopening,
      wantsFrame,
      frame,
      refine,
      refining: () => open && api.refining() === 1,
      holds: (key) => api.holds(key) === 1,
      // For tests: what was fetched and the frames' timeline.
      stats: () => ({ ...record, last, inFlight: inFlight.size, queued: queue.length, t0,
        decodeTasks: decodeTasks.map((d) => ({ t: d.at - t0, ms: d.ms })) }),
    };
  }

  window.TesseraZarr = { isStoreUrl, create };
})();
