// The native Inflater (io/Inflater.h): zlib.
#include <zlib.h>

#include <algorithm>
#include <limits>

#include "io/Inflater.h"

namespace tessera::io_detail {

namespace {

class ZlibInflater final : public Inflater {
 public:
  ZlibInflater() {
    // 15 + 32: the largest window, and either a zlib or a gzip header.
    ready_ = inflateInit2(&zs_, 15 + 32) == Z_OK;
  }
  ~ZlibInflater() override {
    if (ready_) inflateEnd(&zs_);
  }
  ZlibInflater(const ZlibInflater&) = delete;
  ZlibInflater& operator=(const ZlibInflater&) = delete;

  Step inflate(std::span<const std::byte> in, std::span<std::byte> out) override {
    Step step;
    if (!ready_) {
      step.error = "cannot start zlib inflation";
      return step;
    }
    constexpr std::size_t kMost = std::numeric_limits<uInt>::max() / 2;
    const std::size_t inSize = std::min(in.size(), kMost);
    const std::size_t outSize = std::min(out.size(), kMost);
    zs_.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(in.data()));
    zs_.avail_in = static_cast<uInt>(inSize);
    zs_.next_out = reinterpret_cast<Bytef*>(out.data());
    zs_.avail_out = static_cast<uInt>(outSize);
    const int ret = ::inflate(&zs_, Z_NO_FLUSH);
    step.consumed = inSize - zs_.avail_in;
    step.produced = outSize - zs_.avail_out;
    step.ended = ret == Z_STREAM_END;
    if (ret != Z_OK && ret != Z_STREAM_END && ret != Z_BUF_ERROR) {
      step.error = zs_.msg != nullptr ? zs_.msg : "zlib error " + std::to_string(ret);
    }
    return step;
  }

 private:
  z_stream zs_{};
  bool ready_ = false;
};

}  // namespace

std::unique_ptr<Inflater> Inflater::create() {
  return std::make_unique<ZlibInflater>();
}

}  // namespace tessera::io_detail
