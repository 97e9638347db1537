#include "tessera/viewer/InMemoryVolumeReader.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/NiftiGeometry.h"
#include "tessera/io/NrrdGeometry.h"

namespace tessera::viewer {

namespace {

bool endsWith(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  return std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(), [](char a, char b) {
    return std::tolower(static_cast<unsigned char>(a)) ==
           std::tolower(static_cast<unsigned char>(b));
  });
}

bool startsWith(std::span<const std::byte> b, const char* magic) {
  const std::size_t n = std::strlen(magic);
  return b.size() >= n && std::memcmp(b.data(), magic, n) == 0;
}

// How stored voxels become Volume values.
enum class SourceType { U8, I8, U16, I16, I32, U32, F32, F64 };

std::size_t sourceBytes(SourceType t) {
  switch (t) {
    case SourceType::U8:
    case SourceType::I8:
      return 1;
    case SourceType::U16:
    case SourceType::I16:
      return 2;
    case SourceType::I32:
    case SourceType::U32:
    case SourceType::F32:
      return 4;
    case SourceType::F64:
      return 8;
  }
  return 1;
}

const char* sourceName(SourceType t) {
  switch (t) {
    case SourceType::U8:
      return "uint8";
    case SourceType::I8:
      return "int8";
    case SourceType::U16:
      return "uint16";
    case SourceType::I16:
      return "int16";
    case SourceType::I32:
      return "int32";
    case SourceType::U32:
      return "uint32";
    case SourceType::F32:
      return "float32";
    case SourceType::F64:
      return "float64";
  }
  return "?";
}

struct Layout {
  glm::ivec3 dims{0};
  // Placement, from the same io/NiftiGeometry and io/NrrdGeometry maths as
  // the native readers.
  glm::dmat4 indexToWorld{1.0};
  std::string geometrySource;
  SourceType type = SourceType::U8;
  bool swap = false;  // stored big-endian (this code runs on little-endian hosts)
  double slope = 1.0, inter = 0.0;
};

template <class T>
T load(const std::byte* p, bool swap) {
  std::array<std::byte, sizeof(T)> b;
  std::memcpy(b.data(), p, sizeof(T));
  if (swap) std::reverse(b.begin(), b.end());
  T v;
  std::memcpy(&v, b.data(), sizeof(T));
  return v;
}

// Converts the voxels at `data` (already checked to hold dims x type bytes).
Volume convert(const Layout& l, const std::byte* data, const std::string& name) {
  const bool scaled = !(l.slope == 1.0 && l.inter == 0.0);
  ScalarType out = ScalarType::F32;
  if (!scaled) {
    switch (l.type) {
      case SourceType::U8:
        out = ScalarType::U8;
        break;
      case SourceType::I8:
      case SourceType::I16:
        out = ScalarType::I16;
        break;
      case SourceType::U16:
        out = ScalarType::U16;
        break;
      default:
        out = ScalarType::F32;
    }
  }
  Volume v = Volume::allocate(l.dims, out, name);
  v.setIndexToWorld(l.indexToWorld);
  v.setGeometrySource(l.geometrySource);
  const std::size_t n = static_cast<std::size_t>(v.voxelCount());
  const std::size_t bpv = sourceBytes(l.type);
  for (std::size_t i = 0; i < n; ++i) {
    const std::byte* p = data + i * bpv;
    double value = 0.0;
    switch (l.type) {
      case SourceType::U8:
        value = static_cast<double>(std::to_integer<std::uint8_t>(*p));
        break;
      case SourceType::I8:
        value = static_cast<double>(static_cast<std::int8_t>(std::to_integer<std::uint8_t>(*p)));
        break;
      case SourceType::U16:
        value = load<std::uint16_t>(p, l.swap);
        break;
      case SourceType::I16:
        value = load<std::int16_t>(p, l.swap);
        break;
      case SourceType::I32:
        value = load<std::int32_t>(p, l.swap);
        break;
      case SourceType::U32:
        value = load<std::uint32_t>(p, l.swap);
        break;
      case SourceType::F32:
        value = load<float>(p, l.swap);
        break;
      case SourceType::F64:
        value = load<double>(p, l.swap);
        break;
    }
    v.setValueAtIndex(i, value * l.slope + l.inter);
  }
  v.invalidateRange();
  std::ostringstream d;
  d << name << " (" << sourceName(l.type);
  if (scaled) d << ", scaled by " << l.slope << " and " << l.inter;
  d << ", read in memory)";
  v.setDescription(d.str());
  return v;
}

// Checks dims x type against the bytes present, before anything is allocated.
const std::byte* checkedPayload(const Layout& l, std::span<const std::byte> bytes,
                                std::uint64_t offset, const std::string& name) {
  for (int a = 0; a < 3; ++a) {
    if (l.dims[a] < 1) {
      throw InputError(name + ": dimension " + std::to_string(a + 1) + " is " +
                       std::to_string(l.dims[a]) + ", expected >= 1");
    }
  }
  const std::uint64_t voxels = static_cast<std::uint64_t>(l.dims.x) *
                               static_cast<std::uint64_t>(l.dims.y) *
                               static_cast<std::uint64_t>(l.dims.z);
  const std::uint64_t need = voxels * sourceBytes(l.type);
  const std::uint64_t have = bytes.size() > offset ? bytes.size() - offset : 0;
  if (offset > bytes.size() || need > have) {
    throw InputError(name + ": header says " + std::to_string(l.dims.x) + "x" +
                     std::to_string(l.dims.y) + "x" + std::to_string(l.dims.z) + " " +
                     sourceName(l.type) + " = " + formatBytes(need) + " from byte " +
                     std::to_string(offset) + ", but the file has " + formatBytes(have) +
                     " of data (truncated or not this format)");
  }
  HostBudget::global().check(voxels * 4, name);
  return bytes.data() + offset;
}

Volume readNifti1(const std::string& name, std::span<const std::byte> b) {
  if (b.size() < 348) {
    throw InputError(name + ": " + std::to_string(b.size()) +
                     " bytes is too short for a NIfTI-1 header (348 bytes)");
  }
  const std::byte* h = b.data();
  bool swap = false;
  const std::int32_t sizeofHdr = load<std::int32_t>(h, false);
  if (sizeofHdr == 540 || load<std::int32_t>(h, true) == 540) {
    throw InputError(name +
                     ": NIfTI-2 is not read in the browser; convert it with "
                     "`tessera convert FILE out.nii` (NIfTI-1) or to .nrrd");
  }
  if (sizeofHdr != 348) {
    if (load<std::int32_t>(h, true) != 348) {
      throw InputError(name + ": not a NIfTI-1 file (sizeof_hdr is " + std::to_string(sizeofHdr) +
                       ", expected 348)");
    }
    swap = true;
  }
  const char* magic = reinterpret_cast<const char*>(h + 344);
  if (std::memcmp(magic, "n+1\0", 4) != 0) {
    if (std::memcmp(magic, "ni1\0", 4) == 0) {
      throw InputError(name +
                       ": a .hdr/.img pair cannot be opened as one file in the browser; "
                       "convert it to .nii first");
    }
    throw InputError(name + ": NIfTI-1 magic is not \"n+1\"");
  }
  std::array<std::int16_t, 8> dim{};
  for (int i = 0; i < 8; ++i)
    dim[static_cast<std::size_t>(i)] = load<std::int16_t>(h + 40 + 2 * i, swap);
  const int ndim = dim[0];
  if (ndim < 3 || ndim > 7) {
    throw InputError(name + ": dim[0] is " + std::to_string(ndim) +
                     "; Tessera reads 3-D volumes (dim[0] = 3, or more with single extra axes)");
  }
  for (int i = 4; i <= ndim; ++i) {
    if (dim[static_cast<std::size_t>(i)] != 1) {
      throw InputError(name + ": dim[" + std::to_string(i) + "] is " +
                       std::to_string(dim[static_cast<std::size_t>(i)]) +
                       "; series of volumes are not supported, expected 1");
    }
  }
  Layout l;
  l.swap = swap;
  l.dims = glm::ivec3(dim[1], dim[2], dim[3]);
  const std::int16_t datatype = load<std::int16_t>(h + 70, swap);
  switch (datatype) {
    case 2:
      l.type = SourceType::U8;
      break;
    case 4:
      l.type = SourceType::I16;
      break;
    case 8:
      l.type = SourceType::I32;
      break;
    case 16:
      l.type = SourceType::F32;
      break;
    case 64:
      l.type = SourceType::F64;
      break;
    case 256:
      l.type = SourceType::I8;
      break;
    case 512:
      l.type = SourceType::U16;
      break;
    case 768:
      l.type = SourceType::U32;
      break;
    default:
      throw InputError(name + ": NIfTI datatype " + std::to_string(datatype) +
                       " is not supported (uint8, int8, uint16, int16, int32, uint32, float32, "
                       "float64 are)");
  }
  // Offsets from nifti1.h.
  NiftiGeometryFields g;
  for (int a = 0; a < 4; ++a) {
    const double p = load<float>(h + 76 + 4 * a, swap);
    if (a > 0 && (!std::isfinite(p) || p == 0.0)) {
      std::ostringstream m;
      m << name << ": voxel size pixdim[" << a << "] is " << p
        << ", expected a finite non-zero value";
      throw InputError(m.str());
    }
    g.pixdim[static_cast<std::size_t>(a)] = p;
  }
  for (int a = 0; a < 3; ++a)
    g.dim[static_cast<std::size_t>(a)] = dim[static_cast<std::size_t>(a + 1)];
  g.qformCode = load<std::int16_t>(h + 252, swap);
  g.sformCode = load<std::int16_t>(h + 254, swap);
  g.quaternB = load<float>(h + 256, swap);
  g.quaternC = load<float>(h + 260, swap);
  g.quaternD = load<float>(h + 264, swap);
  g.qoffset = glm::dvec3(load<float>(h + 268, swap), load<float>(h + 272, swap),
                         load<float>(h + 276, swap));
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 4; ++col) {
      g.srow[static_cast<std::size_t>(row)][static_cast<std::size_t>(col)] =
          load<float>(h + 280 + 16 * row + 4 * col, swap);
    }
  }
  const NiftiGeometry geometry = niftiGeometry(g);
  l.indexToWorld = geometry.indexToWorld;
  l.geometrySource = geometry.source;
  const double voxOffset = load<float>(h + 108, swap);
  if (!std::isfinite(voxOffset) || voxOffset < 348.0 ||
      voxOffset > static_cast<double>(std::numeric_limits<std::uint32_t>::max())) {
    std::ostringstream m;
    m << name << ": vox_offset is " << voxOffset << ", expected >= 348";
    throw InputError(m.str());
  }
  const double slope = load<float>(h + 112, swap), inter = load<float>(h + 116, swap);
  if (std::isfinite(slope) && slope != 0.0 && !(slope == 1.0 && inter == 0.0)) {
    if (!std::isfinite(inter)) throw InputError(name + ": scl_inter is not finite");
    l.slope = slope;
    l.inter = inter;
  }
  const std::byte* data = checkedPayload(l, b, static_cast<std::uint64_t>(voxOffset), name);
  return convert(l, data, name);
}

