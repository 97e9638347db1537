// PVM, the volume format of Roettger's volume library (V^3; ddsbase.cpp's
// readPVMvolume/writePVMvolume define it):
//   "PVM\n"  "W H D\n" "C\n"                 voxels
//   "PVM2\n" "W H D\n" "SX SY SZ\n" "C\n"     voxels
//   "PVM3\n" "W H D\n" "SX SY SZ\n" "C\n"     voxels, then four zero-terminated
//            strings: description, courtesy, parameter, comment
// with C bytes per voxel (2 = 16 bit, most significant byte first), x
// fastest. The file is usually DDS-compressed as a whole (io/PvmDds.h).
#include "tessera/io/PvmReader.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "io/ByteStream.h"
#include "io/HeaderText.h"
#include "io/PvmDds.h"
#include "io/VoxelLoader.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"

namespace tessera {

namespace {

using io_detail::DiskType;

constexpr std::int64_t kMaxDim = 1 << 20;  // the limit Volume::allocate applies
// The header is four short lines; ddsbase.cpp formats it into 256 bytes.
constexpr std::size_t kMaxHeaderBytes = 1024;
// The trailing strings of a PVM3 file are a few lines of text.
constexpr std::uint64_t kMaxTrailerBytes = 64 * 1024;

struct PvmHeader {
  int version = 1;  // 1, 2, 3 for "PVM", "PVM2", "PVM3"
  glm::ivec3 dims{0, 0, 0};
  glm::dvec3 spacing{1.0, 1.0, 1.0};
  int components = 1;
  std::size_t dataOffset = 0;  // bytes of header text before the voxels
};

std::string printable(std::string_view s, std::size_t limit) {
  std::string out;
  for (char c : s.substr(0, limit)) {
    if (c == '\n') {
      out += "\\n";
    } else {
      out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
    }
  }
  return out;
}

using io_detail::numberString;

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const std::size_t b = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > b) out.push_back(line.substr(b, i - b));
  }
  return out;
}

// Reads the header lines from the first bytes of the (decoded) file.
class HeaderParser {
 public:
  HeaderParser(std::string text, std::string path) : text_(std::move(text)), p_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& msg) const {
    throw InputError(p_ + ": PVM header line " + std::to_string(line_) + ": " + msg);
  }

  std::string_view nextLine(const char* what) {
    ++line_;
    const std::size_t end = text_.find('\n', pos_);
    if (end == std::string::npos) {
      if (text_.size() >= kMaxHeaderBytes) {
        fail("no end of line within the first " + std::to_string(kMaxHeaderBytes) +
             " bytes where the " + what + " should be; not a PVM header");
      }
      fail("the file ends where the " + std::string(what) + " should be");
    }
    std::string_view line(text_.data() + pos_, end - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = end + 1;
    return line;
  }

  std::int64_t whole(std::string_view s, const char* name) const {
    std::int64_t v = 0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec == std::errc::result_out_of_range) {
      fail(std::string(name) + " '" + std::string(s) + "' is out of range, expected 1.." +
           std::to_string(kMaxDim));
    }
    if (ec != std::errc() || ptr != s.data() + s.size()) {
      fail(std::string(name) + " '" + printable(s, 40) + "' is not a whole number");
    }
    return v;
  }

  double real(std::string_view s, const char* name) const {
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || ptr != s.data() + s.size()) {
      fail(std::string(name) + " '" + printable(s, 40) + "' is not a number");
    }
    return v;
  }

  std::size_t position() const { return pos_; }

 private:
  std::string text_;
  std::string p_;
  std::size_t pos_ = 0;
  int line_ = 0;
};

std::string notPvmMessage(const std::string& p, std::string_view start) {
  return p + ": not a PVM file: starts with '" + printable(start, 16) +
         "', expected 'PVM', 'PVM2', 'PVM3' or the DDS magic 'DDS v3d'/'DDS v3e'";
}

