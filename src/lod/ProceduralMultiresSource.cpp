#include "tessera/lod/ProceduralMultiresSource.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "tessera/core/Error.h"
#include "tessera/lod/InCoreMultiresSource.h"

namespace tessera::lod {

namespace {

constexpr const char* kPrefix = "head:";
constexpr const char* kPrefix16 = "head16:";

bool sixteenBits(const std::string& spec) {
  return spec.rfind(kPrefix16, 0) == 0;
}

// Integer lattice hash -> [0, 1).
double hash3(int x, int y, int z) {
  std::uint32_t h = static_cast<std::uint32_t>(x) * 73856093u ^
                    static_cast<std::uint32_t>(y) * 19349663u ^
                    static_cast<std::uint32_t>(z) * 83492791u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return static_cast<double>(h & 0xffffffu) / 16777216.0;
}

// Trilinear value noise with smoothstep weights, [0, 1).
double valueNoise(glm::dvec3 p) {
  const glm::dvec3 f = glm::floor(p);
  const glm::ivec3 i(f);
  glm::dvec3 t = p - f;
  t = t * t * (3.0 - 2.0 * t);
  double c[2][2][2];
  for (int dz = 0; dz < 2; ++dz) {
    for (int dy = 0; dy < 2; ++dy) {
      for (int dx = 0; dx < 2; ++dx) c[dz][dy][dx] = hash3(i.x + dx, i.y + dy, i.z + dz);
    }
  }
  auto lerp = [](double a, double b, double w) { return a + (b - a) * w; };
  const double y0 = lerp(lerp(c[0][0][0], c[0][0][1], t.x), lerp(c[0][1][0], c[0][1][1], t.x), t.y);
  const double y1 = lerp(lerp(c[1][0][0], c[1][0][1], t.x), lerp(c[1][1][0], c[1][1][1], t.x), t.y);
  return lerp(y0, y1, t.z);
}

// How much of a noise component of lattice period `period` (level-0
// voxels) a level whose voxel spans `voxel` level-0 voxels keeps: all of it
// at level 0 and while a period spans at least 4 of the level's voxels,
// none (its mean) at 2 voxels (the level's Nyquist limit), linear between.
double detailWeight(double period, double voxel) {
  if (voxel <= 1.0) return 1.0;
  return std::clamp((period / voxel - 2.0) / 2.0, 0.0, 1.0);
}

// A component's value `v` with weight w, the rest its mean.
double keptDetail(double v, double mean, double w) {
  return w == 1.0 ? v : mean + w * (v - mean);
}

// The fraction of space where valueNoise exceeds 0.86: the mean of the
// speckle indicator, measured once over 64^3 points of 16^3 lattice cells
// (the noise is stationary; its mean is 0.5 by symmetry of the hash).
double speckleShare() {
  static const double share = [] {
    std::uint64_t hits = 0;
    const int n = 64;
    for (int z = 0; z < n; ++z) {
      for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
          const glm::dvec3 p = (glm::dvec3(x, y, z) + 0.5) * (16.0 / n) + 0.37;
          hits += valueNoise(p) > 0.86;
        }
      }
    }
    return static_cast<double>(hits) / (double(n) * n * n);
  }();
  return share;
}

glm::ivec3 parseDims(const std::string& spec) {
  if (!ProceduralMultiresSource::isSpec(spec)) {
    throw InputError("'" + spec +
                     "': expected head:WxHxD or head:N (a generated large volume; head16: for "
                     "u16)");
  }
  const std::string size = spec.substr(std::string(sixteenBits(spec) ? kPrefix16 : kPrefix).size());
  std::vector<int> parts;
  std::size_t b = 0;
  while (true) {
    const std::size_t e = size.find('x', b);
    const std::string p = size.substr(b, e == std::string::npos ? std::string::npos : e - b);
    if (p.empty() || p.find_first_not_of("0123456789") != std::string::npos || p.size() > 6) {
      throw InputError("'" + spec + "': size must be N or WxHxD with N in 1..100000");
    }
    parts.push_back(std::stoi(p));
    if (e == std::string::npos) break;
    b = e + 1;
  }
  if (parts.size() != 1 && parts.size() != 3) {
    throw InputError("'" + spec + "': size must be N or WxHxD");
  }
  const glm::ivec3 d =
      parts.size() == 1 ? glm::ivec3(parts[0]) : glm::ivec3(parts[0], parts[1], parts[2]);
  if (glm::any(glm::lessThan(d, glm::ivec3(1))) ||
      glm::any(glm::greaterThan(d, glm::ivec3(100000))))
    throw InputError("'" + spec + "': each side must be 1..100000");
  return d;
}

}  // namespace

bool ProceduralMultiresSource::isSpec(const std::string& spec) {
  return spec.rfind(kPrefix, 0) == 0 || sixteenBits(spec);
}

