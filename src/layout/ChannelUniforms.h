#pragma once
// The u_layoutChannel* uniforms of layout/channels.glsl, which ChannelLayout
// and BricksLayout's channels share: per channel its window as n = stored *
// scale + bias (stored in [0,1] over the channel's mapping), its visibility
// and its colour, four channels per vec4 (docs/channels.md).
#include <vector>

#include "tessera/core/ChannelSet.h"
#include "tessera/gpu/Program.h"
#include "tessera/layout/Layout.h"

namespace tessera::layout {

// `mappings[i]`: channel i's raw value of stored 0..1 (raw = scale * stored
// + offset); `textures`: the RGBA textures (or atlases) holding them.
void setChannelUniforms(const gpu::Program& program, const ChannelSet& set,
                        const std::vector<ValueMapping>& mappings, int textures);

}  // namespace tessera::layout
