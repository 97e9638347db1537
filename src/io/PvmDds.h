#pragma once
// DDS, the "differential data stream" compression of Roettger's volume
// library (V^3, ddsbase.cpp) in which most .pvm files are stored. The whole
// PVM file (text header, voxels, trailing strings) is the payload.
//
// Layout, as ddsbase.cpp's writeDDSfile/readDDSfile define it:
//  - 8 bytes of magic: "DDS v3d\n" or "DDS v3e\n".
//  - a bit stream read most significant bit first (32-bit big-endian words,
//    the last one cut to the bytes it uses; bits past the end read as 0):
//      2 bits  skip - 1    (1..4: bytes per voxel, the interleave stride)
//      16 bits strip - 1   (1..65536: bytes per row, for the predictor)
//    then runs until a run count of 0:
//      7 bits  count       (1..127 values; 0 ends the stream)
//      3 bits  code        (value width: 0 bits for code 0, code + 1 bits otherwise)
//      count × width bits  value; delta = value - 2^width / 2
//  - byte i of the decoded stream is (prev + delta) mod 256, where prev is
//    byte i - 1 (0 before the first) plus, for i > strip, the difference
//    byte[i - strip] - byte[i - strip - 1] of the row above (a 2-D
//    Lorenzo-style predictor).
//  - the decoded stream is planar: the encoder gathered byte j of every
//    `skip`-byte voxel into plane j ("deinterleave"). v3d applies this to the
//    whole payload, v3e to consecutive chunks of skip × 2^24 bytes.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tessera::io_detail {

enum class DdsVersion { V3d, V3e };

constexpr std::size_t kDdsMagicBytes = 8;
// Tessera keeps the volume origin, which PVM lacks, in the PVM3 comment
// string: written by writePvm, read by readPvm.
constexpr std::string_view kPvmOriginTag = "tessera origin: ";
constexpr std::uint64_t kDdsInterleaveBlock = std::uint64_t{1} << 24;

// The version whose magic `prefix` starts with, if any.
std::optional<DdsVersion> ddsVersionOf(std::string_view prefix);

// What a first pass over the runs learns without decoding a byte.
struct DdsStreamInfo {
  DdsVersion version = DdsVersion::V3d;
  unsigned skip = 1;
  unsigned strip = 1;
  std::uint64_t decodedSize = 0;
};

// Scans the runs of a whole DDS file (magic included) and returns the
// decoded size, so that callers can check it against a budget before
// decoding. InputError (prefixed by `what`) for a wrong magic, a run that
// ends past the end of the file (truncation), or an empty stream.
DdsStreamInfo scanDds(std::span<const std::uint8_t> file, const std::string& what);

// The decoded payload, kept in the encoder's planar order; reads go through
// the interleave mapping, so no second full-size buffer is needed.
class DdsPayload {
 public:
  std::uint64_t size() const { return planar_.size(); }
  // Copies payload bytes [begin, begin + count) in file order.
  void copy(std::uint64_t begin, std::uint64_t count, std::uint8_t* dst) const;
  std::string bytesAt(std::uint64_t begin, std::uint64_t count) const;

 private:
  friend DdsPayload decodeDds(std::span<const std::uint8_t>, const DdsStreamInfo&, std::uint64_t);
  std::vector<std::uint8_t> planar_;
  unsigned skip_ = 1;
  std::uint64_t chunk_ = 0;  // bytes per interleave chunk
};

// Decodes a file that scanDds accepted. `interleaveBlock` is 2^24 for real
// files; tests lower it to exercise v3e chunking on small data.
DdsPayload decodeDds(std::span<const std::uint8_t> file, const DdsStreamInfo& info,
                     std::uint64_t interleaveBlock = kDdsInterleaveBlock);

// Encodes `payload` as a DDS file (magic included) by the same scheme: runs
// of equal value width, up to 127 values each. The tests use it to feed the
// decoder every shape of data; a writer could use it too.
std::vector<std::uint8_t> encodeDds(std::span<const std::uint8_t> payload, unsigned skip,
                                    unsigned strip, DdsVersion version,
                                    std::uint64_t interleaveBlock = kDdsInterleaveBlock);

}  // namespace tessera::io_detail
