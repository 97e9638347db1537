#pragma once
// Bounded sequential input for the readers, on a ByteSource: its bytes from
// an offset, a gzip or zlib stream inflated chunk by chunk, and buffers of
// inflated chunks. Nothing here allocates more than the bytes it has
// actually read.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "io/Inflater.h"
#include "tessera/io/ByteSource.h"

namespace tessera::io_detail {

// Deflate emits at least 2 bits per 258-byte match, so no deflate stream
// inflates to more than 1032 times its size (zlib FAQ, "What's the maximum
// compression ratio?"). A header claiming more than that is lying, and we
// can say so before inflating anything.
constexpr std::uint64_t kMaxDeflateRatio = 1032;

// True if the bytes at `offset` start with the gzip magic (1f 8b).
bool startsWithGzipMagic(const ByteSource& source, std::uint64_t offset = 0);

class ByteStream {
 public:
  virtual ~ByteStream() = default;
  // Reads up to `n` bytes into `dst`; fewer only at the end of the data.
  // Throws InputError on I/O or decompression errors.
  virtual std::size_t read(std::byte* dst, std::size_t n) = 0;

  // Drops `n` bytes; returns how many were dropped (fewer at end of data).
  std::uint64_t skip(std::uint64_t n);
};

// The bytes of a source from `offset` on.
class SourceStream : public ByteStream {
 public:
  SourceStream(const ByteSource& source, std::uint64_t offset) : source_(source), pos_(offset) {}
  std::size_t read(std::byte* dst, std::size_t n) override;
  std::uint64_t position() const { return pos_; }

 private:
  const ByteSource& source_;
  std::uint64_t pos_;
};

// The inflated bytes of gzip (or zlib) data that starts at `offset` in a
// source; concatenated gzip members are read one after another, as gunzip
// does, and other bytes after the stream are ignored.
class InflateStream : public ByteStream {
 public:
  InflateStream(const ByteSource& source, std::uint64_t offset);
  std::size_t read(std::byte* dst, std::size_t n) override;

  // Inflated bytes handed out so far (for "ends after X bytes" messages).
  std::uint64_t inflatedSoFar() const { return produced_; }

 private:
  // Keeps at least `want` unread input bytes buffered unless the data ends.
  void fill(std::size_t want);
  std::size_t buffered() const { return len_ - pos_; }

  const ByteSource& source_;
  SourceStream in_;
  std::unique_ptr<Inflater> inflater_;
  std::vector<std::byte> buf_;
  std::size_t pos_ = 0;
  std::size_t len_ = 0;
  bool inputEnded_ = false;
  bool finished_ = false;
  std::uint64_t produced_ = 0;
};

// Bytes held in chunks that are allocated only as data arrives, so a stream
// that ends early never costs more than what it delivered.
class ChunkedBuffer : public ByteStream {
 public:
  // Reads up to `n` bytes from `src`; size() tells how many arrived.
  static ChunkedBuffer readUpTo(ByteStream& src, std::uint64_t n);

  std::uint64_t size() const { return size_; }
  // Reading consumes the chunks front to back and frees each once drained.
  std::size_t read(std::byte* dst, std::size_t n) override;

 private:
  std::vector<std::vector<std::byte>> chunks_;
  std::size_t chunk_ = 0;
  std::size_t pos_ = 0;
  std::uint64_t size_ = 0;
};

}  // namespace tessera::io_detail
