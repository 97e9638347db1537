#include "cli/FusionOptions.h"

#include <cstdio>

#include "tessera/core/Error.h"
#include "tessera/render/HybridCompositor.h"

namespace tessera::app {

void addFusionOptions(CLI::App* cmd, FusionOptions& o) {
  o.command = cmd;
  cmd->add_option("--overlay", o.file,
                  "A second volume over this one (an atlas, a segmentation, PET, a statistical "
                  "map), aligned by world (patient) coordinates and resampled on the fly, mixed "
                  "into the same ray march (docs/fusion.md; raycast, composite, ES 3 profiles)");
  o.labelsOption =
      cmd->add_option("--overlay-labels", o.labels,
                      "The overlay is a label volume (integers 0..255): nearest sampling and the "
                      "colours and names of TABLE (a label file as --labels takes; without "
                      "TABLE a default palette)")
          ->expected(0, 1);
  o.tfOption = cmd->add_option("--overlay-tf", o.tf,
                               "The overlay's colour map: hot (default), a --tf preset or "
                               "FILE.json");
  cmd->add_option("--overlay-opacity,--overlay-alpha", o.opacity,
                  "How much the overlay's colour replaces the anatomy's, (0, 1] (default 0.5)");
  cmd->add_option("--overlay-window", o.window,
                  "The overlay's value window LO HI (raw values; default its value range)")
      ->expected(2);
}

const std::set<std::string>& fusionOptionNames() {
  static const std::set<std::string> names = {"--overlay", "--overlay-labels", "--overlay-tf",
                                              "--overlay-opacity", "--overlay-window"};
  return names;
}

namespace {

// --overlay-opacity's value: the overlay's opacity. Until 2026-11 the option
// named the hybrid compositor's line attenuation, now --line-attenuation; an
// old command line gets that said rather than "needs --overlay".
double overlayOpacity(const std::string& text) {
  if (text.empty()) return 0.5;
  for (const render::OverlayOpacity m : render::allOverlayOpacities()) {
    if (render::overlayOpacityName(m) == text) {
      throw InputError("--overlay-opacity " + text +
                       ": the attenuation of the --overlays lines is now --line-attenuation " +
                       text + "; --overlay-opacity is the --overlay volume's opacity, (0, 1]");
    }
  }
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !(value > 0.0 && value <= 1.0)) {
    throw InputError("--overlay-opacity '" + text + "': expected the overlay's opacity in (0, 1]");
  }
  return value;
}

}  // namespace

void openFusion(session::Session& session, const FusionOptions& o) {
  const CLI::App* cmd = o.command;
  const double opacity = overlayOpacity(o.opacity);
  if (o.file.empty()) {
    for (const std::string& name : fusionOptionNames()) {
      if (name != "--overlay" && cmd->get_option(name)->count() > 0) {
        throw InputError(name + " needs --overlay FILE");
      }
    }
    return;
  }
  if (o.labelOverlay() && o.tfOption->count() > 0) {
    throw InputError(
        "--overlay-labels and --overlay-tf exclude each other: a label overlay takes "
        "its colours from its table");
  }
  session::OverlayOptions options;
  options.labels = o.labelOverlay();
  options.labelTable = o.labels;
  options.tf = o.tf;
  options.opacity = opacity;
  if (!o.window.empty()) options.window = ValueRange{o.window[0], o.window[1]};
  session.openOverlay(o.file, options);
  if (!session.overlay()->note.empty()) {
    std::fprintf(stderr, "tessera: note: %s\n", session.overlay()->note.c_str());
  }
}

void printOverlayText(const session::Overlay& overlay) {
  const FusedVolume& f = *overlay.fused;
  const glm::ivec3 d = f.volume->dims();
  const std::string look =
      f.labels ? "labels (" + std::to_string(overlay.labels.labels.size()) + " in the table)"
               : "tf " + f.tf.name + ", window " + std::to_string(f.window.min) + ".." +
                     std::to_string(f.window.max);
  std::printf("overlay  %s %dx%dx%d: %s, opacity %g, fused in the ray march\n",
              overlay.name.c_str(), d.x, d.y, d.z, look.c_str(), f.opacity);
}

}  // namespace tessera::app
