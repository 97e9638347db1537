// The browser's Inflater (io/Inflater.h): the page loads pako
// (web/package.json, copied into the site as pako_inflate.min.js), and each
// step runs it synchronously through JavaScript. pako's Inflate takes a
// push of input and hands out whole output buffers; the queue below gives
// its output out in the caller's pieces, and each push is at most 16 KiB of
// input, so no more than 16.5 MiB of output (deflate's 1032:1) waits in
// JavaScript while the readers' chunked, budget-checked decoding goes on.
#include <emscripten/emscripten.h>

#include <algorithm>
#include <array>

#include "io/Inflater.h"

// Returns a stream id, or 0 when pako is not on the page.
EM_JS(int, tessera_pako_open, (), {
  const pako = globalThis.pako;
  if (!pako || !pako.Inflate) return 0;
  const reg =
      Module.tesseraInflaters || (Module.tesseraInflaters = {next : 1, streams : new Map()});
  const s =
      {inf : new pako.Inflate({chunkSize : 65536}), queue : [], buf : null, taken : 0, error : ''};
  // Output arrives as pako's buffers; `taken` bytes of the current one
  // (`buf`) are queued already.
  const take = (chunkEnd) = > {
    const out = s.inf.strm.output;
    const from = s.buf == = out ? s.taken : 0;
    if (chunkEnd > from) s.queue.push(out.subarray(from, chunkEnd));
    s.buf = out;
    s.taken = chunkEnd;
  };
  s.take = take;
  s.inf.onData = (chunk) = > take(chunk.length);
  const id = reg.next++;
  reg.streams.set(id, s);
  return id;
});

// One step: info[0] = input bytes consumed, info[1] = 1 when the stream
// ended, info[2] = 1 on corrupt data (its message in `error`). Returns the
// bytes written to `out`.
EM_JS(int, tessera_pako_step,
      (int id, const void* in, int inSize, void* out, int outSize, int* info, char* error,
       int errorSize),
      {
        const s = Module.tesseraInflaters.streams.get(id);
        let consumed = 0;
        if (s.queue.length == = 0 && !s.inf.ended && !s.error && inSize > 0) {
          const n = Math.min(inSize, 16384);
          const ok = s.inf.push(HEAPU8.slice(in, in + n), false);
          const strm = s.inf.strm;
          consumed = n - (s.inf.ended ? strm.avail_in : 0);
          if (strm.output) s.take(strm.next_out);
          if (!ok) s.error = s.inf.msg || ('zlib error ' + s.inf.err);
        }
        let produced = 0;
        while (produced < outSize && s.queue.length > 0) {
          const head = s.queue[0];
          const k = Math.min(head.length, outSize - produced);
          HEAPU8.set(head.subarray(0, k), out + produced);
          produced += k;
          if (k == = head.length) {
            s.queue.shift();
          } else {
            s.queue[0] = head.subarray(k);
          }
        }
        const drained = s.queue.length == = 0;
        HEAP32[info >> 2] = consumed;
        HEAP32[(info >> 2) + 1] = drained && s.inf.ended && !s.error ? 1 : 0;
        HEAP32[(info >> 2) + 2] = drained && s.error ? 1 : 0;
        if (drained && s.error) stringToUTF8(s.error, error, errorSize);
        return produced;
      });

EM_JS(void, tessera_pako_close, (int id), { Module.tesseraInflaters.streams.delete(id); });

namespace tessera::io_detail {

namespace {

class PakoInflater final : public Inflater {
 public:
  PakoInflater() : id_(tessera_pako_open()) {}
  ~PakoInflater() override {
    if (id_ != 0) tessera_pako_close(id_);
  }
  PakoInflater(const PakoInflater&) = delete;
  PakoInflater& operator=(const PakoInflater&) = delete;

  Step inflate(std::span<const std::byte> in, std::span<std::byte> out) override {
    Step step;
    if (id_ == 0) {
      step.error = "pako (pako_inflate.min.js) is not loaded by the page";
      return step;
    }
    std::array<int, 3> info{};
    std::array<char, 256> error{};
    step.produced = static_cast<std::size_t>(tessera_pako_step(
        id_, in.data(), static_cast<int>(std::min<std::size_t>(in.size(), 1 << 30)), out.data(),
        static_cast<int>(std::min<std::size_t>(out.size(), 1 << 30)), info.data(), error.data(),
        static_cast<int>(error.size())));
    step.consumed = static_cast<std::size_t>(info[0]);
    step.ended = info[1] != 0;
    if (info[2] != 0) step.error = error.data();
    return step;
  }

 private:
  int id_;
};

}  // namespace

std::unique_ptr<Inflater> Inflater::create() {
  return std::make_unique<PakoInflater>();
}

}  // namespace tessera::io_detail
