#include "io/PvmDds.h"

#include <algorithm>
#include <cstring>

#include "tessera/core/Error.h"

namespace tessera::io_detail {

namespace {

constexpr char kMagicV3d[] = "DDS v3d\n";
constexpr char kMagicV3e[] = "DDS v3e\n";
constexpr int kCountBits = 7;  // ddsbase.cpp's DDS_RL
constexpr int kCodeBits = 3;
constexpr unsigned kMaxRun = (1u << kCountBits) - 1;

// Most significant bit first; bits past the end of the data read as 0, as
// in ddsbase.cpp, which is how a stream without an explicit 0 count ends.
class BitReader {
 public:
  explicit BitReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}

  // n <= 16
  std::uint32_t read(int n) {
    if (n == 0) return 0;
    const std::uint64_t byte = pos_ >> 3;
    std::uint32_t window = 0;
    for (std::uint64_t k = 0; k < 3; ++k) {
      window = (window << 8) | (byte + k < bytes_.size() ? bytes_[byte + k] : 0u);
    }
    const int shift = 24 - static_cast<int>(pos_ & 7) - n;
    pos_ += static_cast<std::uint64_t>(n);
    return (window >> shift) & ((1u << n) - 1);
  }
  void skip(std::uint64_t n) { pos_ += n; }
  std::uint64_t position() const { return pos_; }
  std::uint64_t size() const { return static_cast<std::uint64_t>(bytes_.size()) * 8; }

 private:
  std::span<const std::uint8_t> bytes_;
  std::uint64_t pos_ = 0;
};

class BitWriter {
 public:
  void write(std::uint32_t value, int n) {
    for (int b = n - 1; b >= 0; --b) {
      if (used_ == 0) bytes_.push_back(0);
      if ((value >> b) & 1u) bytes_.back() |= static_cast<std::uint8_t>(0x80u >> used_);
      used_ = (used_ + 1) & 7;
    }
  }
  std::vector<std::uint8_t>& bytes() { return bytes_; }

 private:
  std::vector<std::uint8_t> bytes_;
  int used_ = 0;  // bits used in the last byte
};

int widthOfCode(std::uint32_t code) {
  return code == 0 ? 0 : static_cast<int>(code) + 1;
}
std::uint32_t codeOfWidth(int width) {
  return width == 0 ? 0 : static_cast<std::uint32_t>(width - 1);
}

// Value bits a delta needs: 0 for 0, else the smallest w in 2..8 with
// -2^(w-1) <= delta < 2^(w-1) (the format has no 1-bit width).
int widthOf(int delta) {
  if (delta == 0) return 0;
  for (int w = 2; w < 8; ++w) {
    if (delta >= -(1 << (w - 1)) && delta < (1 << (w - 1))) return w;
  }
  return 8;
}

std::uint64_t chunkBytes(DdsVersion version, unsigned skip, std::uint64_t size,
                         std::uint64_t interleaveBlock) {
  return version == DdsVersion::V3d ? std::max<std::uint64_t>(size, 1) : skip * interleaveBlock;
}

// Bytes in plane `p` of a chunk of `n` bytes interleaved with stride `skip`.
std::uint64_t planeLength(std::uint64_t n, unsigned skip, unsigned p) {
  return n > p ? (n - p + skip - 1) / skip : 0;
}

}  // namespace

std::optional<DdsVersion> ddsVersionOf(std::string_view prefix) {
  if (prefix.size() < kDdsMagicBytes) return std::nullopt;
  if (prefix.compare(0, kDdsMagicBytes, kMagicV3d) == 0) return DdsVersion::V3d;
  if (prefix.compare(0, kDdsMagicBytes, kMagicV3e) == 0) return DdsVersion::V3e;
  return std::nullopt;
}

