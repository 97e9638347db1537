#pragma once
// The CPU twin of the GPU's multi-channel frames (docs/channels.md): the same
// rays and sample positions as renderReference (ReferenceRaycaster.h), each
// sample classifying every visible channel by its own window and colour and
// the transfer function's opacity, composited additively or projected per
// channel (ChannelSet::mode).
#include "tessera/core/Camera.h"
#include "tessera/core/ChannelSet.h"
#include "tessera/core/Image.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/core/TransferFunction.h"

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

}  // namespace tessera