// `text` holds the first bytes of the uncompressed file (at most
// kMaxHeaderBytes).
PvmHeader parseHeader(std::string text, const std::string& p) {
  HeaderParser parse(std::move(text), p);
  PvmHeader h;
  const std::string_view magic = parse.nextLine("magic");
  if (magic == "PVM") {
    h.version = 1;
  } else if (magic == "PVM2") {
    h.version = 2;
  } else if (magic == "PVM3") {
    h.version = 3;
  } else {
    throw InputError(notPvmMessage(p, magic));
  }

  const auto dims = words(parse.nextLine("dimensions"));
  if (dims.size() != 3) {
    parse.fail("expected the dimensions 'width height depth', found " +
               std::to_string(dims.size()) + " values");
  }
  static const char* const kDimNames[] = {"width", "height", "depth"};
  for (int a = 0; a < 3; ++a) {
    const std::int64_t d = parse.whole(dims[a], kDimNames[a]);
    if (d < 1 || d > kMaxDim) {
      parse.fail(std::string(kDimNames[a]) + " is " + std::to_string(d) + ", expected 1.." +
                 std::to_string(kMaxDim));
    }
    h.dims[a] = static_cast<int>(d);
  }

  if (h.version >= 2) {
    const auto spacing = words(parse.nextLine("voxel spacing"));
    if (spacing.size() != 3) {
      parse.fail("expected the voxel spacing 'sx sy sz', found " + std::to_string(spacing.size()) +
                 " values");
    }
    static const char* const kSpacingNames[] = {"spacing x", "spacing y", "spacing z"};
    for (int a = 0; a < 3; ++a) {
      const double s = parse.real(spacing[a], kSpacingNames[a]);
      if (!std::isfinite(s) || s <= 0.0) {
        parse.fail(std::string(kSpacingNames[a]) + " is " + numberString(s) +
                   ", expected a finite value > 0");
      }
      h.spacing[a] = s;
    }
  }

  const auto components = words(parse.nextLine("component count"));
  if (components.size() != 1) parse.fail("expected the number of components per voxel");
  const std::int64_t c = parse.whole(components[0], "component count");
  if (c == 3 || c == 4) {
    parse.fail(std::to_string(c) + " components per voxel (" + (c == 3 ? "RGB" : "RGBA") +
               ") are not supported: Tessera reads scalar volumes, 1 (8 bit) or 2 (16 bit) "
               "components");
  }
  if (c != 1 && c != 2) {
    parse.fail("component count is " + std::to_string(c) + ", expected 1 (8 bit) or 2 (16 bit)");
  }
  h.components = static_cast<int>(c);
  h.dataOffset = parse.position();
  return h;
}

std::uint64_t voxelBytes(const PvmHeader& h) {
  return static_cast<std::uint64_t>(h.dims.x) * static_cast<std::uint64_t>(h.dims.y) *
         static_cast<std::uint64_t>(h.dims.z) * static_cast<std::uint64_t>(h.components);
}

// "PVM3 /data/bucky.pvm (32x32x32 u8, uncompressed"; the caller closes it.
std::string describe(const PvmHeader& h, const std::string& p, const char* encoding) {
  return "PVM" + (h.version > 1 ? std::to_string(h.version) : std::string()) + " " + p + " (" +
         io_detail::dimsString(h.dims) + (h.components == 1 ? " u8, " : " u16, ") + encoding;
}

std::string readPrefix(const ByteSource& file, std::uint64_t offset, std::size_t n) {
  std::string s(n, '\0');
  s.resize(file.read(offset, reinterpret_cast<std::byte*>(s.data()), n));
  return s;
}

// Splits the PVM3 trailer into its zero-terminated strings and adds the
// non-empty ones to the description; picks up Tessera's origin tag.
void applyTrailer(std::string_view trailer, Volume& v, std::string& description,
                  const std::string& p) {
  static const char* const kNames[] = {"description", "courtesy", "parameter", "comment"};
  std::size_t at = 0;
  for (const char* name : kNames) {
    if (at >= trailer.size()) break;
    std::size_t end = trailer.find('\0', at);
    if (end == std::string_view::npos) end = trailer.size();
    const std::string_view text = trailer.substr(at, end - at);
    at = end + 1;
    if (text.empty()) continue;
    if (std::string_view(name) == "comment" &&
        text.substr(0, io_detail::kPvmOriginTag.size()) == io_detail::kPvmOriginTag) {
      const auto w = words(text.substr(io_detail::kPvmOriginTag.size()));
      glm::dvec3 o(0.0);
      bool ok = w.size() == 3;
      for (int a = 0; ok && a < 3; ++a) {
        const auto [ptr, ec] = std::from_chars(w[a].data(), w[a].data() + w[a].size(), o[a]);
        ok = ec == std::errc() && ptr == w[a].data() + w[a].size() && std::isfinite(o[a]);
      }
      if (!ok) {
        throw InputError(p + ": PVM comment '" + printable(text, 80) +
                         "' should hold three finite numbers after '" +
                         std::string(io_detail::kPvmOriginTag) + "'");
      }
      v.setOrigin(o);
      continue;
    }
    description += std::string(", ") + name + ": " + printable(text, 200);
  }
}