std::vector<std::string> words(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

double number(const std::string& w, const std::string& field, const std::string& name) {
  try {
    std::size_t used = 0;
    const double v = std::stod(w, &used);
    if (used == w.size()) return v;
  } catch (const std::exception&) {
  }
  throw InputError(name + ": NRRD field '" + field + "': '" + w + "' is not a number");
}

// "(1,0,0) none (0,1,0)": one vector per "(...)", nothing for "none".
std::vector<std::optional<std::vector<double>>> nrrdVectors(const std::string& s,
                                                            const std::string& fieldName,
                                                            const std::string& name) {
  std::vector<std::optional<std::vector<double>>> out;
  for (const auto& w : words(s)) {
    if (w == "none") out.emplace_back(std::nullopt);
    if (w.front() == '(') out.emplace_back(std::vector<double>{});
    if (out.empty() || !out.back()) continue;
    std::string inner = w;
    std::replace(inner.begin(), inner.end(), ',', ' ');
    std::replace(inner.begin(), inner.end(), '(', ' ');
    std::replace(inner.begin(), inner.end(), ')', ' ');
    for (const auto& x : words(inner)) out.back()->push_back(number(x, fieldName, name));
  }
  return out;
}

struct NrrdHeader {
  std::size_t payload = 0;  // offset of the data after the blank line
  std::vector<std::pair<std::string, std::string>> fields;
};

// Splits the header into fields; InputError if it has no end.
NrrdHeader nrrdHeader(std::span<const std::byte> b, const std::string& name) {
  NrrdHeader h;
  const char* s = reinterpret_cast<const char*>(b.data());
  const std::size_t n = std::min<std::size_t>(b.size(), 1 << 20);
  std::size_t pos = 0;
  bool first = true;
  while (true) {
    const char* nl = static_cast<const char*>(std::memchr(s + pos, '\n', n - pos));
    if (!nl) {
      throw InputError(name +
                       ": NRRD header has no blank line before the data (detached "
                       "headers, .nhdr, cannot be opened in the browser)");
    }
    std::string line(s + pos, static_cast<std::size_t>(nl - (s + pos)));
    pos = static_cast<std::size_t>(nl - s) + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (first) {
      first = false;
      continue;  // the magic, checked by the caller
    }
    if (line.empty()) break;
    if (line[0] == '#') continue;
    const auto colon = line.find(": ");
    if (colon == std::string::npos) continue;  // key:=value pairs are not needed
    std::string key = line.substr(0, colon);
    for (char& c : key) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    h.fields.emplace_back(key, line.substr(colon + 2));
  }
  h.payload = pos;
  return h;
}

std::string field(const NrrdHeader& h, const std::string& key) {
  for (const auto& [k, v] : h.fields)
    if (k == key) return v;
  return {};
}

Volume readNrrd(const std::string& name, std::span<const std::byte> b, bool payloadInflated) {
  const NrrdHeader h = nrrdHeader(b, name);
  if (!field(h, "data file").empty() || !field(h, "datafile").empty()) {
    throw InputError(name +
                     ": NRRD with a detached data file cannot be opened in the browser; "
                     "save it with attached data (tessera convert FILE out.nrrd)");
  }
  const std::string enc = field(h, "encoding");
  const bool gz = enc == "gzip" || enc == "gz";
  if (!(enc == "raw" || (gz && payloadInflated))) {
    throw InputError(name + ": NRRD encoding '" + enc + "' is not supported here (raw, gzip are)");
  }
  const std::string t = field(h, "type");
  Layout l;
  if (t == "uchar" || t == "unsigned char" || t == "uint8" || t == "uint8_t")
    l.type = SourceType::U8;
  else if (t == "signed char" || t == "int8" || t == "int8_t")
    l.type = SourceType::I8;
  else if (t == "ushort" || t == "unsigned short" || t == "unsigned short int" || t == "uint16" ||
           t == "uint16_t")
    l.type = SourceType::U16;
  else if (t == "short" || t == "short int" || t == "signed short" || t == "signed short int" ||
           t == "int16" || t == "int16_t")
    l.type = SourceType::I16;
  else if (t == "int" || t == "signed int" || t == "int32" || t == "int32_t")
    l.type = SourceType::I32;
  else if (t == "uint" || t == "unsigned int" || t == "uint32" || t == "uint32_t")
    l.type = SourceType::U32;
  else if (t == "float")
    l.type = SourceType::F32;
  else if (t == "double")
    l.type = SourceType::F64;
  else
    throw InputError(name + ": NRRD type '" + t + "' is not supported");
  const std::vector<std::string> sizes = words(field(h, "sizes"));
  std::vector<double> dims;
  for (const auto& w : sizes) dims.push_back(number(w, "sizes", name));
  // A single-sample first or last axis (a 4-D file of one component) is fine.
  std::size_t first = 0;
  if (dims.size() == 4 && dims[0] == 1.0) first = 1;
  if (dims.size() - first == 4 && dims.back() == 1.0) dims.pop_back();
  if (dims.size() - first != 3) {
    throw InputError(name + ": NRRD sizes '" + field(h, "sizes") + "': expected 3 axes");
  }
  for (int a = 0; a < 3; ++a) {
    const double d = dims[first + static_cast<std::size_t>(a)];
    if (!(d >= 1.0 && d <= 1 << 20) || d != std::floor(d)) {
      throw InputError(name + ": NRRD size '" + sizes[first + static_cast<std::size_t>(a)] +
                       "' is not an integer in 1..1048576");
    }
    l.dims[a] = static_cast<int>(d);
  }
  const std::string endian = field(h, "endian");
  l.swap = endian == "big" && sourceBytes(l.type) > 1;
  NrrdGeometryFields g;
  g.space = field(h, "space");
  const std::string spaceDim = field(h, "space dimension");
  if (!spaceDim.empty())
    g.spaceDimension = static_cast<int>(number(spaceDim, "space dimension", name));
  g.firstAxis = static_cast<int>(first);
  const std::vector<std::string> sp = words(field(h, "spacings"));
  if (sp.size() >= first + 3) {
    for (int a = 0; a < 3; ++a)
      g.spacings[a] = number(sp[first + static_cast<std::size_t>(a)], "spacings", name);
  }
  const std::string dirs = field(h, "space directions");
  if (!dirs.empty()) {
    // "(a,b,c) (d,e,f) (g,h,i)", with "none" for a non-spatial axis.
    const auto axes = nrrdVectors(dirs, "space directions", name);
    if (axes.size() < first + 3) {
      throw InputError(name + ": NRRD 'space directions' has " + std::to_string(axes.size()) +
                       " entries, expected one per axis");
    }
    g.hasSpaceDirections = true;
    for (std::size_t a = first; a < first + 3; ++a) g.spaceDirections.push_back(axes[a]);
  }
  const std::string origin = field(h, "space origin");
  if (!origin.empty()) {
    const auto o = nrrdVectors(origin, "space origin", name);
    if (o.size() == 1 && o[0]) g.spaceOrigin = *o[0];
  }
  const NrrdGeometry geometry = nrrdGeometry(g, name);
  l.indexToWorld = geometry.indexToWorld;
  l.geometrySource = geometry.source;
  std::uint64_t offset = h.payload;
  const std::string skip = field(h, "byte skip");
  if (!skip.empty()) {
    const double s = number(skip, "byte skip", name);
    if (s == -1.0 && !gz) {
      const std::uint64_t need =
          static_cast<std::uint64_t>(l.dims.x) * l.dims.y * l.dims.z * sourceBytes(l.type);
      offset = b.size() >= need ? b.size() - need : b.size() + 1;
    } else if (s >= 0.0 && s == std::floor(s)) {
      offset += static_cast<std::uint64_t>(s);
    } else {
      throw InputError(name + ": NRRD byte skip '" + skip + "' must be -1 or >= 0");
    }
  }
  return convert(l, checkedPayload(l, b, offset, name), name);
}

}  // namespace

