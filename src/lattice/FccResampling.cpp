#include "tessera/lattice/FccResampling.h"

#include <array>
#include <vector>

#include "lattice/CartesianInterpolant.h"
#include "lattice/ParallelFor.h"
#include "tessera/core/Error.h"

namespace tessera::lattice {

namespace {

// The 12 nearest neighbours of an FCC point.
constexpr std::array<glm::ivec3, 12> kNeighbours = {{{1, 1, 0},
                                                     {1, -1, 0},
                                                     {-1, 1, 0},
                                                     {-1, -1, 0},
                                                     {1, 0, 1},
                                                     {1, 0, -1},
                                                     {-1, 0, 1},
                                                     {-1, 0, -1},
                                                     {0, 1, 1},
                                                     {0, 1, -1},
                                                     {0, -1, 1},
                                                     {0, -1, -1}}};

// f(point) for every texel of a grid's packing (padding texels included:
// they hold a point outside the grid, which fromTexels() overwrites).
std::vector<float> texelsOf(glm::ivec3 grid, int threads,
                            const std::function<double(glm::ivec3)>& f) {
  const glm::ivec3 packed = FccVolume::packedDims(grid);
  std::vector<float> out(static_cast<std::size_t>(packed.x) * packed.y * packed.z);
  const std::int64_t rows = static_cast<std::int64_t>(packed.y) * packed.z;
  detail::parallelFor(rows * packed.x, threads, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) {
      const std::int64_t row = i / packed.x;
      const glm::ivec3 texel(static_cast<int>(i % packed.x), static_cast<int>(row % packed.y),
                             static_cast<int>(row / packed.y));
      const glm::ivec3 p = FccVolume::pointOf(texel);
      out[static_cast<std::size_t>(i)] = p.x < grid.x ? static_cast<float>(f(p)) : 0.0f;
    }
  });
  return out;
}

}  // namespace

FccVolume resampleToFcc(const Volume& source, const FccResampleOptions& options,
                        FccResampleStats* stats) {
  const glm::ivec3 grid = fccGridDims(source.dims(), options.density);
  const glm::dvec3 toIndex = glm::dvec3(source.dims()) / glm::dvec3(grid);
  std::vector<float> texels;
  (void)source.valueRange();  // cached before threads read it (NaN -> nonFiniteValue)
  if (grid == source.dims()) {
    // Half density: the lattice points are voxel centres, nothing to interpolate.
    texels = texelsOf(grid, options.threads, [&](glm::ivec3 p) {
      return source.finiteValueAtIndex(source.index(p.x, p.y, p.z));
    });
  } else {
    const detail::CartesianInterpolantField field(source, options.interpolant, options.threads);
    texels = texelsOf(grid, options.threads, [&](glm::ivec3 p) {
      // Same texture position, in the source's voxel index.
      return field.at((glm::dvec3(p) + 0.5) * toIndex - 0.5);
    });
  }
  if (options.quasiInterpolate) {
    const FccVolume q =
        quasiInterpolate(FccVolume::fromTexels(source, grid, ScalarType::F32, texels));
    const float* qt = q.packed().dataAs<float>();
    texels.assign(qt, qt + texels.size());
  }
  FccResampleStats s;
  FccVolume out = FccVolume::fromTexels(source, grid, options.type.value_or(source.type()), texels,
                                        &s.saturated);
  out.setQuasiInterpolated(options.quasiInterpolate);
  if (stats) *stats = s;
  return out;
}

FccVolume sampleOnFcc(const Volume& box, FccDensity density,
                      const std::function<double(glm::dvec3)>& f, bool quasiInterpolated,
                      int threads) {
  const glm::ivec3 grid = fccGridDims(box.dims(), density);
  const std::vector<float> texels = texelsOf(
      grid, threads, [&](glm::ivec3 p) { return f((glm::dvec3(p) + 0.5) / glm::dvec3(grid)); });
  FccVolume samples = FccVolume::fromTexels(box, grid, ScalarType::F32, texels);
  return quasiInterpolated ? quasiInterpolate(samples, threads) : samples;
}

FccVolume quasiInterpolate(const FccVolume& samples, int threads) {
  if (samples.quasiInterpolated()) {
    throw InputError("FCC lattice is already quasi-interpolated; doing it twice would sharpen it");
  }
  const std::vector<float> texels = texelsOf(samples.gridDims(), threads, [&](glm::ivec3 p) {
    const double f = samples.value(p);
    double sum = 0.0;
    for (const glm::ivec3& n : kNeighbours) sum += samples.clampedValue(p + n) - f;
    return f - sum / 24.0;  // f - laplacian / 6, laplacian = sum / 4
  });
  FccVolume out = FccVolume::fromTexels(samples.box(), samples.gridDims(), ScalarType::F32, texels);
  out.setQuasiInterpolated(true);
  return out;
}

}  // namespace tessera::lattice
