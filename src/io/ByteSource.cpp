#include "io/ByteSource.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <limits>
#include <system_error>

#include "tessera/core/Error.h"

namespace tessera::io_detail {

namespace {

// Chunk sizes: big enough that per-call overhead vanishes, small enough that
// a stream which ends early wastes little.
constexpr std::size_t kInputChunk = 256 * 1024;
constexpr std::size_t kBufferChunk = 4 * 1024 * 1024;

std::FILE* openAt(const std::filesystem::path& path, std::uint64_t offset) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    throw InputError(path.string() + ": cannot open: " + std::strerror(errno));
  }
  if (offset > static_cast<std::uint64_t>(std::numeric_limits<off_t>::max()) ||
      fseeko(f, static_cast<off_t>(offset), SEEK_SET) != 0) {
    std::fclose(f);
    throw InputError(path.string() + ": cannot seek to byte " + std::to_string(offset));
  }
  return f;
}

}  // namespace

std::uint64_t regularFileSize(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) {
    throw InputError(path.string() + ": no such file");
  }
  if (std::filesystem::is_directory(status)) {
    throw InputError(path.string() + ": is a directory, expected a volume file");
  }
  if (!std::filesystem::is_regular_file(status)) {
    throw InputError(path.string() + ": is not a regular file");
  }
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(path.string() + ": cannot read its size: " + ec.message());
  return size;
}

bool startsWithGzipMagic(const std::filesystem::path& path, std::uint64_t offset) {
  std::FILE* f = openAt(path, offset);
  std::array<unsigned char, 2> magic{};
  const std::size_t n = std::fread(magic.data(), 1, magic.size(), f);
  std::fclose(f);
  return n == 2 && magic[0] == 0x1f && magic[1] == 0x8b;
}

std::uint64_t ByteSource::skip(std::uint64_t n) {
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

FileByteSource::FileByteSource(const std::filesystem::path& path, std::uint64_t offset)
    : path_(path), file_(openAt(path, offset)) {}

FileByteSource::~FileByteSource() {
  if (file_ != nullptr) std::fclose(file_);
}

std::size_t FileByteSource::read(std::byte* dst, std::size_t n) {
  const std::size_t got = std::fread(dst, 1, n, file_);
  if (got < n && std::ferror(file_)) {
    throw InputError(path_.string() + ": read error: " + std::strerror(errno));
  }
  return got;
}

GzipByteSource::GzipByteSource(const std::filesystem::path& path, std::uint64_t offset)
    : path_(path), file_(openAt(path, offset)), in_(kInputChunk) {
  // 15 + 32: largest window, and accept both gzip and zlib headers.
  if (inflateInit2(&zs_, 15 + 32) != Z_OK) {
    std::fclose(file_);
    throw InputError(path_.string() + ": cannot start zlib inflation");
  }
  zsReady_ = true;
}

GzipByteSource::~GzipByteSource() {
  if (zsReady_) inflateEnd(&zs_);
  if (file_ != nullptr) std::fclose(file_);
}

bool GzipByteSource::refill() {
  const std::size_t got = std::fread(in_.data(), 1, in_.size(), file_);
  if (got == 0 && std::ferror(file_)) {
    throw InputError(path_.string() + ": read error: " + std::strerror(errno));
  }
  zs_.next_in = in_.data();
  zs_.avail_in = static_cast<uInt>(got);
  return got > 0;
}

std::size_t GzipByteSource::read(std::byte* dst, std::size_t n) {
  std::size_t done = 0;
  while (done < n && !finished_) {
    if (zs_.avail_in == 0 && !refill()) {
      finished_ =
          true;  // compressed data ends (possibly mid-stream: the caller reports the shortfall)
      break;
    }
    const std::size_t want = std::min<std::size_t>(n - done, std::numeric_limits<uInt>::max() / 2);
    zs_.next_out = reinterpret_cast<Bytef*>(dst + done);
    zs_.avail_out = static_cast<uInt>(want);
    const int ret = inflate(&zs_, Z_NO_FLUSH);
    const std::size_t made = want - zs_.avail_out;
    done += made;
    produced_ += made;
    if (ret == Z_STREAM_END) {
      // Another gzip member may follow; anything else after the stream is
      // ignored, as gunzip does with trailing garbage.
      if (zs_.avail_in == 0 && !refill()) {
        finished_ = true;
      } else if (zs_.avail_in >= 2 && zs_.next_in[0] == 0x1f && zs_.next_in[1] == 0x8b) {
        inflateReset(&zs_);
      } else {
        finished_ = true;
      }
    } else if (ret != Z_OK && ret != Z_BUF_ERROR) {
      throw InputError(path_.string() + ": gzip data is corrupt after " +
                       std::to_string(produced_) + " inflated bytes (" +
                       (zs_.msg != nullptr ? zs_.msg : "zlib error " + std::to_string(ret)) + ")");
    }
  }
  return done;
}

ChunkedBuffer ChunkedBuffer::readUpTo(ByteSource& src, std::uint64_t n) {
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
