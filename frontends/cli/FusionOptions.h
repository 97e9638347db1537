#pragma once
// A second volume over the anatomy (docs/fusion.md), the options render and
// probe share: --overlay FILE, --overlay-labels [TABLE] or --overlay-tf
// PRESET, --overlay-opacity A (or its older name --overlay-alpha),
// --overlay-window LO HI. (--overlays and --line-attenuation are the hybrid
// compositor's lines, HybridJob.h.)
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "tessera/session/Session.h"

namespace tessera::app {

struct FusionOptions {
  std::string file;
  std::string tf = "hot";
  std::string labels;
  CLI::Option* labelsOption = nullptr;
  CLI::Option* tfOption = nullptr;
  std::string opacity;  // "" (0.5) or a number in (0, 1]
  std::vector<double> window;
  const CLI::App* command = nullptr;
  bool labelOverlay() const { return labelsOption != nullptr && labelsOption->count() > 0; }
};

void addFusionOptions(CLI::App* cmd, FusionOptions& o);
// The options' names (for render's runOptions()).
const std::set<std::string>& fusionOptionNames();
// Opens the overlay in the session when --overlay is given (its note on
// stderr); InputError for an --overlay-* option without --overlay, or both
// --overlay-labels and --overlay-tf.
void openFusion(session::Session& session, const FusionOptions& o);

// "overlay  FILE: labels (N named), opacity A" for render's text report.
void printOverlayText(const session::Overlay& overlay);

}  // namespace tessera::app
