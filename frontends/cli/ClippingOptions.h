#pragma once
// The clipping options of the commands that render (render, bench, view):
// --crop x0:x1,y0:y1,z0:z1 (normalised) and --clip nx,ny,nz,d (repeatable),
// parsed into RenderSettings::clipping (core/RenderSettings.h).
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "tessera/core/RenderSettings.h"

namespace tessera::app {

struct ClippingOptions {
  std::string crop;
  std::vector<std::string> clip;
};

void addClippingOptions(CLI::App* cmd, ClippingOptions& o);
// InputError naming the option and what was expected.
Clipping clippingFrom(const ClippingOptions& o);

}  // namespace tessera::app