ProceduralMultiresSource::ProceduralMultiresSource(const std::string& spec, int coarsestSide)
    : spec_(spec) {
  const glm::ivec3 d = parseDims(spec);
  dims_ = pyramidDims(d, coarsestSide);
  sixteen_ = sixteenBits(spec);
  shape_ = Volume::shapeOnly(d, sixteen_ ? ScalarType::U16 : ScalarType::U8);
  const double top = sixteen_ ? 65535.0 : 255.0;
  shape_.setValueRange({0.0, top});
  shape_.setWindow({0.0, top});
  shape_.setDescription("generated: " + spec + " (computed brick by brick)");
  shape_.setGeometrySource("generated");
}

LevelInfo ProceduralMultiresSource::levelInfo(int level) const {
  if (level < 0 || level >= levelCount()) throw Error("no level " + std::to_string(level));
  return {.dims = dims_[static_cast<std::size_t>(level)],
          .spacing = glm::vec3(static_cast<float>(1 << level)),
          .chunk = glm::ivec3(0)};
}

double ProceduralMultiresSource::valueAt(glm::dvec3 x) const {
  return fieldAt(x, 1.0);
}

double ProceduralMultiresSource::fieldAt(glm::dvec3 x, double voxel) const {
  const glm::dvec3 d(shape_.dims());
  const double half = 0.5 * std::max({d.x, d.y, d.z});
  // Isotropic coordinates, the longest axis spanning [-1, 1].
  const glm::dvec3 q = (x - 0.5 * d) / half;
  const glm::dvec3 axes = 0.92 * d / (2.0 * half);  // the head fills the box
  const double r = glm::length(q / axes);
  if (r >= 1.0) return 0.0;
  if (r >= 0.88) return 230.0;  // skull
  // Soft tissue: 40 .. 140 with a texture of ~16 features across the head.
  const double tissue =
      40.0 + 100.0 * keptDetail(valueNoise(q * 16.0 + 7.3), 0.5, detailWeight(half / 16.0, voxel));
  // Speckles: where fine noise is high, ~4 voxels across at 512^3.
  if (r >= 0.8) return tissue;
  const double w = detailWeight(half / 110.0, voxel);
  const bool speckle = w > 0.0 && valueNoise(q * 110.0 + 1.7) > 0.86;
  if (w == 1.0) return speckle ? 250.0 : tissue;
  // Band-limited: the share of the voxel the speckles cover, on average.
  const double share = keptDetail(speckle ? 1.0 : 0.0, speckleShare(), w);
  return tissue + share * (250.0 - tissue);
}

double ProceduralMultiresSource::value16At(glm::dvec3 x) const {
  return field16At(x, 1.0);
}

double ProceduralMultiresSource::field16At(glm::dvec3 x, double voxel) const {
  const double v = fieldAt(x, voxel);
  if (v <= 0.0) return 0.0;
  // The 8-bit field times 257, and a fine texture of up to 200 (less than
  // one 8-bit step) that only 16-bit storage keeps.
  const glm::dvec3 d(shape_.dims());
  const double half = 0.5 * std::max({d.x, d.y, d.z});
  const glm::dvec3 q = (x - 0.5 * d) / half;
  const double w = detailWeight(half / 64.0, voxel);
  const double texture = w > 0.0 ? valueNoise(q * 64.0 + 3.1) : 0.5;
  return std::min(65535.0, v * 257.0 + 200.0 * keptDetail(texture, 0.5, w));
}

double ProceduralMultiresSource::levelValue(int level, glm::ivec3 voxel) const {
  const double scale = static_cast<double>(1 << level);
  const glm::dvec3 c = (glm::dvec3(voxel) + 0.5) * scale;
  // head: point-samples the field at every level; head16: levels >= 1 are
  // band-limited (see the header).
  if (!sixteen_) return static_cast<double>(std::lround(valueAt(c)));
  return static_cast<double>(std::lround(field16At(c, scale)));
}

Volume ProceduralMultiresSource::readBox(int level, const VoxelBox& box) const {
  const LevelInfo info = levelInfo(level);
  if (box.count() == 0 || glm::any(glm::lessThan(box.begin, glm::ivec3(0))) ||
      glm::any(glm::greaterThan(box.end, info.dims))) {
    throw Error(spec_ + ": box outside level " + std::to_string(level));
  }
  const glm::ivec3 s = box.size();
  Volume out = Volume::allocate(s, shape_.type(), spec_ + " box");
  const double scale = static_cast<double>(1 << level);
  out.setSpacing(glm::dvec3(scale));
  out.setOrigin((glm::dvec3(box.begin) + 0.5) * scale - 0.5);
  out.setWindow(shape_.window());
  std::uint8_t* dst = out.dataAs<std::uint8_t>();
  std::uint16_t* dst16 = out.dataAs<std::uint16_t>();
  for (int z = 0; z < s.z; ++z) {
    for (int y = 0; y < s.y; ++y) {
      for (int x = 0; x < s.x; ++x) {
        const glm::dvec3 c = (glm::dvec3(box.begin + glm::ivec3(x, y, z)) + 0.5) * scale;
        if (sixteen_) {
          *dst16++ = static_cast<std::uint16_t>(std::lround(field16At(c, scale)));
        } else {
          *dst++ = static_cast<std::uint8_t>(std::lround(valueAt(c)));
        }
      }
    }
  }
  return out;
}

}  // namespace tessera::lod
