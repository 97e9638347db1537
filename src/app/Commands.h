#pragma once
// The `tessera` subcommands; each registers itself on the CLI11 app and
// returns a callback run after parsing.
#include <functional>

#include <CLI/CLI.hpp>

namespace tessera::app {

void addInfoCommand(CLI::App& app);
void addRenderCommand(CLI::App& app);
void addBenchCommand(CLI::App& app);
void addProfilesCommand(CLI::App& app);  // ProfilesCommand.cpp
void addPlanCommand(CLI::App& app);      // PlanCommand.cpp
void addConvertCommand(CLI::App& app);   // ConvertCommand.cpp

// ch2 from mricron-data when installed, else a generated Shepp–Logan phantom.
std::string defaultVolumeSpec();

}  // namespace tessera::app
