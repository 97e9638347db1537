// `tessera view [FILE]`: the desktop viewer's command-line options. The
// window itself (a GLFW window with an OpenGL ES context and Dear ImGui
// panels, DesktopApp.cpp) is built where GLFW and ImGui are found
// (cmake/DesktopViewer.cmake); elsewhere the command says what to install
// (ViewUnavailable.cpp).
#include <memory>

#include "ViewOptions.h"
#include "cli/Commands.h"
#include "tessera/core/Error.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/session/Settings.h"

namespace tessera::app {

namespace {

// The switches of where exploring starts.
struct StartFlag {
  const char* name;
  bool desktop::ViewOptions::*member;
  const char* help;
};
constexpr StartFlag kStartFlags[] = {
    {"--pick", &desktop::ViewOptions::pick,
     "Start with the region (default side: 256 or what the profile allows) picked around the "
     "crosshair"},
    {"--zoom-grid", &desktop::ViewOptions::zoomGrid,
     "Let the zoom swap the 3D view between a coarse level, the overview level and the native "
     "grid block around the view's centre (viewer/ZoomSwap: thresholds with hysteresis, a "
     "cross-fade on ES 2 and ES 3)"},
};

}  // namespace

void addViewCommand(CLI::App& app) {
  auto o = std::make_shared<desktop::ViewOptions>();
  CLI::App* cmd = app.add_subcommand(
      "view", "Interactive viewer: GLFW window with OpenGL ES (EGL) and the TF editor");
  addVolumeOptions(cmd, o->file, o->series);
  addTimeChannelOptions(cmd, o->time, o->channel);
  addDefaultedOption(cmd, "--tf", o->tf, "Transfer function: preset or FILE.json");
  addSizeOption(cmd, o->size, "Window");
  o->labelsOption = addLabelsOption(
      cmd, o->labels,
      "Show a label volume (atlas) as `tessera render --labels` does: nearest-neighbour sampling "
      "and a categorical colour table instead of --tf. TABLE (optional): JSON or a label text file "
      "(ITK-SNAP, FreeSurfer LUT, mricron); without it a default palette. The Labels panel shows "
      "and hides labels");
  addFusionOptions(cmd, o->fusion);
  addDefaultedOption(cmd, "--profile", o->profile,
                     "Device profile (gles3, gles2, webgl1, ...; its API level picks the context)");
  cmd->add_option("--azimuth", o->azimuth, "Initial camera azimuth in degrees");
  cmd->add_option("--elevation", o->elevation, "Initial camera elevation in degrees");
  cmd->add_option("--screenshot", o->screenshot,
                  "Write the window to this PNG after --frames frames and exit");
  addDefaultedOption(cmd, "--frames", o->frames, "Frames before --screenshot");
  cmd->add_option("--play", o->play,
                  "A time series (4-D NIfTI, OME-Zarr store with a t axis): start playing at FPS "
                  "time points per second (the "
                  "Time panel plays, pauses and picks one); with --screenshot, the playback's "
                  "rate, time points shown and late frames are printed")
      ->check(CLI::Range(0.1, 120.0));
  cmd->add_flag("--bricks", o->bricks,
                "An OME-Zarr store with a t axis plays over bricks (as `tessera render --layout "
                "bricks`: each time point streamed from its own chunks, the next ones read ahead "
                "within the host budget) even where its level 0 fits in core; a larger one always "
                "does");
  cmd->add_option("--play-time-points", o->playTimePoints,
                  "With --play and --screenshot: end once N time points have been shown after "
                  "the first (instead of after --frames frames)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--play-record", o->playRecord,
                  "With --play over bricks: the 3D view's frame of every time point shown, once "
                  "drawn complete (what playback moves on from), written to DIR/NNNN-tT.png (N: "
                  "the order shown), and a line per time point shown");
  addStateOptions(cmd, o->state, o->saveState,
                  "camera, transfer function, window, rendering settings, labels, crosshair, "
                  "region and grid of the volume given; applied after the other options",
                  "when the window closes");
  cmd->add_flag("--help-overlay", o->helpOverlay,
                "Start with the keyboard shortcuts shown (F1 or ? toggles them)");
  addDefaultedOption(cmd, "--layout", o->layout,
                     "four: axial, 3D, sagittal and coronal views (2x2); single: the 3D view only");
  cmd->add_option("--crosshair", o->crosshair, "Start with the crosshair at voxel X Y Z (native)")
      ->expected(3);
  addDefaultedOption(cmd, "--zoom", o->zoom, "Initial camera zoom (1: the volume fills the view)");
  for (const StartFlag& f : kStartFlags) cmd->add_flag(f.name, (*o).*f.member, f.help);
  cmd->add_option("--region-side", o->regionSide,
                  "Side of the picked region in voxels (16 .. 256 or what the profile allows)");
  addDefaultedOption(cmd, "--mode", o->mode,
                     "Start in: overview, region (the picked region at native resolution) or grid "
                     "(the grid view's block nearest the crosshair)");
  // The session's one list of render modes and its message for another.
  addDefaultedOption(cmd, "--render-mode", o->projection,
                     "The 3D view's mode: " + renderModeChoices() + " (the Rendering panel's mode)")
      ->check([](const std::string& text) {
        try {
          session::parseRenderMode(text);
          return std::string();
        } catch (const Error& e) {
          return std::string(e.what());
        }
      });
  addShadingOptions(cmd, o->shading);
  addClippingOptions(cmd, o->clipping);
  cmd->callback([o, cmd] {
    o->tfGiven = cmd->get_option("--tf")->count() > 0;
    desktop::runView(*o);
  });
}

}  // namespace tessera::app
