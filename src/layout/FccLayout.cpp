#include "tessera/layout/FccLayout.h"

#include "tessera/lattice/BoxSplineReconstruction.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "layout/Fit3DTexture.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/lattice/FccResampling.h"

namespace tessera::layout {

namespace {

using Storage = FccLayout::Storage;

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

gpu::TexelFormat formatFor(ScalarType type, Storage storage) {
  if (storage == Storage::Cubes) {
    return type == ScalarType::U8 ? gpu::TexelFormat::RGBA8 : gpu::TexelFormat::RGBA32F;
  }
  return type == ScalarType::U8 ? gpu::TexelFormat::R8 : gpu::TexelFormat::R32F;
}

// Cube storage: texel t holds the cube at origin t - kCubeMargin. A sample's
// cubes have origins floor(u) - 1 .. floor(u) + 1 with u in [-0.5, D - 0.5]
// (layout/fcc.glsl), i.e. -2 .. D.
constexpr int kCubeMargin = 2;

glm::ivec3 textureDims(glm::ivec3 gridDims, Storage storage) {
  return storage == Storage::Cubes ? gridDims + kCubeMargin + 1
                                   : lattice::FccVolume::packedDims(gridDims);
}

// Every value of the lattice's packing, as floats (padding included).
std::vector<float> packedValues(const lattice::FccVolume& fcc) {
  const Volume& packed = fcc.packed();
  std::vector<float> values(static_cast<std::size_t>(packed.voxelCount()));
  for (std::size_t i = 0; i < values.size(); ++i) {
    values[i] = static_cast<float>(packed.finiteValueAtIndex(i));
  }
  return values;
}

// The FCC corners q + o of every cube q, in channel o.x + 2 o.y, under the
// boundary rule (FccVolume::clampedTexel), as the CPU evaluator reads them.
template <class T>
std::vector<T> cubeTexels(const lattice::FccVolume& fcc, glm::ivec3 dims) {
  const glm::ivec3 grid = fcc.gridDims();
  const glm::ivec3 pd = fcc.packed().dims();
  const std::vector<float> values = packedValues(fcc);
  std::vector<T> out(static_cast<std::size_t>(dims.x) * dims.y * dims.z * 4);
  std::size_t n = 0;
  for (int z = 0; z < dims.z; ++z) {
    for (int y = 0; y < dims.y; ++y) {
      for (int x = 0; x < dims.x; ++x) {
        const glm::ivec3 q = glm::ivec3(x, y, z) - kCubeMargin;
        for (int ch = 0; ch < 4; ++ch) {
          const int ox = ch & 1, oy = ch >> 1;
          const glm::ivec3 o(ox, oy, (q.x + q.y + q.z + ox + oy) & 1);
          const glm::ivec3 t = lattice::FccVolume::clampedTexel(q + o, grid);
          out[n++] =
              static_cast<T>(values[(static_cast<std::size_t>(t.z) * pd.y + t.y) * pd.x + t.x]);
        }
      }
    }
  }
  return out;
}

LayoutPlan planStorage(glm::ivec3 gridDims, ScalarType type, const gpu::DeviceLimits& limits,
                       const std::string& name, Storage storage) {
  LayoutPlan plan;
  plan.layout = name;
  PlannedTexture t;
  t.label = storage == Storage::Cubes ? "FCC lattice cubes" : "FCC lattice";
  t.size = textureDims(gridDims, storage);
  t.is3D = true;
  const gpu::TexelFormat format = formatFor(type, storage);
  t.format = gpu::texelFormatName(format);
  t.bytes = static_cast<std::uint64_t>(t.size.x) * static_cast<std::uint64_t>(t.size.y) *
            static_cast<std::uint64_t>(t.size.z) * gpu::bytesPerTexel(format);
  plan.totalBytes = t.bytes;
  plan.textures.push_back(t);
  const bool cubes = storage == Storage::Cubes;
  const std::string what =
      "FCC lattice on a " + dimsText(gridDims) + " grid" +
      (cubes ? ", the corners of its unit cubes in one " : ", packed into one ") +
      dimsText(t.size) + " " + t.format + " 3D texture (" + formatBytes(t.bytes) +
      "), box spline from " + (cubes ? "5" : "16") + " texelFetch per sample";
  plan.reason = refusalFor3DTexture(
      limits, t.size, t.bytes, what,
      "the box spline needs OpenGL ES 3 (3D textures, texelFetch, integer maths), which " +
          limits.profile + " does not have",
      "the lattice");
  plan.fits = plan.reason.empty();
  if (plan.fits) plan.reason = what;
  return plan;
}

Storage storageOf(const LayoutPlan& plan) {
  return plan.textures.at(0).label == "FCC lattice cubes" ? Storage::Cubes : Storage::Packed;
}

// The grid-coordinate range [lo, hi] of the samples a block along one axis
// can take, widened by the spline's reach (|x|_inf < 2) and clamped to the
// grid: every point the boundary rule may read for them.
glm::ivec2 latticeReach(int block, int blockSize, int boxDim, int gridDim) {
  const double scale = static_cast<double>(gridDim) / boxDim;
  const double uLo = block * blockSize * scale - 0.5;
  const double uHi = std::min((block + 1) * blockSize, boxDim) * scale - 0.5;
  const int lo = std::clamp(static_cast<int>(std::floor(uLo)) - 2, 0, gridDim - 1);
  const int hi = std::clamp(static_cast<int>(std::ceil(uHi)) + 2, 0, gridDim - 1);
  return {lo, hi};
}

}  // namespace

std::string FccLayout::layoutName(lattice::FccDensity density) {
  return density == lattice::FccDensity::Same ? "fcc" : "fcc-half";
}

const char* FccLayout::storageName(Storage storage) {
  switch (storage) {
    case Storage::Auto:
      return "auto";
    case Storage::Packed:
      return "packed";
    case Storage::Cubes:
      return "cubes";
  }
  return "?";
}

LayoutPlan FccLayout::planFor(glm::ivec3 gridDims, ScalarType type, const gpu::DeviceLimits& limits,
                              const std::string& name, Storage storage) {
  if (storage != Storage::Auto) return planStorage(gridDims, type, limits, name, storage);
  const LayoutPlan cubes = planStorage(gridDims, type, limits, name, Storage::Cubes);
  if (cubes.fits) return cubes;
  LayoutPlan packed = planStorage(gridDims, type, limits, name, Storage::Packed);
  if (packed.fits) packed.reason += " (not cubes: " + cubes.reason + ")";
  return packed;
}

std::unique_ptr<FccLayout> FccLayout::create(lattice::FccVolume fcc,
                                             const gpu::DeviceLimits& limits,
                                             gpu::MemoryLedger& ledger, const std::string& name,
                                             Storage storage) {
  std::unique_ptr<FccLayout> l(new FccLayout());
  l->name_ = name;
  l->plan_ = planFor(fcc.gridDims(), fcc.packed().type(), limits, name, storage);
  if (!l->plan_.fits) throw GpuError(name + " layout: " + l->plan_.reason);
  l->storage_ = storageOf(l->plan_);
  if (l->storage_ == Storage::Cubes) {
    l->uploadCubes(fcc, ledger);
  } else {
    l->uploadPacked(fcc, ledger);
  }
  l->texture_.setFilter(gpu::Filter::Nearest);
  l->fcc_ = std::move(fcc);
  return l;
}

void FccLayout::uploadCubes(const lattice::FccVolume& fcc, gpu::MemoryLedger& ledger) {
  const glm::ivec3 d = textureDims(fcc.gridDims(), Storage::Cubes);
  const std::uint64_t texels = static_cast<std::uint64_t>(d.x) * d.y * d.z;
  const std::string label = "FCC lattice cubes (" + name_ + ")";
  if (fcc.packed().type() == ScalarType::U8) {
    HostBudget::global().check(texels * 4, "FCC cube texture staging");
    const std::vector<std::uint8_t> t = cubeTexels<std::uint8_t>(fcc, d);
    texture_ =
        gpu::Texture::create3D(ledger, label, gpu::TexelFormat::RGBA8, d.x, d.y, d.z, t.data());
    mapping_ = {255.0, 0.0};
  } else {
    HostBudget::global().check(texels * 16, "FCC cube texture staging");
    const std::vector<float> t = cubeTexels<float>(fcc, d);
    texture_ =
        gpu::Texture::create3D(ledger, label, gpu::TexelFormat::RGBA32F, d.x, d.y, d.z, t.data());
    mapping_ = {1.0, 0.0};
  }
}

void FccLayout::uploadPacked(const lattice::FccVolume& fcc, gpu::MemoryLedger& ledger) {
  const Volume& packed = fcc.packed();
  const glm::ivec3 d = packed.dims();
  const std::string label = "FCC lattice (" + name_ + ")";
  if (packed.type() == ScalarType::U8) {
    texture_ = gpu::Texture::create3D(ledger, label, gpu::TexelFormat::R8, d.x, d.y, d.z,
                                      packed.bytes().data());
    mapping_ = {255.0, 0.0};
    return;
  }
  HostBudget::global().check(static_cast<std::uint64_t>(packed.voxelCount()) * sizeof(float),
                             "FCC lattice upload staging");
  const std::vector<float> values = packedValues(fcc);
  texture_ =
      gpu::Texture::create3D(ledger, label, gpu::TexelFormat::R32F, d.x, d.y, d.z, values.data());
  mapping_ = {1.0, 0.0};
}

std::unique_ptr<FccLayout> FccLayout::resample(const Volume& volume, lattice::FccDensity density,
                                               const gpu::DeviceLimits& limits,
                                               gpu::MemoryLedger& ledger) {
  const std::string name = layoutName(density);
  // Refuse before the (seconds-long) resampling when it cannot fit.
  const LayoutPlan plan =
      planFor(lattice::fccGridDims(volume.dims(), density), volume.type(), limits, name);
  if (!plan.fits) throw GpuError(name + " layout: " + plan.reason);
  lattice::FccResampleOptions options;
  options.density = density;
  return create(lattice::resampleToFcc(volume, options), limits, ledger, name);
}

gpu::ShaderPart FccLayout::glsl() const {
  return gpu::embeddedShaderPart("layout/fcc.glsl");
}

std::vector<gpu::ShaderPart> FccLayout::glslParts() const {
  std::vector<gpu::ShaderPart> parts;
  if (storage_ == Storage::Cubes) parts.push_back({"fcc cube storage", "#define FCC_CUBES 1\n"});
  if (evaluation_ == Evaluation::FetchesOnly) {
    parts.push_back({"fcc cost split", "#define FCC_FETCHES_ONLY 1\n"});
  } else if (evaluation_ == Evaluation::ArithmeticOnly) {
    parts.push_back({"fcc cost split", "#define FCC_ARITHMETIC_ONLY 1\n"});
  }
  parts.push_back(glsl());
  parts.push_back(gpu::embeddedShaderPart("layout/fcc_pieces.glsl"));
  return parts;
}

int FccLayout::bind(const gpu::Program& program, int firstUnit) const {
  texture_.bind(firstUnit);
  program.set("u_layoutFcc", firstUnit);
  program.set("u_layoutFccGrid", glm::vec3(fcc_.gridDims()));
  return 1;
}

ValueBlocks FccLayout::valueBlocks(int blockSize) const {
  if (blockSize < 1) throw InputError("block size must be >= 1");
  const glm::ivec3 box = fcc_.box().dims();
  const glm::ivec3 grid = fcc_.gridDims();
  const glm::ivec3 count = (box + blockSize - 1) / blockSize;
  const glm::ivec3 pd = fcc_.packed().dims();
  const std::vector<float> texels = packedValues(fcc_);
  std::vector<glm::ivec2> reach[3];
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < count[a]; ++b) {
      reach[a].push_back(latticeReach(b, blockSize, box[a], grid[a]));
    }
  }
  const std::size_t n = static_cast<std::size_t>(count.x) * count.y * count.z;
  std::vector<float> mins(n), maxs(n);
  for (int bz = 0; bz < count.z; ++bz) {
    for (int by = 0; by < count.y; ++by) {
      for (int bx = 0; bx < count.x; ++bx) {
        // Texels of the reached grid points: x texel = point.x >> 1.
        const glm::ivec2 rx = reach[0][static_cast<std::size_t>(bx)] >> 1;
        const glm::ivec2 ry = reach[1][static_cast<std::size_t>(by)];
        const glm::ivec2 rz = reach[2][static_cast<std::size_t>(bz)];
        float lo = std::numeric_limits<float>::infinity(), hi = -lo;
        for (int z = rz.x; z <= rz.y; ++z) {
          for (int y = ry.x; y <= ry.y; ++y) {
            const float* row = texels.data() + (static_cast<std::size_t>(z) * pd.y + y) * pd.x;
            for (int x = rx.x; x <= std::min(rx.y, pd.x - 1); ++x) {
              lo = std::min(lo, row[x]);
              hi = std::max(hi, row[x]);
            }
          }
        }
        const std::size_t i = (static_cast<std::size_t>(bz) * count.y + by) * count.x + bx;
        mins[i] = lo;
        maxs[i] = hi;
      }
    }
  }
  return ValueBlocks(count, blockSize, supportVoxels(), std::move(mins), std::move(maxs));
}

ReferenceField FccLayout::referenceField() const {
  return {.box = &fcc_.box(), .field = std::make_shared<lattice::BoxSplineReconstruction>(fcc_)};
}

LayoutEntry FccLayout::registration(lattice::FccDensity density) {
  return {.name = layoutName(density),
          .minApi = gpu::ApiLevel::Gles3,
          .needs3DTextures = true,
          .automatic = false,
          .needsText = "OpenGL ES 3 (3D textures, texelFetch and integer maths for the box spline)",
          .holdsVoxelGrid = false,
          .plan =
              [density](const Volume& shape, const gpu::DeviceLimits& limits, int) {
                return planFor(lattice::fccGridDims(shape.dims(), density), shape.type(), limits,
                               layoutName(density));
              },
          .create = [density](const Volume& volume, const gpu::DeviceLimits& limits,
                              gpu::MemoryLedger& ledger, int) -> std::unique_ptr<Layout> {
            return resample(volume, density, limits, ledger);
          }};
}

}  // namespace tessera::layout
