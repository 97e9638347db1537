#include "cli/SamplingOptions.h"

#include <cmath>
#include <cstdio>

#include "cli/Options.h"
#include "tessera/core/Error.h"

namespace tessera::app {

bool parseOnOff(const std::string& text, const std::string& option) {
  return parseOnOffOr(text, option, "");
}

bool parseOnOffOr(const std::string& text, const std::string& option, const std::string& other) {
  if (text == "on" || text == "true" || text == "1" || text == "yes") return true;
  if (text == "off" || text == "false" || text == "0" || text == "no") return false;
  throw InputError(option + " '" + text + "': expected " +
                   (other.empty() ? "on or off" : "on, off or " + other));
}

void addSamplingOptions(CLI::App* cmd, SamplingOptions& o) {
  o.stepOption =
      addDefaultedOption(cmd, "--step", o.step,
                         "Base sample distance in voxels of the smallest spacing; adaptive steps "
                         "take every m-th sample of it where the TF allows (add --adaptive off for "
                         "exactly this step everywhere)");
  addDefaultedOption(cmd, "--preintegrate", o.preintegrate,
                     "Pre-integrated classification of the segments between samples (composite "
                     "ray casting): on, off (post-classification of each sample; with adaptive "
                     "steps the fastest that keeps 40 dB, docs/sampling.md) or lit (only frames "
                     "with --shade or --gradient-opacity)");
  addDefaultedOption(
      cmd, "--adaptive", o.adaptive,
      "Adaptive sampling: larger steps inside empty-space blocks where the TF varies "
      "little over the block's values (composite ray casting; needs --skip-block > "
      "0): on or off");
  o.toleranceOption =
      addDefaultedOption(cmd, "--adaptive-tolerance", o.tolerance,
                         "With --adaptive: a block takes m base steps at once while m * step * (TF "
                         "variation over its values, per mm) <= this; by default this in unlit "
                         "frames and half of it with --shade or --gradient-opacity");
  addDefaultedOption(cmd, "--adaptive-max", o.maxMultiplier,
                     "With --adaptive: the largest multiple of the base step (1, 2, 4, ... 64)");
  addDefaultedOption(cmd, "--adaptive-growth", o.growth,
                     "With --adaptive: steps also grow behind accumulated opacity A, by "
                     "2^floor(-log2(1 - A)) (its error reaches the pixel 1 - A times weaker): on "
                     "or off");
}

void applySampling(const SamplingOptions& o, RenderSettings& settings) {
  settings.stepVoxels = o.step;
  settings.sampling.preintegrateLitOnly = o.preintegrate == "lit";
  settings.sampling.preintegrate = settings.sampling.preintegrateLitOnly ||
                                   parseOnOffOr(o.preintegrate, "--preintegrate", "lit");
  settings.sampling.adaptive = parseOnOff(o.adaptive, "--adaptive");
  const int m = o.maxMultiplier;
  settings.sampling.tolerance = o.tolerance;
  // Given, the tolerance holds for lit frames too; otherwise theirs is the default's.
  const bool given = o.toleranceOption != nullptr && o.toleranceOption->count() > 0;
  settings.sampling.litTolerance = given ? -1.0 : defaultSampling().litTolerance;
  settings.sampling.maxMultiplier = m;
  settings.sampling.opacityGrowth = parseOnOff(o.growth, "--adaptive-growth");
}

std::string describeSampling(const RenderSettings& s) {
  char buf[160];
  std::string out;
  std::snprintf(buf, sizeof buf, "step %g voxel", s.stepVoxels);
  out = buf;
  out += usesPreintegration(s) ? ", pre-integrated" : ", post-classified";
  if (usesAdaptiveSampling(s)) {
    std::snprintf(buf, sizeof buf, ", adaptive steps up to %dx (tolerance %g%s)",
                  s.sampling.maxMultiplier, adaptiveTolerance(s),
                  s.sampling.opacityGrowth ? ", growing behind opacity" : "");
    out += buf;
  }
  return out;
}

}  // namespace tessera::app