bool isGzip(std::span<const std::byte> bytes) {
  return bytes.size() >= 2 && std::to_integer<int>(bytes[0]) == 0x1f &&
         std::to_integer<int>(bytes[1]) == 0x8b;
}

std::optional<std::size_t> gzipPayloadOffset(std::span<const std::byte> bytes) {
  if (!startsWith(bytes, "NRRD000")) return std::nullopt;
  try {
    const NrrdHeader h = nrrdHeader(bytes, "NRRD");
    const std::string enc = field(h, "encoding");
    if (enc == "gzip" || enc == "gz") return h.payload;
  } catch (const InputError&) {
  }
  return std::nullopt;
}

Volume readVolumeFromMemory(const std::string& name, std::span<const std::byte> bytes,
                            bool payloadInflated) {
  if (isGzip(bytes)) {
    throw InputError(name + ": gzip data must be inflated before it is read");
  }
  if (startsWith(bytes, "NRRD000")) return readNrrd(name, bytes, payloadInflated);
  if (endsWith(name, ".nii") || endsWith(name, ".nii.gz") ||
      (bytes.size() >= 348 && (std::memcmp(bytes.data() + 344, "n+1", 3) == 0 ||
                               std::memcmp(bytes.data() + 344, "ni1", 3) == 0))) {
    return readNifti1(name, bytes);
  }
  if (endsWith(name, ".nrrd")) throw InputError(name + ": does not start with the NRRD magic");
  throw InputError(name + ": not a NIfTI-1 (.nii, .nii.gz) or NRRD (.nrrd) file");
}

}  // namespace tessera::viewer
