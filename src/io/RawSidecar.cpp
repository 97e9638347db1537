// Raw voxels described by a JSON sidecar (declared in tessera/io/PvmReader.h):
//   data.raw + data.raw.json (or data.json), e.g.
//   {"dims": [256, 256, 128], "type": "u16", "spacing": [0.5, 0.5, 1.2],
//    "origin": [0, 0, 0], "direction": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
//    "endian": "little", "offset": 0, "file": "data.raw"}
// Only dims and type are required; unknown keys are errors, so that a typo
// ("spacings") is reported instead of silently ignored.
// Geometry is Tessera's own (core/PatientFrame.h), RAS+ mm: "origin" is
// voxel (0,0,0)'s centre, "direction" lists the unit direction of index axis
// i, then j, then k (the columns of the direction matrix, like NRRD's "space
// directions" without the spacing), so world = origin + sum over a of
// direction[a] * spacing[a] * index[a]. Without "direction": identity.
#include "tessera/io/PvmReader.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/ByteSource.h"
#include "io/VoxelLoader.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"

namespace tessera {

namespace {

using io_detail::DiskType;
using nlohmann::json;

constexpr std::int64_t kMaxDim = 1 << 20;  // the limit Volume::allocate applies
constexpr std::uint64_t kMaxSidecarBytes = 1 << 20;
constexpr const char* kKeys = "dims, type, spacing, origin, direction, endian, offset, file";
// How far from 1 a direction's length may be (hand-written 0.7071...).
constexpr double kUnitTolerance = 1e-4;

struct Sidecar {
  glm::ivec3 dims{0, 0, 0};
  DiskType type = DiskType::U8;
  glm::dvec3 spacing{1.0, 1.0, 1.0};
  glm::dvec3 origin{0.0, 0.0, 0.0};
  std::optional<glm::dmat3> direction;
  bool bigEndian = false;
  std::uint64_t offset = 0;
  std::optional<std::string> file;
};

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string numberString(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

class SidecarParser {
 public:
  explicit SidecarParser(std::string path) : p_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& msg) const { throw InputError(p_ + ": " + msg); }

  Sidecar parse(const std::string& text) const {
    json root;
    try {
      root = json::parse(text);
    } catch (const json::exception& e) {  // parse_error, or out_of_range for 1e999
      fail(std::string("malformed JSON: ") + e.what());
    }
    if (!root.is_object())
      fail("expected a JSON object like {\"dims\": [x, y, z], \"type\": \"u8\"}");
    Sidecar s;
    bool hasDims = false;
    bool hasType = false;
    for (const auto& [key, value] : root.items()) {
      if (key == "dims") {
        const auto v = triple(value, key);
        for (int a = 0; a < 3; ++a) {
          if (!v[a].is_number_integer())
            fail("dims[" + std::to_string(a) + "] is " + v[a].dump() + ", expected a whole number");
          const bool negative = v[a].is_number_integer() && !v[a].is_number_unsigned();
          const std::uint64_t d = negative ? 0 : v[a].get<std::uint64_t>();
          if (negative || d < 1 || d > static_cast<std::uint64_t>(kMaxDim)) {
            fail("dims[" + std::to_string(a) + "] is " + v[a].dump() + ", expected 1.." +
                 std::to_string(kMaxDim));
          }
          s.dims[a] = static_cast<int>(d);
        }
        hasDims = true;
      } else if (key == "type") {
        const std::string t = stringValue(value, key);
        if (t == "u8") {
          s.type = DiskType::U8;
        } else if (t == "u16") {
          s.type = DiskType::U16;
        } else if (t == "i16") {
          s.type = DiskType::I16;
        } else if (t == "f32") {
          s.type = DiskType::F32;
        } else {
          fail("type is \"" + t + "\", expected \"u8\", \"u16\", \"i16\" or \"f32\"");
        }
        hasType = true;
      } else if (key == "spacing") {
        const auto v = numbers(value, key);
        for (int a = 0; a < 3; ++a) {
          if (!(v[a] > 0.0))
            fail("spacing[" + std::to_string(a) + "] is " + numberString(v[a]) +
                 ", expected a finite value > 0");
        }
        s.spacing = glm::dvec3(v[0], v[1], v[2]);
      } else if (key == "origin") {
        const auto v = numbers(value, key);
        s.origin = glm::dvec3(v[0], v[1], v[2]);
      } else if (key == "direction") {
        s.direction = direction(value);
      } else if (key == "endian") {
        const std::string e = stringValue(value, key);
        if (e != "little" && e != "big")
          fail("endian is \"" + e + "\", expected \"little\" or \"big\"");
        s.bigEndian = e == "big";
      } else if (key == "offset") {
        if (!value.is_number_unsigned())
          fail("offset is " + value.dump() + ", expected a whole number of bytes >= 0");
        s.offset = value.get<std::uint64_t>();
      } else if (key == "file") {
        const std::string f = stringValue(value, key);
        if (f.empty()) fail("file is empty, expected the name of the raw file");
        s.file = f;
      } else {
        fail("unknown key \"" + key + "\"; expected only " + kKeys);
      }
    }
    if (!hasDims) fail("no \"dims\": [x, y, z]");
    if (!hasType) fail("no \"type\" (\"u8\", \"u16\", \"i16\" or \"f32\")");
    return s;
  }

 private:
  std::array<json, 3> triple(const json& value, const std::string& key) const {
    if (!value.is_array() || value.size() != 3)
      fail(key + " is " + value.dump() + ", expected an array of 3 numbers");
    return {value[0], value[1], value[2]};
  }

  std::array<double, 3> numbers(const json& value, const std::string& key) const {
    const auto v = triple(value, key);
    std::array<double, 3> out{};
    for (int a = 0; a < 3; ++a) {
      if (!v[a].is_number())
        fail(key + "[" + std::to_string(a) + "] is " + v[a].dump() + ", expected a number");
      out[a] = v[a].get<double>();
      if (!std::isfinite(out[a]))
        fail(key + "[" + std::to_string(a) + "] is " + numberString(out[a]) +
             ", expected a finite number");
    }
    return out;
  }

  // [[ix, iy, iz], [jx, jy, jz], [kx, ky, kz]]: unit vectors, one per axis.
  glm::dmat3 direction(const json& value) const {
    if (!value.is_array() || value.size() != 3) {
      fail("direction is " + value.dump() +
           ", expected 3 unit vectors [[ix, iy, iz], [jx, jy, jz], [kx, ky, kz]]");
    }
    glm::dmat3 d;
    for (int a = 0; a < 3; ++a) {
      const std::string key = "direction[" + std::to_string(a) + "]";
      const auto v = numbers(value[static_cast<std::size_t>(a)], key);
      d[a] = glm::dvec3(v[0], v[1], v[2]);
      const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      if (std::abs(len - 1.0) > kUnitTolerance) {
        fail(key + " has length " + numberString(len) +
             ", expected a unit vector (the voxel size goes in \"spacing\")");
      }
    }
    return d;
  }

  std::string stringValue(const json& value, const std::string& key) const {
    if (!value.is_string()) fail(key + " is " + value.dump() + ", expected a string");
    return value.get<std::string>();
  }

  std::string p_;
};

std::string readSidecarText(const std::filesystem::path& path) {
  const std::uint64_t size = io_detail::regularFileSize(path);
  if (size > kMaxSidecarBytes) {
    throw InputError(path.string() + ": " + std::to_string(size) +
                     " bytes is too large for a JSON sidecar (at most " +
                     std::to_string(kMaxSidecarBytes) + ")");
  }
  io_detail::FileByteSource src(path, 0);
  std::string text(static_cast<std::size_t>(size), '\0');
  text.resize(src.read(reinterpret_cast<std::byte*>(text.data()), text.size()));
  return text;
}

bool isFile(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_regular_file(p, ec);
}

bool sameFile(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code ec;
  const bool same = std::filesystem::equivalent(a, b, ec);
  return !ec && same;
}

}  // namespace

Volume readRawWithSidecar(const std::filesystem::path& path) {
  const std::string p = path.string();
  std::filesystem::path sidecarPath;
  std::filesystem::path rawPath;
  const bool givenJson = endsWith(path.filename().string(), ".json");
  if (givenJson) {
    sidecarPath = path;
  } else {
    io_detail::regularFileSize(path);  // the raw file itself: "no such file" names it
    std::filesystem::path beside = path;
    beside += ".json";
    std::filesystem::path stem = path;
    stem.replace_extension(".json");
    if (isFile(beside)) {
      sidecarPath = beside;
    } else if (isFile(stem)) {
      sidecarPath = stem;
    } else {
      throw InputError(p + ": no JSON sidecar describing it (looked for " + beside.string() +
                       " and " + stem.string() + ")");
    }
    rawPath = path;
  }
  const std::string sp = sidecarPath.string();
  const Sidecar s = SidecarParser(sp).parse(readSidecarText(sidecarPath));

  if (givenJson) {
    if (s.file) {
      rawPath = std::filesystem::path(*s.file);
      // Like NRRD's "data file", a relative name is relative to the sidecar.
      if (rawPath.is_relative()) rawPath = sidecarPath.parent_path() / rawPath;
    } else {
      rawPath = std::filesystem::path(sp.substr(0, sp.size() - 5));  // data.raw.json → data.raw
      if (!isFile(rawPath)) {
        throw InputError(sp + ": no \"file\" key naming the raw data, and no " + rawPath.string() +
                         " beside it");
      }
    }
    if (!isFile(rawPath)) {
      throw InputError(sp + ": raw file " + rawPath.string() +
                       " named by \"file\" does not exist or is not a regular file");
    }
  } else if (s.file) {
    std::filesystem::path named(*s.file);
    if (named.is_relative()) named = sidecarPath.parent_path() / named;
    if (!sameFile(named, rawPath)) {
      throw InputError(sp + ": describes \"file\": \"" + *s.file + "\", not " + p);
    }
  }

  if (s.direction) {
    // Singular directions are refused before any voxel is read.
    try {
      Volume().setDirection(*s.direction);
    } catch (const InputError& e) {
      throw InputError(sp + ": direction: " + e.what());
    }
  }
  io_detail::VoxelFormat format;
  format.dims = s.dims;
  format.type = s.type;
  format.bigEndian = s.bigEndian;
  const std::uint64_t rawSize = io_detail::regularFileSize(rawPath);
  const std::uint64_t needed =
      static_cast<std::uint64_t>(s.dims.x) * static_cast<std::uint64_t>(s.dims.y) *
      static_cast<std::uint64_t>(s.dims.z) * io_detail::diskTypeSize(s.type);
  const std::string declared = sp + ": declares " + io_detail::dimsString(s.dims) + " " +
                               std::string(io_detail::diskTypeName(s.type)) + " = " +
                               std::to_string(needed) + " bytes (" + formatBytes(needed) +
                               ") of voxel data at offset " + std::to_string(s.offset) + ", but " +
                               rawPath.string() + " has " + std::to_string(rawSize) + " bytes";
  if (s.offset > rawSize) {
    throw InputError(sp + ": offset " + std::to_string(s.offset) + " lies beyond the end of " +
                     rawPath.string() + " (" + std::to_string(rawSize) + " bytes)");
  }
  if (rawSize - s.offset < needed) {
    throw InputError(declared + " (" + std::to_string(needed - (rawSize - s.offset)) + " too few)");
  }
  if (rawSize - s.offset > needed) {
    // A larger file means dims or type are wrong far more often than that
    // trailing bytes are meant to be ignored.
    throw InputError(declared + " (" + std::to_string(rawSize - s.offset - needed) +
                     " more than declared; check dims, type and offset)");
  }
  io_detail::VoxelSource source;
  source.file = rawPath;
  source.fileOffset = s.offset;
  Volume v = io_detail::loadVoxels(source, format, sp);
  v.setSpacing(s.spacing);
  v.setOrigin(s.origin);
  if (s.direction) v.setDirection(*s.direction);  // checked above
  v.setGeometrySource(s.direction ? "JSON sidecar direction, spacing and origin (RAS)"
                                  : "JSON sidecar spacing and origin (no direction: identity)");
  v.setDescription(
      "raw " + rawPath.string() + " described by " + sp + " (" + io_detail::dimsString(s.dims) +
      " " + std::string(io_detail::diskTypeName(s.type)) +
      (io_detail::diskTypeSize(s.type) > 1 ? s.bigEndian ? ", big endian" : ", little endian"
                                           : "") +
      ")");
  return v;
}

namespace {

// Output written under a temporary name beside the target and renamed over
// it only once complete, so that a failed write never leaves a partial file
// under the final name.
class PendingFile {
 public:
  explicit PendingFile(const std::filesystem::path& target) : target_(target) {
    static int counter = 0;
    const std::filesystem::path dir = target.parent_path().empty() ? "." : target.parent_path();
    std::string name = target.filename().string();
    // A hidden name, built piecewise: GCC 12 warns falsely on "." + string.
    name.insert(0, 1, '.');
    name += '.';
    name += std::to_string(::getpid());
    name += '-';
    name += std::to_string(counter++);
    name += ".tmp";
    temp_ = dir / name;
    const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 || (file_ = ::fdopen(fd, "wb")) == nullptr) {
      const int err = errno;
      if (fd >= 0) ::close(fd);
      throw Error(target_.string() + ": cannot create a temporary file in '" + dir.string() +
                  "' to write it: " + std::strerror(err));
    }
  }
  ~PendingFile() {
    if (file_ != nullptr) std::fclose(file_);
    if (!committed_) {
      std::error_code ignored;
      std::filesystem::remove(temp_, ignored);
    }
  }
  PendingFile(const PendingFile&) = delete;
  PendingFile& operator=(const PendingFile&) = delete;

