#include "tessera/io/Procedural.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <exception>
#include <functional>
#include <numbers>
#include <thread>
#include <vector>

#include "tessera/core/Error.h"

namespace tessera {

namespace {

constexpr std::int64_t kMaxDim = 1 << 20;

std::string dimsString(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

// Calls fill(z0, z1) for slabs of z-slices, on several threads once the
// volume is large enough for thread start-up to be worth it. Slabs are
// disjoint, so the callers write without synchronisation.
void forEachSlab(glm::ivec3 dims, const std::function<void(int, int)>& fill) {
  const std::uint64_t voxels = static_cast<std::uint64_t>(dims.x) * dims.y * dims.z;
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  const int threads =
      static_cast<int>(std::min<std::uint64_t>(hw, static_cast<std::uint64_t>(dims.z)));
  if (voxels < (1u << 18) || threads <= 1) {
    fill(0, dims.z);
    return;
  }
  std::vector<std::thread> pool;
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(threads));
  for (int t = 0; t < threads; ++t) {
    const int z0 = static_cast<int>(static_cast<std::int64_t>(dims.z) * t / threads);
    const int z1 = static_cast<int>(static_cast<std::int64_t>(dims.z) * (t + 1) / threads);
    pool.emplace_back([&, z0, z1, t] {
      try {
        fill(z0, z1);
      } catch (...) {
        errors[static_cast<std::size_t>(t)] = std::current_exception();
      }
    });
  }
  for (auto& th : pool) th.join();
  for (const auto& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

// One ellipsoid of the 3-D Shepp–Logan head: additive intensity, semi-axes,
// centre, and Euler angles (degrees, z-x-z: phi, theta, psi).
struct Ellipsoid {
  int intensityTenths;  // additive intensity × 10: sums stay exact, so 0.3 → 76.5 → 77 everywhere
  double a, b, c;
  double x0, y0, z0;
  double phi, theta, psi;
};

// The ten ellipsoids of the 3-D Shepp–Logan phantom (the 3-D extension of
// Shepp & Logan 1974 given with Kak & Slaney's tables), with the higher
// contrast intensities of Toft (1996, pp. 199–200) as tabulated in
// M. Schabel's phantom3d (MATLAB File Exchange 9416, "modified Shepp-Logan").
// The original intensities (2, -0.98, -0.02, ...) leave the inner structures
// at 1-2 % contrast, invisible in an 8-bit volume.
constexpr std::array<Ellipsoid, 10> kSheppLogan = {{
    {10, 0.6900, 0.920, 0.810, 0.00, 0.0000, 0.00, 0, 0, 0},
    {-8, 0.6624, 0.874, 0.780, 0.00, -0.0184, 0.00, 0, 0, 0},
    {-2, 0.1100, 0.310, 0.220, 0.22, 0.0000, 0.00, -18, 0, 10},
    {-2, 0.1600, 0.410, 0.280, -0.22, 0.0000, 0.00, 18, 0, 10},
    {1, 0.2100, 0.250, 0.410, 0.00, 0.3500, -0.15, 0, 0, 0},
    {1, 0.0460, 0.046, 0.050, 0.00, 0.1000, 0.25, 0, 0, 0},
    {1, 0.0460, 0.046, 0.050, 0.00, -0.1000, 0.25, 0, 0, 0},
    {1, 0.0460, 0.023, 0.050, -0.08, -0.6050, 0.00, 0, 0, 0},
    {1, 0.0230, 0.023, 0.020, 0.00, -0.6060, 0.00, 0, 0, 0},
    {1, 0.0230, 0.046, 0.020, 0.06, -0.6050, 0.00, 0, 0, 0},
}};

// Rows of R^T for R = Rz(phi) Rx(theta) Rz(psi), so that q = R^T (p - c)
// gives p in the ellipsoid's own axes. Rotating about the ellipsoid's centre
// (rather than about the origin as the original phantom3d code does) keeps
// every centre where the table puts it.
struct PreparedEllipsoid {
  Ellipsoid e;
  std::array<std::array<double, 3>, 3> rt;
};

std::array<std::array<double, 3>, 3> eulerZxzTransposed(double phiDeg, double thetaDeg,
                                                        double psiDeg) {
  const double k = std::numbers::pi / 180.0;
  const double cf = std::cos(phiDeg * k), sf = std::sin(phiDeg * k);
  const double ct = std::cos(thetaDeg * k), st = std::sin(thetaDeg * k);
  const double cp = std::cos(psiDeg * k), sp = std::sin(psiDeg * k);
  // R = Rz(phi) Rx(theta) Rz(psi)
  const std::array<std::array<double, 3>, 3> r = {{
      {cf * cp - sf * ct * sp, -cf * sp - sf * ct * cp, sf * st},
      {sf * cp + cf * ct * sp, -sf * sp + cf * ct * cp, -cf * st},
      {st * sp, st * cp, ct},
  }};
  std::array<std::array<double, 3>, 3> t{};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) t[i][j] = r[j][i];
  }
  return t;
}

// Voxel centre i of n along an axis spanning [-1, 1].
double cellCentre(int i, int n) {
  return (2.0 * i + 1.0) / n - 1.0;
}

// Marschner & Lobb (1994), "An evaluation of reconstruction filters for
// volume rendering", eq. 2 with f_M = 6 and alpha = 0.25.
double marschnerLobb(double x, double y, double z) {
  constexpr double kFm = 6.0;
  constexpr double kAlpha = 0.25;
  const double pi = std::numbers::pi;
  const double r = std::sqrt(x * x + y * y);
  const double rhoR = std::cos(2.0 * pi * kFm * std::cos(pi * r / 2.0));
  return (1.0 - std::sin(pi * z / 2.0) + kAlpha * (1.0 + rhoR)) / (2.0 * (1.0 + kAlpha));
}

[[noreturn]] void badSpec(const std::string& spec, const std::string& why) {
  throw InputError(spec + ": " + why +
                   " (expected gen:NAME, gen:NAME:N or gen:NAME:WxHxD with NAME sphere, "
                   "shepp-logan or marschner-lobb and sizes 1.." +
                   std::to_string(kMaxDim) + ")");
}

int parseSize(const std::string& spec, const std::string& text) {
  std::int64_t v = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (text.empty() || ec != std::errc() || ptr != end || v < 1 || v > kMaxDim) {
    badSpec(spec, "size '" + text + "' is not an integer between 1 and " + std::to_string(kMaxDim));
  }
  return static_cast<int>(v);
}

}  // namespace

Volume makeSphere(glm::ivec3 dims) {
  Volume v = Volume::allocate(dims, ScalarType::U8, "gen:sphere");
  const double radius = 0.4 * std::min({dims.x, dims.y, dims.z});
  const glm::dvec3 centre = (glm::dvec3(dims) - 1.0) * 0.5;
  std::uint8_t* out = v.dataAs<std::uint8_t>();
  forEachSlab(dims, [&](int z0, int z1) {
    for (int z = z0; z < z1; ++z) {
      for (int y = 0; y < dims.y; ++y) {
        for (int x = 0; x < dims.x; ++x) {
          const double dx = x - centre.x, dy = y - centre.y, dz = z - centre.z;
          const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
          // Linear ramp over one voxel centred on the surface: an
          // anti-aliased edge instead of a staircase.
          const double cover = std::clamp(radius + 0.5 - d, 0.0, 1.0);
          out[v.index(x, y, z)] = static_cast<std::uint8_t>(std::lround(255.0 * cover));
        }
      }
    }
  });
  v.invalidateRange();
  v.setDescription("generated: sphere " + dimsString(dims));
  return v;
}

Volume makeSheppLogan(glm::ivec3 dims) {
  Volume v = Volume::allocate(dims, ScalarType::U8, "gen:shepp-logan");
  std::vector<PreparedEllipsoid> ellipsoids;
  for (const Ellipsoid& e : kSheppLogan) {
    ellipsoids.push_back({e, eulerZxzTransposed(e.phi, e.theta, e.psi)});
  }
  std::uint8_t* out = v.dataAs<std::uint8_t>();
  forEachSlab(dims, [&](int z0, int z1) {
    for (int z = z0; z < z1; ++z) {
      const double pz = cellCentre(z, dims.z);
      for (int y = 0; y < dims.y; ++y) {
        const double py = cellCentre(y, dims.y);
        for (int x = 0; x < dims.x; ++x) {
          const double px = cellCentre(x, dims.x);
          int tenths = 0;
          for (const PreparedEllipsoid& pe : ellipsoids) {
            const double d[3] = {px - pe.e.x0, py - pe.e.y0, pz - pe.e.z0};
            const double qx = pe.rt[0][0] * d[0] + pe.rt[0][1] * d[1] + pe.rt[0][2] * d[2];
            const double qy = pe.rt[1][0] * d[0] + pe.rt[1][1] * d[1] + pe.rt[1][2] * d[2];
            const double qz = pe.rt[2][0] * d[0] + pe.rt[2][1] * d[1] + pe.rt[2][2] * d[2];
            const double r = (qx * qx) / (pe.e.a * pe.e.a) + (qy * qy) / (pe.e.b * pe.e.b) +
                             (qz * qz) / (pe.e.c * pe.e.c);
            if (r <= 1.0) tenths += pe.e.intensityTenths;
          }
          // The skull (intensity 1) is the brightest region; map it to 255.
          out[v.index(x, y, z)] =
              static_cast<std::uint8_t>(std::lround(25.5 * std::clamp(tenths, 0, 10)));
        }
      }
    }
  });
  v.invalidateRange();
  // The phantom spans [-1, 1] on every axis; this spacing keeps its shape
  // for non-cubic sizes, and is 1 (voxel units) along the longest axis so
  // that TF opacities "per unit length" mean per voxel, as for scanned data.
  const int longest = std::max({dims.x, dims.y, dims.z});
  v.setSpacing(static_cast<double>(longest) / glm::dvec3(dims));
  v.setDescription("generated: shepp-logan " + dimsString(dims));
  return v;
}

Volume makeMarschnerLobb(glm::ivec3 dims) {
  Volume v = Volume::allocate(dims, ScalarType::F32, "gen:marschner-lobb");
  // Samples include both ends of [-1, 1] (the paper's 41^3 grid has spacing
  // 0.05), so voxel i sits at -1 + i * 2 / (n - 1).
  auto coord = [](int i, int n) { return n > 1 ? -1.0 + 2.0 * i / (n - 1) : 0.0; };
  float* out = v.dataAs<float>();
  forEachSlab(dims, [&](int z0, int z1) {
    for (int z = z0; z < z1; ++z) {
      const double pz = coord(z, dims.z);
      for (int y = 0; y < dims.y; ++y) {
        const double py = coord(y, dims.y);
        for (int x = 0; x < dims.x; ++x) {
          out[v.index(x, y, z)] = static_cast<float>(marschnerLobb(coord(x, dims.x), py, pz));
        }
      }
    }
  });
  v.invalidateRange();
  // Cube-shaped in world space, spacing 1 along the longest axis (as for
  // Shepp–Logan: TF opacity per unit length = per voxel).
  const int longest = std::max({dims.x, dims.y, dims.z});
  const double unit = longest > 1 ? (longest - 1) / 2.0 : 0.5;
  auto step = [unit](int n) { return n > 1 ? 2.0 / (n - 1) * unit : 2.0 * unit; };
  v.setSpacing(glm::dvec3(step(dims.x), step(dims.y), step(dims.z)));
  // The signal's range is [0, 1] whatever the samples hit.
  v.setWindow({0.0, 1.0});
  v.setDescription("generated: marschner-lobb " + dimsString(dims));
  return v;
}

Volume makeProcedural(const std::string& spec) {
  if (spec.rfind("gen:", 0) != 0) badSpec(spec, "not a generator spec");
  const std::string rest = spec.substr(4);
  const std::size_t colon = rest.find(':');
  const std::string name = rest.substr(0, colon);
  if (name.empty()) badSpec(spec, "no generator name");
  if (name != "sphere" && name != "shepp-logan" && name != "marschner-lobb") {
    badSpec(spec, "unknown generator '" + name + "'");
  }
  glm::ivec3 dims = name == "marschner-lobb" ? glm::ivec3(41) : glm::ivec3(64);
  if (colon != std::string::npos) {
    const std::string size = rest.substr(colon + 1);
    if (size.find(':') != std::string::npos) badSpec(spec, "too many ':' parts");
    std::vector<std::string> parts;
    std::size_t b = 0;
    while (true) {
      const std::size_t e = size.find('x', b);
      parts.push_back(size.substr(b, e == std::string::npos ? std::string::npos : e - b));
      if (e == std::string::npos) break;
      b = e + 1;
    }
    if (parts.size() == 1) {
      dims = glm::ivec3(parseSize(spec, parts[0]));
    } else if (parts.size() == 3) {
      dims = glm::ivec3(parseSize(spec, parts[0]), parseSize(spec, parts[1]),
                        parseSize(spec, parts[2]));
    } else {
      badSpec(spec, "size '" + size + "' is neither N nor WxHxD");
    }
  }
  if (name == "sphere") return makeSphere(dims);
  if (name == "shepp-logan") return makeSheppLogan(dims);
  return makeMarschnerLobb(dims);
}

}  // namespace tessera
