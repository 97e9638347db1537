#pragma once
// The shading options every command that renders offers (render, bench,
// view): --shade, --light, --ambient, --diffuse, --specular, --shininess,
// parsed into RenderSettings::shading (core/RenderSettings.h).
#include <string>

#include <CLI/CLI.hpp>

#include "tessera/core/RenderSettings.h"

namespace tessera::app {

struct ShadingOptions {
  bool shade = false;
  std::string light = "headlight";
  Shading coefficients;           // ambient, diffuse, specular, shininess and their defaults
  std::string gradient = "auto";  // auto, on-the-fly or precomputed (layout/GradientTexture.h)
  std::string gradientOpacity;    // --gradient-opacity: empty/off, on or LOW,HIGH
};

void addShadingOptions(CLI::App* cmd, ShadingOptions& o);
// InputError for a bad --light or coefficient.
Shading shadingFrom(const ShadingOptions& o);

}  // namespace tessera::app
