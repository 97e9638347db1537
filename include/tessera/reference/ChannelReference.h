#pragma once
// The CPU twin of the GPU's multi-channel frames (docs/channels.md): the same
// rays and sample positions as renderReference (ReferenceRaycaster.h), each
// sample classifying every visible channel by its own window and colour and
// the transfer function's opacity, composited additively or projected per
// channel (ChannelSet::mode).
#include <memory>
#include <vector>

#include "tessera/core/Camera.h"
#include "tessera/core/ChannelSet.h"
#include "tessera/core/Image.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/reference/CellLevels.h"

namespace tessera {

// One sample of the channels' normalised values n (one per channel, 0 for a
// hidden one) as premultiplied colour and opacity for additive mode, with
// the opacities a_i given: the definition both renderers follow.
struct ChannelSample {
  glm::dvec3 premultiplied{0.0};
  double alpha = 0.0;
};
ChannelSample combineChannels(const ChannelSet& channels, const double* opacities);

// width x height pixels of the channels' trilinear fields. Composite frames
// only in additive mode; settings.mode is ignored (the set's mode decides).
// Shading, clipping and pre-integration do not apply to channel frames.
Image renderChannelsReference(const ChannelSet& channels, const TransferFunction& tf,
                              const Camera& camera, const RenderSettings& settings, int width,
                              int height, int threads = 0);

// The levels a streamed channel frame shows (BricksLayout::createChannels:
// one page table for every channel): per channel its pyramid levels
// (index = level, null where no cell shows it), each level's scale
// (lod::levelScale) and the level of each level-0 brick cell.
struct ChannelLevels {
  CellLevels cells;
  std::vector<glm::ivec3> scales;
  std::vector<std::vector<std::shared_ptr<const Volume>>> volumes;  // [channel][level]
};

// As above, each sample reading, in every channel, the level its cell
// shows (sampleLevel): the reference of a frame that mixes levels.
// InputError when a cell names a level `levels` does not hold or a
// transparent constant (channel frames have none).
Image renderChannelsReference(const ChannelSet& channels, const ChannelLevels& levels,
                              const TransferFunction& tf, const Camera& camera,
                              const RenderSettings& settings, int width, int height,
                              int threads = 0);

}  // namespace tessera
