#pragma once
// Ground truth for volume rendering with overlay lines: the CPU reference
// ray caster (same semantics as renderReference) at full resolution, where
// each ray that meets a line stops at the line's distance and the line,
// opaque, takes the place of the background. A line inside or behind
// semi-transparent volume is so attenuated by exactly the volume in front
// of it; a line in front of the volume is seen unattenuated.
#include <vector>

#include "tessera/core/Camera.h"
#include "tessera/core/Image.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/core/Volume.h"

namespace tessera {

// `lineColor` (width x height, top row first): alpha > 0 marks a line
// pixel, whose RGB is the line's colour; `lineDistance`: for each pixel the
// line's distance along the pixel ray (Camera::pixelRay parameter, world
// units), ignored where there is no line. Both typically come from
// render::OverlayRenderer, so that the ground truth and the GPU paths see
// the same line pixels. InputError when the sizes disagree.
Image renderReferenceWithLines(const Volume& volume, const TransferFunction& tf,
                               const Camera& camera, const RenderSettings& settings, int width,
                               int height, const Image& lineColor,
                               const std::vector<float>& lineDistance, int threads = 0);

}  // namespace tessera
