#pragma once
// Bounded byte input for the readers: plain files from an offset, gzip
// streams inflated chunk by chunk, and buffers of inflated chunks. Nothing
// here allocates more than the bytes it has actually read.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <zlib.h>

namespace tessera::io_detail {

// Deflate emits at least 2 bits per 258-byte match, so no deflate stream
// inflates to more than 1032 times its size (zlib FAQ, "What's the maximum
// compression ratio?"). A header claiming more than that is lying, and we
// can say so before inflating anything.
constexpr std::uint64_t kMaxDeflateRatio = 1032;

// Size of a regular file; InputError naming `path` if it does not exist, is a
// directory or something else that is not a regular file.
std::uint64_t regularFileSize(const std::filesystem::path& path);

// True if the bytes at `offset` start with the gzip magic (1f 8b).
bool startsWithGzipMagic(const std::filesystem::path& path, std::uint64_t offset = 0);

class ByteSource {
 public:
  virtual ~ByteSource() = default;
  // Reads up to `n` bytes into `dst`; fewer only at the end of the data.
  // Throws InputError on I/O or decompression errors.
  virtual std::size_t read(std::byte* dst, std::size_t n) = 0;

  // Drops `n` bytes; returns how many were dropped (fewer at end of data).
  std::uint64_t skip(std::uint64_t n);
};

// The bytes of a file from `offset` on.
class FileByteSource : public ByteSource {
 public:
  FileByteSource(const std::filesystem::path& path, std::uint64_t offset);
  ~FileByteSource() override;
  FileByteSource(const FileByteSource&) = delete;
  FileByteSource& operator=(const FileByteSource&) = delete;
  std::size_t read(std::byte* dst, std::size_t n) override;

 private:
  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
};

// The inflated bytes of gzip (or zlib) data that starts at `offset` in a
// file; concatenated gzip members are read one after another, as gunzip does.
class GzipByteSource : public ByteSource {
 public:
  GzipByteSource(const std::filesystem::path& path, std::uint64_t offset);
  ~GzipByteSource() override;
  GzipByteSource(const GzipByteSource&) = delete;
  GzipByteSource& operator=(const GzipByteSource&) = delete;
  std::size_t read(std::byte* dst, std::size_t n) override;

  // Inflated bytes handed out so far (for "ends after X bytes" messages).
  std::uint64_t inflatedSoFar() const { return produced_; }

 private:
  bool refill();

  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
  z_stream zs_{};
  bool zsReady_ = false;
  bool finished_ = false;
  std::uint64_t produced_ = 0;
  std::vector<unsigned char> in_;
};

// Bytes held in chunks that are allocated only as data arrives, so a stream
// that ends early never costs more than what it delivered.
class ChunkedBuffer : public ByteSource {
 public:
  // Reads up to `n` bytes from `src`; size() tells how many arrived.
  static ChunkedBuffer readUpTo(ByteSource& src, std::uint64_t n);

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
