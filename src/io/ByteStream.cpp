#include "io/ByteStream.h"

#include <algorithm>
#include <array>
#include <cstring>

#include "tessera/core/Error.h"

namespace tessera::io_detail {

namespace {

// Chunk sizes: big enough that per-call overhead vanishes, small enough that
// a stream which ends early wastes little.
constexpr std::size_t kInputChunk = 256 * 1024;
constexpr std::size_t kBufferChunk = 4 * 1024 * 1024;

}  // namespace

bool startsWithGzipMagic(const ByteSource& source, std::uint64_t offset) {
  std::array<std::byte, 2> magic{};
  return source.read(offset, magic.data(), magic.size()) == 2 && magic[0] == std::byte{0x1f} &&
         magic[1] == std::byte{0x8b};
}

std::uint64_t ByteStream::skip(std::uint64_t n) {
  std::vector<std::byte> scratch(static_cast<std::size_t>(std::min<std::uint64_t>(n, 64 * 1024)));
  std::uint64_t done = 0;
  while (done < n) {
    const std::size_t want =
        static_cast<std::size_t>(std::min<std::uint64_t>(n - done, scratch.size()));
    const std::size_t got = read(scratch.data(), want);
    done += got;
    if (got < want) break;
  }
  return done;
}

std::size_t SourceStream::read(std::byte* dst, std::size_t n) {
  const std::size_t got = source_.read(pos_, dst, n);
  pos_ += got;
  return got;
}

InflateStream::InflateStream(const ByteSource& source, std::uint64_t offset)
    : source_(source), in_(source, offset), inflater_(Inflater::create()), buf_(kInputChunk) {}

void InflateStream::fill(std::size_t want) {
  if (buffered() >= want || inputEnded_) return;
  std::memmove(buf_.data(), buf_.data() + pos_, buffered());
  len_ = buffered();
  pos_ = 0;
  while (len_ < want && !inputEnded_ && len_ < buf_.size()) {
    const std::size_t got = in_.read(buf_.data() + len_, buf_.size() - len_);
    len_ += got;
    inputEnded_ = got == 0;
  }
}

std::size_t InflateStream::read(std::byte* dst, std::size_t n) {
  std::size_t done = 0;
  while (done < n && !finished_) {
    fill(1);
    const Inflater::Step step =
        inflater_->inflate(std::span<const std::byte>(buf_.data() + pos_, buffered()),
                           std::span(dst + done, n - done));
    pos_ += step.consumed;
    done += step.produced;
    produced_ += step.produced;
    if (!step.error.empty()) {
      throw InputError(source_.name() + ": gzip data is corrupt after " +
                       std::to_string(produced_) + " inflated bytes (" + step.error + ")");
    }
    if (step.ended) {
      // Another gzip member may follow; anything else after the stream is
      // ignored, as gunzip does with trailing garbage.
      fill(2);
      if (buffered() >= 2 && buf_[pos_] == std::byte{0x1f} && buf_[pos_ + 1] == std::byte{0x8b}) {
        inflater_ = Inflater::create();
      } else {
        finished_ = true;
      }
    } else if (step.consumed == 0 && step.produced == 0) {
      // The inflater wants more input than is buffered; when the compressed
      // data ends instead (possibly mid-stream), the caller reports the
      // shortfall.
      const std::size_t before = buffered();
      fill(before + 1);
      finished_ = buffered() == before;
    }
  }
  return done;
}

ChunkedBuffer ChunkedBuffer::readUpTo(ByteStream& src, std::uint64_t n) {
  ChunkedBuffer buf;
  while (buf.size_ < n) {
    const std::size_t want =
        static_cast<std::size_t>(std::min<std::uint64_t>(n - buf.size_, kBufferChunk));
    std::vector<std::byte> chunk(want);
    const std::size_t got = src.read(chunk.data(), want);
    if (got == 0) break;
    chunk.resize(got);
    chunk.shrink_to_fit();
    buf.size_ += got;
    buf.chunks_.push_back(std::move(chunk));
    if (got < want) break;
  }
  return buf;
}

std::size_t ChunkedBuffer::read(std::byte* dst, std::size_t n) {
  std::size_t done = 0;
  while (done < n && chunk_ < chunks_.size()) {
    std::vector<std::byte>& c = chunks_[chunk_];
    const std::size_t take = std::min(n - done, c.size() - pos_);
    std::memcpy(dst + done, c.data() + pos_, take);
    done += take;
    pos_ += take;
    if (pos_ == c.size()) {
      std::vector<std::byte>().swap(c);  // free drained chunks as we go
      ++chunk_;
      pos_ = 0;
    }
  }
  return done;
}

}  // namespace tessera::io_detail
