#pragma once
// Option registrations that render, bench, view and the other commands share
// (Commands.h includes this; the option groups' own files include it alone).
#include <string>

#include <CLI/CLI.hpp>

namespace tessera::app {

// An option whose help shows the default (what `value` holds when it is
// registered): most options of render, bench and view are of this kind.
template <typename T>
CLI::Option* addDefaultedOption(CLI::App* cmd, const std::string& name, T& value,
                                const std::string& help) {
  return cmd->add_option(name, value, help)->capture_default_str();
}

// --size WIDTHxHEIGHT, read by parseSize; `what` says whose size it is
// ("Image" for render and bench, "Window" for view).
inline void addSizeOption(CLI::App* cmd, std::string& size, const std::string& what) {
  addDefaultedOption(cmd, "--size", size, what + " size WIDTHxHEIGHT");
}

// --state FILE and --save-state FILE: the session state a command starts
// from and writes (session::Session::state, one versioned JSON schema that
// render, view and the web page share). `starts` and `writes` finish the two
// help texts: what the command takes from the file, and when it writes one.
inline void addStateOptions(CLI::App* cmd, std::string& state, std::string& saveState,
                            const std::string& starts, const std::string& writes) {
  cmd->add_option("--state", state,
                  "Start from the session state in FILE (render --save-state, view --save-state "
                  "or the viewers' Save state): " +
                      starts)
      ->type_name("FILE");
  cmd->add_option("--save-state", saveState,
                  "Write the session's state (version, volume, settings, exploration; JSON) to "
                  "FILE " +
                      writes)
      ->type_name("FILE");
}

}  // namespace tessera::app
