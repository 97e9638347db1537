#include "tessera/session/Convert.h"

#include <algorithm>
#include <sstream>
#include <string>

#include "tessera/core/Error.h"
#include "tessera/lod/Downsample.h"

namespace tessera::session {

namespace {

// "Z,Y,X" (array order, as NGFF writes chunks): each an even size in
// 8..1024; returned as x, y, z.
glm::ivec3 parseChunkShape(const std::string& text) {
  const std::string what =
      "--chunk '" + text + "': expected 64, 128 or Z,Y,X (even sizes in 8..1024)";
  int zyx[3] = {0, 0, 0};
  std::size_t at = 0;
  for (int a = 0; a < 3; ++a) {
    const std::size_t comma = a < 2 ? text.find(',', at) : text.size();
    if (comma == std::string::npos) throw InputError(what);
    const std::string part = text.substr(at, comma - at);
    if (part.empty() || part.size() > 4 ||
        part.find_first_not_of("0123456789") != std::string::npos)
      throw InputError(what);
    zyx[a] = std::stoi(part);
    if (zyx[a] < 8 || zyx[a] > 1024 || zyx[a] % 2 != 0) throw InputError(what);
    at = comma + 1;
  }
  if (at != text.size() + 1) throw InputError(what);
  return {zyx[2], zyx[1], zyx[0]};
}

// "Z,Y,X", each 1 or 2, at least one 2; returned as x, y, z.
glm::ivec3 parsePyramidFactors(const std::string& text) {
  const std::string what = "--pyramid-factors '" + text +
                           "': expected Z,Y,X each 1 (axis kept) or 2 (halved), at least one 2 "
                           "(e.g. 1,2,2 keeps z)";
  if (text.size() != 5 || text[1] != ',' || text[3] != ',') throw InputError(what);
  glm::ivec3 f;
  for (int a = 0; a < 3; ++a) {
    const char c = text[std::size_t(2 * a)];
    if (c != '1' && c != '2') throw InputError(what);
    f[2 - a] = c - '0';
  }
  if (f == glm::ivec3(1)) throw InputError(what);
  return f;
}

}  // namespace

glm::ivec3 parseDownsample(const std::string& text) {
  int a = 0, b = 0, c = 0;
  char x1 = 0, x2 = 0;
  std::istringstream in(text);
  if ((in >> a) && in.eof() && a >= 1) return {a, a, a};
  in.clear();
  in.str(text);
  if (!(in >> a >> x1 >> b >> x2 >> c) || x1 != 'x' || x2 != 'x' || !in.eof() || a < 1 || b < 1 ||
      c < 1) {
    throw InputError("--downsample '" + text + "': expected N or AxBxC with factors >= 1");
  }
  return {a, b, c};
}

// "x0:x1,y0:y1,z0:z1", half-open voxel ranges.
std::pair<glm::ivec3, glm::ivec3> parseCrop(const std::string& text, glm::ivec3 dims) {
  glm::ivec3 lo, hi;
  std::istringstream in(text);
  char c1, c2, c3, c4, c5;
  if (!(in >> lo.x >> c1 >> hi.x >> c2 >> lo.y >> c3 >> hi.y >> c4 >> lo.z >> c5 >> hi.z) ||
      c1 != ':' || c3 != ':' || c5 != ':' || c2 != ',' || c4 != ',' || !in.eof()) {
    throw InputError("--crop '" + text + "': expected x0:x1,y0:y1,z0:z1 (voxels, end exclusive)");
  }
  for (int a = 0; a < 3; ++a) {
    if (lo[a] < 0 || hi[a] > dims[a] || lo[a] >= hi[a]) {
      throw InputError("--crop '" + text + "': axis " + std::to_string(a) + " range " +
                       std::to_string(lo[a]) + ":" + std::to_string(hi[a]) +
                       " is empty or outside 0:" + std::to_string(dims[a]));
    }
  }
  return {lo, hi};
}

Volume cropVolume(const Volume& v, glm::ivec3 lo, glm::ivec3 hi) {
  Volume out = Volume::allocate(hi - lo, v.type(), "cropped volume");
  out.setSpacing(v.spacing());
  out.setDirection(v.direction());
  out.setOrigin(v.worldOf(glm::dvec3(lo)));
  out.setGeometrySource(v.geometrySource());
  if (v.hasWindow()) out.setWindow(v.window());
  out.setDescription(v.description());
  const std::size_t bpv = bytesPerVoxel(v.type());
  const std::size_t row = static_cast<std::size_t>(hi.x - lo.x) * bpv;
  for (int z = lo.z; z < hi.z; ++z) {
    for (int y = lo.y; y < hi.y; ++y) {
      const std::byte* src = v.bytes().data() + v.index(lo.x, y, z) * bpv;
      std::byte* dst = out.bytes().data() + out.index(0, y - lo.y, z - lo.z) * bpv;
      std::copy(src, src + row, dst);
    }
  }
  out.invalidateRange();
  return out;
}

OmeZarrWriteOptions zarrWriteOptions(const ConvertRequest& o) {
  OmeZarrWriteOptions z;
  if (o.chunk == "64" || o.chunk == "128") {
    z.chunk = std::stoi(o.chunk);
  } else {
    z.chunkShape = parseChunkShape(o.chunk);
  }
  if (o.levels != "auto") {
    try {
      std::size_t used = 0;
      z.levels = std::stoi(o.levels, &used);
      if (used != o.levels.size() || z.levels < 1) throw InputError("");
    } catch (const std::exception&) {
      throw InputError("--levels '" + o.levels + "': expected auto or a count >= 1");
    }
  }
  try {
    z.compressor = parseZarrCompressor(o.compressor);
  } catch (const InputError& e) {
    throw InputError(std::string("--") + e.what());
  }
  z.zarrFormat = o.zarrFormat;
  z.shard = o.shard;
  z.factors = parsePyramidFactors(o.pyramidFactors);
  return z;
}

Volume cropAndDownsample(Volume v, const ConvertRequest& request) {
  if (!request.crop.empty()) {
    const auto [lo, hi] = parseCrop(request.crop, v.dims());
    v = cropVolume(v, lo, hi);
  }
  if (!request.downsample.empty()) {
    const glm::ivec3 f = parseDownsample(request.downsample);
    if (f != glm::ivec3(1)) v = lod::downsample(v, f);
  }
  return v;
}

}  // namespace tessera::session
