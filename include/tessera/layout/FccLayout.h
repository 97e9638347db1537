#pragma once
// An FCC lattice (lattice/FccVolume.h) behind the layout seam: its x-packed
// texels in one single-channel 3D texture (R8 for u8 lattices, R32F for the
// others: texelFetch needs no filtering, so float texels cost no feature),
// and a sampleVolume() that evaluates the six-direction box spline from the
// 16 lattice points of the sample's tetrahedron with texelFetch
// (layout/fcc.glsl + the generated layout/fcc_pieces.glsl; the CPU twin is
// lattice::FccBoxSpline, the CPU reference's reconstruction is
// lattice::BoxSplineReconstruction). Every technique that samples a layout
// renders FCC data unchanged. Needs OpenGL ES 3 (3D textures, texelFetch,
// integer maths); the planner refuses it on gles2 profiles and never picks it
// for "auto" (it changes the reconstruction, not only the storage).
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

  // The texture a lattice of gridDims with `type` texels needs, within
  // `limits` (fits = false and why: no ES 3, too large, over budget).
  static LayoutPlan planFor(glm::ivec3 gridDims, ScalarType type, const gpu::DeviceLimits& limits,
                            const std::string& name = "fcc");

  // Uploads a lattice (kept by the layout, for its value blocks). GpuError
  // when the plan does not fit.
  static std::unique_ptr<FccLayout> create(lattice::FccVolume fcc, const gpu::DeviceLimits& limits,
                                           gpu::MemoryLedger& ledger,
                                           const std::string& name = "fcc");
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

  // For `tessera bench --fcc`'s split of the cost: the 16 fetches without
  // the weights (their mean), or the weights without fetches (coefficients
  // made up from the point's coordinates). Neither is a reconstruction; set
  // before a technique builds its program.
  enum class Evaluation { BoxSpline, FetchesOnly, ArithmeticOnly };
  void setEvaluation(Evaluation e) { evaluation_ = e; }

  static LayoutEntry registration(lattice::FccDensity density);

 private:
  FccLayout() = default;
  std::string name_;
  lattice::FccVolume fcc_;
  LayoutPlan plan_;
  gpu::Texture texture_;
  ValueMapping mapping_;
  Evaluation evaluation_ = Evaluation::BoxSpline;
};

}  // namespace tessera::layout