Volume readDdsPvm(const ByteSource& source) {
  const std::string& p = source.name();
  const std::uint64_t fileSize = source.size();
  HostBudget::global().check(fileSize, p + " (DDS-compressed file)");
  std::vector<std::uint8_t> file(static_cast<std::size_t>(fileSize));
  if (source.read(0, reinterpret_cast<std::byte*>(file.data()), file.size()) != file.size()) {
    throw InputError(p + ": file shrank while being read");
  }
  const io_detail::DdsStreamInfo info = io_detail::scanDds(file, p);
  // The decoded file and the volume it holds coexist while copying.
  HostBudget::global().check(fileSize + 2 * info.decodedSize, p + " (DDS data decoding to " +
                                                                  formatBytes(info.decodedSize) +
                                                                  ", plus the volume it holds)");
  const io_detail::DdsPayload payload = io_detail::decodeDds(file, info);
  std::vector<std::uint8_t>().swap(file);

  const std::string head = payload.bytesAt(0, kMaxHeaderBytes);
  if (head.rfind("PVM", 0) != 0) {
    throw InputError(p + ": DDS data decodes to something that is not a PVM volume (starts with '" +
                     printable(head, 16) + "')");
  }
  const PvmHeader h = parseHeader(head, p);
  const std::uint64_t bytes = voxelBytes(h);
  if (h.dataOffset + bytes > payload.size()) {
    throw InputError(p + ": header says " + io_detail::dimsString(h.dims) + " " +
                     (h.components == 1 ? "u8" : "u16") + " = " + std::to_string(bytes) +
                     " bytes of voxel data after a " + std::to_string(h.dataOffset) +
                     "-byte header, but the DDS data decode to " + std::to_string(payload.size()) +
                     " bytes");
  }
  const bool u16 = h.components == 2;
  Volume v = Volume::allocate(h.dims, u16 ? ScalarType::U16 : ScalarType::U8, p);
  auto* dst = reinterpret_cast<std::uint8_t*>(v.bytes().data());
  payload.copy(h.dataOffset, bytes, dst);
  if (u16 && std::endian::native == std::endian::little) {
    for (std::uint64_t i = 0; i + 1 < bytes; i += 2) std::swap(dst[i], dst[i + 1]);
  }
  v.invalidateRange();
  v.setSpacing(h.spacing);

  std::string description = describe(
      h, p,
      info.version == io_detail::DdsVersion::V3d ? "DDS v3d-compressed" : "DDS v3e-compressed");
  if (h.version == 3) {
    applyTrailer(payload.bytesAt(h.dataOffset + bytes, kMaxTrailerBytes), v, description, p);
  }
  v.setDescription(description + ")");
  return v;
}

}  // namespace

Volume readPvm(const std::filesystem::path& path) {
  return readPvm(FileSource(path));
}

Volume readPvm(const ByteSource& file) {
  const std::string& p = file.name();
  const std::uint64_t fileSize = file.size();
  const std::string head = readPrefix(file, 0, kMaxHeaderBytes);
  if (io_detail::ddsVersionOf(head)) return readDdsPvm(file);
  if (head.rfind("PVM", 0) != 0) throw InputError(notPvmMessage(p, head));

  const PvmHeader h = parseHeader(head, p);
  io_detail::VoxelFormat format;
  format.dims = h.dims;
  format.type = h.components == 1 ? DiskType::U8 : DiskType::U16;
  format.bigEndian = true;  // ddsbase.cpp: 16-bit voxels are stored MSB first
  io_detail::VoxelSource source;
  source.file = &file;
  source.fileOffset = h.dataOffset;
  Volume v = io_detail::loadVoxels(source, format, p);
  v.setSpacing(h.spacing);

  std::string description = describe(h, p, "uncompressed");
  if (h.version == 3) {
    const std::uint64_t trailerStart = h.dataOffset + voxelBytes(h);
    const std::uint64_t n = std::min(kMaxTrailerBytes, fileSize - trailerStart);
    applyTrailer(readPrefix(file, trailerStart, static_cast<std::size_t>(n)), v, description, p);
  }
  v.setDescription(description + ")");
  return v;
}

}  // namespace tessera
