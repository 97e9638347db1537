#pragma once
// The `tessera` subcommands; each registers itself on the CLI11 app and
// returns a callback run after parsing.
#include <functional>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/Options.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/io/FormatRegistry.h"
#include "tessera/session/RenderRun.h"
#include "tessera/session/VolumePyramid.h"

namespace tessera::app {

// Exit statuses (docs/cli.md "Exit status"): 0 done; 1 an error, its one
// line on stderr (nothing written); 2 an internal error; 3 the output was
// written but is incomplete (render: bricks left at a coarser level
// because their reads kept failing, or the refinement stopped at its
// limit); CLI11's 100-127 for options it cannot parse.
inline constexpr int kExitError = 1;
inline constexpr int kExitInternal = 2;
inline constexpr int kExitIncomplete = 3;

// Thrown once a command has written its outputs and reported, when they are
// incomplete; main prints "tessera: incomplete: <what>" and exits with
// kExitIncomplete.
class IncompleteOutput : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The session types every command uses.
using gpu::DeviceSession;
using gpu::openDevice;
using session::BricksRun;
using session::chunksTouched;
using session::CountingStorage;
using session::openVolumePyramid;
using session::parseLevel;
using session::parseRegion;
using session::RenderRequest;
using session::RenderResult;
using session::runRender;
using session::VolumePyramid;

void addInfoCommand(CLI::App& app);
void addRenderCommand(CLI::App& app);
void addBenchCommand(CLI::App& app);
void addProfilesCommand(CLI::App& app);  // ProfilesCommand.cpp
void addPlanCommand(CLI::App& app);      // PlanCommand.cpp
void addConvertCommand(CLI::App& app);   // ConvertCommand.cpp
void addViewCommand(CLI::App& app);      // ViewCommand.cpp (desktop viewer)
void addProbeCommand(CLI::App& app);     // ProbeCommand.cpp
void addSliceCommand(CLI::App& app);     // SliceCommand.cpp
void addFormatsCommand(CLI::App& app);   // FormatsCommand.cpp
void addDicomWebCommand(CLI::App& app);  // DicomWebCommand.cpp

// The volume argument's help (its formats from io/FormatRegistry.h), and the
// --series option every command that reads a volume offers.
inline const std::string kVolumeHelp =
    "Volume: " + readExtensionsText() +
    ". An OME-Zarr store: render streams it through bricks when its finest level does not fit "
    "in core or with --layout bricks, otherwise the finest level that fits the host budget is "
    "read. Default: ch2 (mricron-data) or a Shepp-Logan phantom. render and plan: "
    "head:WxHxD (or head:N) is a generated u8 head of any size computed brick by brick, never "
    "held whole (streamed through the bricks layout when it does not fit in core). "
    "`tessera formats` lists the formats";
inline void addSeriesOption(CLI::App* cmd, std::string& series) {
  cmd->add_option("--series", series,
                  "DICOM: Series Instance UID to read when a folder holds several (default: the "
                  "series with the most slices; `tessera info FOLDER` lists them)");
}

// The volume argument and --series together, as info, render, plan, slice
// and view take them.
inline void addVolumeOptions(CLI::App* cmd, std::string& file, std::string& series) {
  cmd->add_option("file", file, kVolumeHelp);
  addSeriesOption(cmd, series);
}

// --time and --channel: which 3D volume of a 4D/5D (t, c, z, y, x) OME-Zarr
// image the command reads.
inline void addTimeChannelOptions(CLI::App* cmd, int& time, int& channel) {
  cmd->add_option("--time", time,
                  "time point to read: an OME-Zarr t axis or a 4-D NIfTI (0-based, default 0)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--channel", channel, "OME-Zarr: channel to read from a c axis (default 0)")
      ->check(CLI::NonNegativeNumber);
}

// --labels [TABLE]: render and view show a label volume with or without a
// colour table; the option's count() says whether it was given.
inline CLI::Option* addLabelsOption(CLI::App* cmd, std::string& table, const std::string& help) {
  return cmd->add_option("--labels", table, help)->expected(0, 1);
}

// Parses --size "512x512" (InputError otherwise).
void parseSize(const std::string& text, int& width, int& height);

// ch2 from mricron-data when installed, else a generated Shepp–Logan phantom.
std::string defaultVolumeSpec();

}  // namespace tessera::app
