#pragma once
// How the ray caster samples (docs/sampling.md): the base step, pre-integrated
// classification and adaptive steps, as `tessera render` and `tessera bench`
// take them. The defaults are the fastest settings measured to keep >= 40 dB
// against a 0.25-voxel reference on every volume, TF and shading tried
// (docs/sampling.md, "Defaults"); `--step` sets the base step, and
// `--preintegrate off --adaptive off` brings back plain post-classified
// sampling at exactly that step.
#include <string>

#include <CLI/CLI.hpp>

#include "tessera/core/RenderSettings.h"

namespace tessera::app {

// Defaults: defaultSampling() and kDefaultStepVoxels (core/RenderSettings.h),
// which the viewers start with too.
struct SamplingOptions {
  double step = kDefaultStepVoxels;
  std::string preintegrate = !defaultSampling().preintegrate         ? "off"
                             : defaultSampling().preintegrateLitOnly ? "lit"
                                                                     : "on";
  std::string adaptive = defaultSampling().adaptive ? "on" : "off";
  double tolerance = defaultSampling().tolerance;
  CLI::Option* toleranceOption = nullptr;  // given: lit frames take it too
  int maxMultiplier = defaultSampling().maxMultiplier;
  std::string growth = defaultSampling().opacityGrowth ? "on" : "off";
  CLI::Option* stepOption = nullptr;
  bool stepGiven() const { return stepOption != nullptr && stepOption->count() > 0; }
};

// --step, --preintegrate, --adaptive, --adaptive-tolerance, --adaptive-max,
// --adaptive-growth.
void addSamplingOptions(CLI::App* cmd, SamplingOptions& o);
// Into settings.stepVoxels and settings.sampling (checked by session::Settings::validate);
// InputError for words that are not on/off.
void applySampling(const SamplingOptions& o, RenderSettings& settings);
// "on"/"off" (also true/false, 1/0, yes/no) as a bool; InputError names the option.
bool parseOnOff(const std::string& text, const std::string& option);
// The same where a third word `other` is handled by the caller (named in the error).
bool parseOnOffOr(const std::string& text, const std::string& option, const std::string& other);
// A line for reports: "step 0.5 voxel, pre-integrated, adaptive x8 (tolerance 0.1)".
std::string describeSampling(const RenderSettings& settings);

}  // namespace tessera::app