DdsStreamInfo scanDds(std::span<const std::uint8_t> file, const std::string& what) {
  const std::string_view head(reinterpret_cast<const char*>(file.data()),
                              std::min<std::size_t>(file.size(), kDdsMagicBytes));
  const auto version = ddsVersionOf(head);
  if (!version) throw InputError(what + ": not a DDS stream (no 'DDS v3d' or 'DDS v3e' magic)");
  DdsStreamInfo info;
  info.version = *version;
  BitReader bits(file.subspan(kDdsMagicBytes));
  info.skip = bits.read(2) + 1;
  info.strip = bits.read(16) + 1;
  if (bits.position() > bits.size()) {
    throw InputError(what + ": DDS stream ends inside its 18-bit header (file has " +
                     std::to_string(file.size()) + " bytes)");
  }
  while (true) {
    const std::uint32_t count = bits.read(kCountBits);
    if (count == 0) break;
    const int width = widthOfCode(bits.read(kCodeBits));
    bits.skip(static_cast<std::uint64_t>(count) * static_cast<std::uint64_t>(width));
    if (bits.position() > bits.size()) {
      throw InputError(what + ": DDS stream is truncated: a run of " + std::to_string(count) +
                       " values ends " + std::to_string(bits.position() - bits.size()) +
                       " bits past the end of the file, after " + std::to_string(info.decodedSize) +
                       " decoded bytes");
    }
    info.decodedSize += count;
  }
  if (info.decodedSize == 0) throw InputError(what + ": DDS stream holds no data");
  return info;
}

DdsPayload decodeDds(std::span<const std::uint8_t> file, const DdsStreamInfo& info,
                     std::uint64_t interleaveBlock) {
  DdsPayload out;
  out.skip_ = info.skip;
  out.chunk_ = chunkBytes(info.version, info.skip, info.decodedSize, interleaveBlock);
  out.planar_.resize(static_cast<std::size_t>(info.decodedSize));
  std::uint8_t* data = out.planar_.data();
  const std::uint64_t strip = info.strip;

  BitReader bits(file.subspan(kDdsMagicBytes));
  bits.skip(18);
  std::uint64_t i = 0;
  int previous = 0;
  while (i < info.decodedSize) {
    const std::uint32_t count = bits.read(kCountBits);
    if (count == 0) break;  // cannot happen after scanDds; defensive
    const int width = widthOfCode(bits.read(kCodeBits));
    const int bias = (1 << width) / 2;
    for (std::uint32_t c = 0; c < count && i < info.decodedSize; ++c, ++i) {
      int value = previous + static_cast<int>(bits.read(width)) - bias;
      if (i > strip) value += data[i - strip] - data[i - strip - 1];
      data[i] = static_cast<std::uint8_t>(value & 0xff);  // arithmetic is mod 256
      previous = data[i];
    }
  }
  return out;
}

void DdsPayload::copy(std::uint64_t begin, std::uint64_t count, std::uint8_t* dst) const {
  const std::uint64_t end = begin + count;
  if (skip_ == 1) {
    std::memcpy(dst, planar_.data() + begin, static_cast<std::size_t>(count));
    return;
  }
  for (std::uint64_t base = begin / chunk_ * chunk_; base < end; base += chunk_) {
    const std::uint64_t n = std::min<std::uint64_t>(chunk_, size() - base);
    const std::uint64_t lo = std::max(begin, base);
    const std::uint64_t hi = std::min(end, base + n);
    std::uint64_t planeStart = base;
    for (unsigned p = 0; p < skip_; ++p) {
      const std::uint64_t length = planeLength(n, skip_, p);
      // Byte k of plane p sits at payload offset base + p + k * skip.
      std::uint64_t k = lo > base + p ? (lo - base - p + skip_ - 1) / skip_ : 0;
      for (std::uint64_t at = base + p + k * skip_; k < length && at < hi; ++k, at += skip_) {
        dst[at - begin] = planar_[static_cast<std::size_t>(planeStart + k)];
      }
      planeStart += length;
    }
  }
}