  void write(const void* data, std::size_t n) {
    if (std::fwrite(data, 1, n, file_) != n) fail("write failed");
  }
  // Closes the temporary; rename() then moves it into place.
  void close() {
    const int rc = std::fclose(file_);
    file_ = nullptr;
    if (rc != 0) fail("write failed");
  }
  void rename() {
    if (std::rename(temp_.c_str(), target_.c_str()) != 0) fail("cannot rename the temporary file");
    committed_ = true;
  }

 private:
  [[noreturn]] void fail(const char* what) const {
    throw Error(target_.string() + ": " + what + ": " + std::strerror(errno));
  }

  std::filesystem::path target_;
  std::filesystem::path temp_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
};

}  // namespace

void writeRawWithSidecar(const Volume& volume, const std::filesystem::path& path) {
  if (!volume.hasData()) throw InputError(path.string() + ": cannot write a volume without voxels");
  const glm::ivec3 d = volume.dims();
  const glm::dvec3 s = volume.spacing();
  const glm::dvec3 o = volume.origin();
  // nlohmann writes doubles with enough digits to read back the same value.
  nlohmann::ordered_json sidecar;
  sidecar["dims"] = {d.x, d.y, d.z};
  sidecar["type"] = std::string(scalarTypeName(volume.type()));
  sidecar["spacing"] = {s.x, s.y, s.z};
  sidecar["origin"] = {o.x, o.y, o.z};
  // + 0.0 writes -0 as 0.
  const glm::dmat3 dir = volume.direction() + glm::dmat3(0.0);
  sidecar["direction"] = {{dir[0].x, dir[0].y, dir[0].z},
                          {dir[1].x, dir[1].y, dir[1].z},
                          {dir[2].x, dir[2].y, dir[2].z}};
  sidecar["endian"] = "little";
  sidecar["offset"] = 0;
  sidecar["file"] = path.filename().string();
  const std::string text = sidecar.dump(2) + "\n";

  std::filesystem::path sidecarPath = path;
  sidecarPath += ".json";
  PendingFile raw(path);
  const std::span<const std::byte> bytes = volume.bytes();
  const std::size_t elem = bytesPerVoxel(volume.type());
  if (elem == 1 || std::endian::native == std::endian::little) {
    raw.write(bytes.data(), bytes.size());
  } else {
    std::vector<std::byte> chunk;
    constexpr std::size_t kChunk = 1 << 20;
    for (std::size_t at = 0; at < bytes.size(); at += kChunk) {
      const std::size_t n = std::min(kChunk, bytes.size() - at);
      chunk.assign(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                   bytes.begin() + static_cast<std::ptrdiff_t>(at + n));
      for (std::size_t i = 0; i + elem <= n; i += elem) {
        std::reverse(chunk.begin() + static_cast<std::ptrdiff_t>(i),
                     chunk.begin() + static_cast<std::ptrdiff_t>(i + elem));
      }
      raw.write(chunk.data(), n);
    }
  }
  raw.close();
  PendingFile sidecarOut(sidecarPath);
  sidecarOut.write(text.data(), text.size());
  sidecarOut.close();
  // Both are complete before either replaces an older version.
  raw.rename();
  sidecarOut.rename();
}

}  // namespace tessera
