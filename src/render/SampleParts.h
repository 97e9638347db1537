#pragma once
// The fragment-shader parts the ray caster and slice3d share: one classified,
// shaded and clipped sample of a layout's volume.
#include <utility>
#include <vector>

#include "tessera/gpu/Program.h"
#include "tessera/layout/Layout.h"
#include "tessera/render/ShadingGradient.h"

namespace tessera::render {

// Appends the precomputed gradient's part (when defined; it stands in for
// the seam's own), the layout's seam parts (sampleVolume() and its gradient)
// and classify, shading, clipping and sample.glsl, in that order; the
// technique's own loop goes after them.
inline void addSampleParts(std::vector<gpu::ShaderPart>& parts, const ShadingGradient& gradient,
                           const layout::Layout& layout) {
  gradient.addParts(parts);
  for (gpu::ShaderPart& part : layout.seamParts()) parts.push_back(std::move(part));
  // render/channels.glsl: the channels' classification, when the layout
  // defines CHANNELS (layout/ChannelLayout.h).
  for (const char* file : {"render/classify.glsl", "render/channels.glsl", "render/shading.glsl",
                           "render/clipping.glsl", "render/sample.glsl"}) {
    parts.push_back(gpu::embeddedShaderPart(file));
  }
}

}  // namespace tessera::render
