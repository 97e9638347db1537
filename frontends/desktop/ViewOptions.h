#pragma once
// `tessera view`'s options as the command line gives them (ViewCommand.cpp)
// and the entry that runs the window with them (DesktopApp.cpp, or
// ViewUnavailable.cpp where the build has no GLFW or Dear ImGui).
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/ClippingOptions.h"
#include "cli/FusionOptions.h"
#include "cli/ShadingOptions.h"

namespace tessera::desktop {

struct ViewOptions {
  std::string file;
  std::string series;
  int time = 0;     // the time point shown first (a 4-D NIfTI, a store's t axis)
  int channel = 0;  // a store's channel (c axis)
  std::string tf = "mr-default";
  bool tfGiven = false;  // --tf given: the volume's modality does not pick the TF
  std::string size = "1280x800";
  std::string profile = "gles3";
  double azimuth = 0.0;
  double elevation = 0.0;
  std::string screenshot;
  std::string state;      // a saved session state to start from
  std::string saveState;  // where the session's state goes when the window closes
  int frames = 3;
  double play = 0.0;       // a time series played at this many time points per second (0: paused)
  bool bricks = false;     // a store's t axis played over bricks (layout bricks)
  int playTimePoints = 0;  // with --screenshot: end once this many time points were shown
  std::string playRecord;  // each time point's frame as shown, into this folder
  bool helpOverlay = false;
  std::string layout = "four";  // four: axial, 3D, sagittal, coronal; single: 3D only
  std::vector<int> crosshair;   // X Y Z (level-0 voxel)
  bool pick = false;            // pick the region around the crosshair
  int regionSide = 0;           // 0: 256 or what the profile allows
  double zoom = 1.0;
  bool zoomGrid = false;          // the zoom swaps coarse / medium / native block (ZoomSwap)
  std::string mode = "overview";  // overview, region, grid
  app::ShadingOptions shading;
  app::ClippingOptions clipping;
  std::string projection = "composite";  // composite, mip, minip, average (RenderMode)
  // --labels [TABLE]: a label volume, as `tessera render --labels` shows it.
  std::string labels;
  CLI::Option* labelsOption = nullptr;
  bool labelVolume() const { return labelsOption != nullptr && labelsOption->count() > 0; }
  app::FusionOptions fusion;  // --overlay: a second volume over this one (docs/fusion.md)
};

// Opens the window and runs it until it is closed (or --screenshot is written).
void runView(const ViewOptions& options);

}  // namespace tessera::desktop
