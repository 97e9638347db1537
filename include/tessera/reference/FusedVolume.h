#pragma once
// A second volume shown over the anatomy in the same ray march (docs/fusion.md):
// a label atlas or segmentation (nearest sampling, a label table's colours) or
// another modality (trilinear, its own transfer function and window), aligned
// by world (patient, RAS+ mm) coordinates through both volumes' index -> world
// affines, so that a fused volume of another spacing, extent or orientation is
// resampled on the fly. This is the look and the CPU maths the GPU
// (render/FusionTexture.h, render/fusion.glsl) and the reference share.
#include <memory>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "tessera/core/TransferFunction.h"
#include "tessera/core/Volume.h"

namespace tessera {

struct FusedVolume {
  std::shared_ptr<const Volume> volume;
  // Labels: `tf` is the label table's categorical TF (x = value / 255), read
  // at the nearest voxel and the nearest of 256 entries; otherwise the TF of
  // the window-normalised, trilinearly interpolated value.
  TransferFunction tf;
  bool labels = false;
  ValueRange window{0.0, 255.0};  // raw values -> [0,1] (labels: 0..255)
  double opacity = 0.5;           // [0,1]: how much the fused colour replaces the anatomy's
};

// The affine from the anatomy's normalised texture coordinates p (voxel
// centres at (i + 0.5) / dims) to the fused volume's: p -> anatomy index ->
// world (mm) -> fused index -> q.
glm::dmat4 fusedFromAnatomy(const Volume& anatomy, const Volume& fused);

// Whether the two volumes' boxes (voxel cells) share any world point: the
// fused box's eight corners in the anatomy's texture space against [0,1]^3,
// and the other way round, by their bounding boxes (conservative).
bool fusedOverlaps(const Volume& anatomy, const Volume& fused);

// The fused volume's straight colour and weight w = TF opacity * opacity at
// its normalised coordinates q; w = 0 outside [0,1]^3.
glm::dvec4 fusedColorAt(const FusedVolume& fused, glm::dvec3 q);

// The fusion rule (docs/fusion.md): anatomy sample (straight colour c, opacity
// a for the step ds) and fused colour f (f.a = w): colour mix(c, f, w),
// opacity max(a, 1 - (1 - w)^(ds / unit)), unit = the fused TF's opacity
// unit length.
glm::dvec4 fuseSample(glm::dvec3 color, double alpha, glm::dvec4 fusedColor, double ds,
                      double unitLength);

// The fused volume's raw value at a world position (mm): its nearest voxel
// for labels, trilinear otherwise; nullopt-like NaN outside its box.
double fusedValueAtWorld(const FusedVolume& fused, glm::dvec3 worldMm);

// What the CPU reference needs to fuse (ReferenceRaycaster.h): the look and
// the matrix of fusedFromAnatomy for the volume it renders.
struct FusionTwin {
  const FusedVolume& fused;
  glm::dmat4 fusedFromAnatomy;
  // The anatomy sample at texture position p (straight colour, opacity for
  // the step ds) with the fused volume over it.
  glm::dvec4 fuse(glm::dvec3 color, double alpha, glm::dvec3 p, double ds) const;
};

// The voxel index (continuous) of a world position in `volume`.
glm::dvec3 indexOfWorld(const Volume& volume, glm::dvec3 worldMm);

}  // namespace tessera
