#pragma once
// The settings of a multi-channel frame (docs/channels.md): which channels
// of an OME-Zarr store, and the user's colours, windows and mode over the
// store's omero defaults. Front ends (CLI, viewers, Python) fill this and
// Session renders it; validate() is the one check.
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/ChannelSet.h"
#include "tessera/core/Image.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/core/TransferFunction.h"

namespace tessera::session {

struct ChannelSettings {
  bool enabled = false;             // render the store's channels together
  std::vector<int> indices;         // empty: every channel of the store
  std::vector<glm::dvec3> colors;   // empty: omero's; else one per channel
  std::vector<ValueRange> windows;  // empty: omero's; else one per channel
  std::vector<bool> visible;        // empty: omero's "active"; else one per channel
  ChannelMode mode = ChannelMode::Additive;

  // InputError for more than ChannelSet::kMaxChannels, a colour outside
  // [0,1], an empty window, or lists of colours/windows/visibility whose
  // length differs from the channels chosen.
  void validate() const;
  // The user's choices over the store's defaults, checked against the
  // channels read (`spec` names the store in the messages).
  void applyTo(ChannelSet& set, const std::string& spec) const;
};

// "ff0000,00ff00" and "100:2000,50:900" as given on the command line.
std::vector<glm::dvec3> parseChannelColors(const std::string& text);
std::vector<ValueRange> parseChannelWindows(const std::string& text);

// One multi-channel frame and, when asked, the CPU reference's.
struct ChannelFrame {
  Image image;
  std::optional<Image> reference;
  double psnr = 0.0;                  // of image against reference
  std::string layout;                 // how the channels lie in textures
  std::vector<std::string> channels;  // "sphere ff0000 100:3000 on", per channel
  double gpuMs = 0.0;
  double referenceMs = 0.0;
};

}  // namespace tessera::session
