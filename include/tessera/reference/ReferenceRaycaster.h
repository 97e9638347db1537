#pragma once
// CPU ray caster in double precision with exactly the rendering semantics of
// the GPU techniques (DESIGN.md, Rendering semantics): same camera rays, same
// sample positions t0 + (k + j) ds, trilinear reconstruction with voxel
// centres at (i + 0.5) / dims and clamp-to-edge, the value window, the
// continuous transfer function with opacity correction, front-to-back
// compositing with the same early termination, MIP, background.
#include <cstdint>
#include <vector>

#include <utility>

#include <glm/vec3.hpp>

#include "tessera/core/Camera.h"
#include "tessera/core/Image.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/core/Volume.h"
#include "tessera/reference/AdaptiveSteps.h"
#include "tessera/reference/FusedVolume.h"
#include "tessera/reference/Reconstruction.h"

namespace tessera {

// Trilinear interpolation of raw values at p in [0,1]^3, straight from the
// volume (TrilinearReconstruction's value without its double copy).
double sampleTrilinear(const Volume& volume, glm::dvec3 p);

// Where a ray from texture-space point `origin` along `direction` (not
// normalised: t in world units, as on the GPU) enters and leaves the unit
// box [0,1]^3, the entry clamped to t >= 0; entry > exit when it misses.
std::pair<double, double> unitBoxSpan(glm::dvec3 origin, glm::dvec3 direction);

// Work done by one reference frame (the same samples the GPU takes when
// empty-space skipping is off): how much work a technique has to do.
struct ReferenceStats {
  std::uint64_t raysHittingVolume = 0;
  std::uint64_t samples = 0;
  // Positions the ray visited, samples plus those where a walked grid
  // (AdaptiveSteps.h) found an empty block and left it: the GPU loop's
  // iterations.
  std::uint64_t steps = 0;
};

// Opaque things in the scene besides the volume (overlay lines), per pixel:
// where color's alpha > 0 the ray stops at `distance` (Camera::pixelRay
// parameter, world units) and the colour takes the place of the background.
// Both are width x height, top row first. See ReferenceOverlay.h.
struct ReferenceStops {
  const Image& color;
  const std::vector<float>& distance;
};

// Renders width x height pixels of the volume's trilinear field; threads = 0
// uses every hardware thread. With settings.sampling.preintegrate the
// composite mode classifies segments (PreIntegration.h). `steps`: the block
// grid the GPU ray caster walks (AdaptiveSteps.h); given, the reference takes
// exactly its samples (adaptive steps, and empty blocks left as it leaves
// them); without it every sample of the lattice, as with skipping off.
// `fusion`: a second volume over this one (FusedVolume.h; composite,
// post-classified samples, before the light).
Image renderReference(const Volume& volume, const TransferFunction& tf, const Camera& camera,
                      const RenderSettings& settings, int width, int height, int threads = 0,
                      ReferenceStats* stats = nullptr, const ReferenceStops* stops = nullptr,
                      const StepGrid* steps = nullptr, const FusionTwin* fusion = nullptr);

// The same with another reconstruction of the field: `volume` gives the box
// (extent, spacing for the sample distance) and the value window, `field`
// the values (e.g. an FCC box spline over the same box).
Image renderReference(const Volume& volume, const Reconstruction& field, const TransferFunction& tf,
                      const Camera& camera, const RenderSettings& settings, int width, int height,
                      int threads = 0, ReferenceStats* stats = nullptr,
                      const ReferenceStops* stops = nullptr, const StepGrid* steps = nullptr,
                      const FusionTwin* fusion = nullptr);

}  // namespace tessera
