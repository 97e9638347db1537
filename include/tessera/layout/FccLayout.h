#pragma once
// An FCC lattice (lattice/FccVolume.h) behind the layout seam: its values in
// one 3D texture (see Storage: the lattice's own x-packing, or the corners of
// every unit cube in RGBA), and a sampleVolume() that evaluates the
// six-direction box spline from the 16 lattice points of the sample's
// tetrahedron with texelFetch (layout/fcc.glsl + the generated
// layout/fcc_pieces.glsl; the CPU twin is lattice::FccBoxSpline, the CPU
// reference's reconstruction is lattice::BoxSplineReconstruction). u8
// lattices are stored as 8-bit texels, the others as 32-bit floats
// (texelFetch needs no filtering, so float texels cost no feature). Every
// technique that samples a layout renders FCC data unchanged. Needs OpenGL
// ES 3 (3D textures, texelFetch, integer maths); the planner refuses it on
// gles2 profiles and never picks it for "auto" (it changes the
// reconstruction, not only the storage).
//
// Registered twice: "fcc" resamples a Cartesian volume onto the lattice at
// the same sample count, "fcc-half" at half of it (Sarfaraz & Shaban 2015,
// Tables 2 and 1); FccLayout::create() takes a lattice made elsewhere (e.g.
// the Marschner-Lobb signal sampled on it directly).
#include <memory>
#include <string>

#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/MemoryLedger.h"
#include "tessera/lattice/FccVolume.h"
#include "tessera/layout/Layout.h"
#include "tessera/layout/LayoutRegistry.h"

namespace tessera::layout {

class FccLayout final : public Layout {
 public:
  // The registry name of a density: "fcc" (same) or "fcc-half".
  static std::string layoutName(lattice::FccDensity density);

  // How the lattice lives in its texture:
  //   Packed: the lattice's x-packing as it is (lattice/FccVolume.h), one
  //     texel per point: 16 texelFetch per sample.
  //   Cubes: one RGBA texel per unit cube of the grid (origins -2 .. D),
  //     holding its four FCC corners, the boundary rule applied: the 16
  //     points of every sample are the corners of 5 cubes, so 5 texelFetch
  //     per sample, for 8 x the bytes of Packed (+ the 2-cube margin).
  //     On llvmpipe a fetch costs far more than the spline's arithmetic
  //     (tessera bench --fcc), which this trades memory for.
  //   Auto: Cubes where they fit the device, else Packed.
  enum class Storage { Auto, Packed, Cubes };
  static const char* storageName(Storage storage);

  // The texture a lattice of gridDims with `type` texels needs, within
  // `limits` (fits = false and why: no ES 3, too large, over budget).
  static LayoutPlan planFor(glm::ivec3 gridDims, ScalarType type, const gpu::DeviceLimits& limits,
                            const std::string& name = "fcc", Storage storage = Storage::Auto);

  // Uploads a lattice (kept by the layout, for its value blocks). GpuError
  // when the plan does not fit.
  static std::unique_ptr<FccLayout> create(lattice::FccVolume fcc, const gpu::DeviceLimits& limits,
                                           gpu::MemoryLedger& ledger,
                                           const std::string& name = "fcc",
                                           Storage storage = Storage::Auto);
  // Resamples a Cartesian volume onto the lattice (lattice::resampleToFcc:
  // cubic B-spline, quasi-interpolated, texels of the volume's type) and
  // uploads it.
  static std::unique_ptr<FccLayout> resample(const Volume& volume, lattice::FccDensity density,
                                             const gpu::DeviceLimits& limits,
                                             gpu::MemoryLedger& ledger);

  std::string name() const override { return name_; }
  const LayoutPlan& plan() const override { return plan_; }
  gpu::ShaderPart glsl() const override;
  std::vector<gpu::ShaderPart> glslParts() const override;
  int bind(const gpu::Program& program, int firstUnit) const override;
  ValueMapping rawFromStored() const override { return mapping_; }
  int textureUnits() const override { return 1; }
  // The Cartesian box the lattice spans (what techniques march through).
  glm::ivec3 volumeDims() const override { return fcc_.box().dims(); }
  std::uint64_t textureBytes() const override { return texture_.bytes(); }
  // The box spline reaches 2 grid units (|x|_inf <= 2): at most 2 voxels of
  // the box at either density.
  int supportVoxels() const override { return 2; }
  // Min/max of the lattice coefficients each block's samples can read: the
  // box spline is non-negative and sums to 1, so every sample lies between
  // them.
  ValueBlocks valueBlocks(int blockSize) const override;

  const lattice::FccVolume& lattice() const { return fcc_; }
  // The box spline over the lattice, the field the GLSL evaluates.
  ReferenceField referenceField() const override;
  Storage storage() const { return storage_; }

  // For `tessera bench --fcc`'s split of the cost: the 16 fetches without
  // the weights (their mean), or the weights without fetches (coefficients
  // made up from the point's coordinates). Neither is a reconstruction; set
  // before a technique builds its program.
  enum class Evaluation { BoxSpline, FetchesOnly, ArithmeticOnly };
  void setEvaluation(Evaluation e) { evaluation_ = e; }

  static LayoutEntry registration(lattice::FccDensity density);

 private:
  FccLayout() = default;
  void uploadPacked(const lattice::FccVolume& fcc, gpu::MemoryLedger& ledger);
  void uploadCubes(const lattice::FccVolume& fcc, gpu::MemoryLedger& ledger);
  std::string name_;
  lattice::FccVolume fcc_;
  LayoutPlan plan_;
  gpu::Texture texture_;
  ValueMapping mapping_;
  Evaluation evaluation_ = Evaluation::BoxSpline;
  Storage storage_ = Storage::Packed;
};

}  // namespace tessera::layout
