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

}  // namespace tessera::app