std::string DdsPayload::bytesAt(std::uint64_t begin, std::uint64_t count) const {
  begin = std::min(begin, size());
  count = std::min(count, size() - begin);
  std::string s(static_cast<std::size_t>(count), '\0');
  copy(begin, count, reinterpret_cast<std::uint8_t*>(s.data()));
  return s;
}

std::vector<std::uint8_t> encodeDds(std::span<const std::uint8_t> payload, unsigned skip,
                                    unsigned strip, DdsVersion version,
                                    std::uint64_t interleaveBlock) {
  if (payload.empty() || skip < 1 || skip > 4 || strip < 1 || strip > 65536) {
    throw InputError("DDS encoder: needs data, skip 1..4 and strip 1..65536");
  }
  // Gather each chunk's bytes plane by plane (ddsbase.cpp's deinterleave).
  std::vector<std::uint8_t> planar;
  planar.reserve(payload.size());
  const std::uint64_t chunk = chunkBytes(version, skip, payload.size(), interleaveBlock);
  for (std::uint64_t base = 0; base < payload.size(); base += chunk) {
    const std::uint64_t n = std::min<std::uint64_t>(chunk, payload.size() - base);
    for (unsigned p = 0; p < skip; ++p) {
      for (std::uint64_t j = p; j < n; j += skip) planar.push_back(payload[base + j]);
    }
  }

  std::vector<int> deltas(planar.size());
  int previous = 0;
  for (std::size_t i = 0; i < planar.size(); ++i) {
    int prediction = previous;
    if (i > strip) prediction += planar[i - strip] - planar[i - strip - 1];
    int delta = (planar[i] - prediction) & 0xff;
    if (delta > 127) delta -= 256;  // deltas are taken mod 256 into -128..127
    deltas[i] = delta;
    previous = planar[i];
  }

  BitWriter bits;
  bits.write(skip - 1, 2);
  bits.write(strip - 1, 16);
  auto emit = [&](std::size_t begin, std::size_t count, int width) {
    bits.write(static_cast<std::uint32_t>(count), kCountBits);
    bits.write(codeOfWidth(width), kCodeBits);
    const int bias = (1 << width) / 2;
    for (std::size_t i = begin; i < begin + count; ++i) {
      bits.write(static_cast<std::uint32_t>(deltas[i] + bias), width);
    }
  };
  // Groups of equal width are merged into the pending run while the wider
  // values cost less than the 10 bits of another run header (the choice
  // ddsbase.cpp's encoder makes).
  std::size_t pendingBegin = 0, pendingCount = 0;
  int pendingWidth = 0;
  for (std::size_t i = 0; i < deltas.size();) {
    const int width = widthOf(deltas[i]);
    std::size_t end = i + 1;
    while (end < deltas.size() && end - i < kMaxRun && widthOf(deltas[end]) == width) ++end;
    const std::size_t count = end - i;
    const int merged = std::max(width, pendingWidth);
    const std::size_t runHeader = kCountBits + kCodeBits;
    if (pendingCount > 0 && pendingCount + count <= kMaxRun &&
        (pendingCount + count) * static_cast<std::size_t>(merged) <
            pendingCount * static_cast<std::size_t>(pendingWidth) +
                count * static_cast<std::size_t>(width) + runHeader) {
      pendingCount += count;
      pendingWidth = merged;
    } else {
      if (pendingCount > 0) emit(pendingBegin, pendingCount, pendingWidth);
      pendingBegin = i;
      pendingCount = count;
      pendingWidth = width;
    }
    i = end;
  }
  emit(pendingBegin, pendingCount, pendingWidth);
  // No closing 0 count: the zero padding and the end of the file read as
  // one, as in ddsbase.cpp.

  const std::vector<std::uint8_t>& stream = bits.bytes();
  std::vector<std::uint8_t> file(kDdsMagicBytes + stream.size());
  std::memcpy(file.data(), version == DdsVersion::V3d ? kMagicV3d : kMagicV3e, kDdsMagicBytes);
  std::memcpy(file.data() + kDdsMagicBytes, stream.data(), stream.size());
  return file;
}

}  // namespace tessera::io_detail
