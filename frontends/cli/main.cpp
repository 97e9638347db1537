// tessera: command-line front end (info, render, bench).
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "cli/Commands.h"
#include "tessera/core/Error.h"

int main(int argc, char** argv) {
  CLI::App app{
      "Tessera: volume rendering for GPUs that lack something (3D textures, texture size,\n"
      "memory, fill rate). Renders headless through EGL and checks itself against a CPU "
      "reference."};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Show help for every subcommand");
  tessera::app::addInfoCommand(app);
  tessera::app::addRenderCommand(app);
  tessera::app::addBenchCommand(app);
  tessera::app::addProfilesCommand(app);
  tessera::app::addPlanCommand(app);
  tessera::app::addConvertCommand(app);
  tessera::app::addViewCommand(app);
  tessera::app::addSliceCommand(app);
  tessera::app::addProbeCommand(app);
  tessera::app::addFormatsCommand(app);
  tessera::app::addDicomWebCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, like every other error (scripts grep stderr).
    std::fprintf(stderr, "tessera: error: %s (see tessera --help)\n", e.what());
    return e.get_exit_code();
  } catch (const tessera::app::IncompleteOutput& e) {
    std::fprintf(stderr, "tessera: incomplete: %s\n", e.what());
    return tessera::app::kExitIncomplete;
  } catch (const tessera::Error& e) {
    std::fprintf(stderr, "tessera: error: %s\n", e.what());
    return tessera::app::kExitError;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tessera: internal error: %s\n", e.what());
    return tessera::app::kExitInternal;
  }
  return 0;
}
