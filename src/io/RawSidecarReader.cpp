// Raw voxels described by a JSON sidecar (tessera/io/RawSidecarReader.h):
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
#include "tessera/io/RawSidecarReader.h"
#include "io/HeaderText.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

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

using io_detail::numberString;

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

std::string readSidecarText(const ByteSource& file) {
  if (file.size() > kMaxSidecarBytes) {
    throw InputError(file.name() + ": " + std::to_string(file.size()) +
                     " bytes is too large for a JSON sidecar (at most " +
                     std::to_string(kMaxSidecarBytes) + ")");
  }
  std::string text(static_cast<std::size_t>(file.size()), '\0');
  text.resize(file.read(0, reinterpret_cast<std::byte*>(text.data()), text.size()));
  return text;
}

// Whether two names of the files in a FileSet are the same file: on disk
// one may be relative, the other absolute, or a link to it.
bool sameFile(const std::string& a, const std::string& b) {
  if (a == b) return true;
  std::error_code ec;
  const bool same = std::filesystem::equivalent(a, b, ec);
  return !ec && same;
}

}  // namespace

Volume readRawWithSidecar(const std::filesystem::path& path) {
  return readRawWithSidecar(FileSource(path), FolderFiles());
}

Volume readRawWithSidecar(const ByteSource& file, const FileSet& files) {
  const std::string& p = file.name();
  std::unique_ptr<ByteSource> sidecarFile;
  std::unique_ptr<ByteSource> rawFile;
  const bool givenJson = endsWith(p, ".json");
  if (!givenJson) {
    // data.raw.json, else data.json
    const std::string name = std::filesystem::path(p).filename().string();
    const std::string beside = files.resolve(file, name + ".json");
    const std::string stem =
        files.resolve(file, std::filesystem::path(name).replace_extension(".json").string());
    if (files.contains(beside)) {
      sidecarFile = files.open(beside);
    } else if (files.contains(stem)) {
      sidecarFile = files.open(stem);
    } else {
      throw InputError(p + ": no JSON sidecar describing it (looked for " + beside + " and " +
                       stem + ")");
    }
  }
  const ByteSource& sidecar = givenJson ? file : *sidecarFile;
  const std::string& sp = sidecar.name();
  const Sidecar s = SidecarParser(sp).parse(readSidecarText(sidecar));

  if (givenJson) {
    std::string rawName;
    if (s.file) {
      // Like NRRD's "data file", a relative name is relative to the sidecar.
      rawName = files.resolve(sidecar, *s.file);
      if (!files.contains(rawName)) {
        throw InputError(sp + ": raw file " + rawName +
                         " named by \"file\" does not exist or is not a regular file");
      }
    } else {
      // data.raw.json → data.raw
      const std::string name = std::filesystem::path(sp).filename().string();
      rawName = files.resolve(sidecar, name.substr(0, name.size() - 5));
      if (!files.contains(rawName)) {
        throw InputError(sp + ": no \"file\" key naming the raw data, and no " + rawName +
                         " beside it");
      }
    }
    rawFile = files.open(rawName);
  } else if (s.file) {
    const std::string named = files.resolve(sidecar, *s.file);
    if (!sameFile(named, p)) {
      throw InputError(sp + ": describes \"file\": \"" + *s.file + "\", not " + p);
    }
  }
  const ByteSource& raw = givenJson ? *rawFile : file;

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
  const std::uint64_t rawSize = raw.size();
  const std::uint64_t needed =
      static_cast<std::uint64_t>(s.dims.x) * static_cast<std::uint64_t>(s.dims.y) *
      static_cast<std::uint64_t>(s.dims.z) * io_detail::diskTypeSize(s.type);
  const std::string declared = sp + ": declares " + io_detail::dimsString(s.dims) + " " +
                               std::string(io_detail::diskTypeName(s.type)) + " = " +
                               std::to_string(needed) + " bytes (" + formatBytes(needed) +
                               ") of voxel data at offset " + std::to_string(s.offset) + ", but " +
                               raw.name() + " has " + std::to_string(rawSize) + " bytes";
  if (s.offset > rawSize) {
    throw InputError(sp + ": offset " + std::to_string(s.offset) + " lies beyond the end of " +
                     raw.name() + " (" + std::to_string(rawSize) + " bytes)");
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
  source.file = &raw;
  source.fileOffset = s.offset;
  Volume v = io_detail::loadVoxels(source, format, sp);
  v.setSpacing(s.spacing);
  v.setOrigin(s.origin);
  if (s.direction) v.setDirection(*s.direction);  // checked above
  v.setGeometrySource(s.direction ? "JSON sidecar direction, spacing and origin (RAS)"
                                  : "JSON sidecar spacing and origin (no direction: identity)");
  v.setDescription(
      "raw " + raw.name() + " described by " + sp + " (" + io_detail::dimsString(s.dims) + " " +
      std::string(io_detail::diskTypeName(s.type)) +
      (io_detail::diskTypeSize(s.type) > 1 ? s.bigEndian ? ", big endian" : ", little endian"
                                           : "") +
      ")");
  return v;
}

}  // namespace tessera
