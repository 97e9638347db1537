// JavaScript half of frontends/web/src/InflaterPako.cpp (an emscripten --js-library):
// gzip/zlib streams inflated by the page's pako (pako_inflate.min.js, from
// frontends/web/package.json). pako's Inflate takes a push of input and hands out
// whole output buffers; each stream queues what it produced and gives it
// out in the caller's pieces. A push is at most 16 KiB of input, so no more
// than 16.5 MiB of output (deflate's 1032:1) waits here at a time.
mergeInto(LibraryManager.library, {
  // A new stream's id, or 0 when pako is not on the page.
  tessera_pako_open: function () {
    const pako = globalThis.pako;
    if (!pako || !pako.Inflate) return 0;
    if (!Module.tesseraInflaters) Module.tesseraInflaters = { next: 1, streams: new Map() };
    const reg = Module.tesseraInflaters;
    const s = { inf: new pako.Inflate({ chunkSize: 65536 }), queue: [], buf: null, taken: 0, error: '' };
    // Queues the output of pako's current buffer up to `end`; `taken` bytes
    // of that buffer (`buf`) are queued already.
    s.take = function (end) {
      const out = s.inf.strm.output;
      const from = s.buf === out ? s.taken : 0;
      if (end > from) s.queue.push(out.subarray(from, end));
      s.buf = out;
      s.taken = end;
    };
    s.inf.onData = function (chunk) { s.take(chunk.length); };
    const id = reg.next++;
    reg.streams.set(id, s);
    return id;
  },

  // One step: writes info[0] = input bytes consumed, info[1] = 1 once the
  // stream ended, info[2] = 1 on corrupt data (pako's message into `error`).
  // Returns the bytes written to `out`.
  tessera_pako_step: function (id, inPtr, inSize, outPtr, outSize, info, error, errorSize) {
    const s = Module.tesseraInflaters.streams.get(id);
    let consumed = 0;
    if (s.queue.length === 0 && !s.inf.ended && !s.error && inSize > 0) {
      const n = Math.min(inSize, 16384);
      const ok = s.inf.push(HEAPU8.slice(inPtr, inPtr + n), false);
      const strm = s.inf.strm;
      consumed = n - (s.inf.ended ? strm.avail_in : 0);
      if (strm.output) s.take(strm.next_out);
      if (!ok) s.error = s.inf.msg || ('zlib error ' + s.inf.err);
    }
    let produced = 0;
    while (produced < outSize && s.queue.length > 0) {
      const head = s.queue[0];
      const k = Math.min(head.length, outSize - produced);
      HEAPU8.set(head.subarray(0, k), outPtr + produced);
      produced += k;
      if (k === head.length) {
        s.queue.shift();
      } else {
        s.queue[0] = head.subarray(k);
      }
    }
    const drained = s.queue.length === 0;
    HEAP32[info >> 2] = consumed;
    HEAP32[(info >> 2) + 1] = drained && s.inf.ended && !s.error ? 1 : 0;
    HEAP32[(info >> 2) + 2] = drained && s.error ? 1 : 0;
    if (drained && s.error) stringToUTF8(s.error, error, errorSize);
    return produced;
  },

  tessera_pako_close: function (id) {
    Module.tesseraInflaters.streams.delete(id);
  },
});
