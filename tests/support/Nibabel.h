#pragma once
// nibabel as an independent NIfTI reader and writer for geometry tests. It
// runs under Debian's /usr/bin/python3 (with python3-nibabel and numpy);
// the `python3` first on PATH may be another interpreter without them.
#include <array>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include <glm/mat4x4.hpp>
#include <nlohmann/json.hpp>

#include "support/TestSupport.h"

namespace tessera::test {

inline constexpr const char* kNibabelPython = "/usr/bin/python3";

// Why nibabel cannot be used here, or nothing when it can.
inline std::optional<std::string> nibabelMissing() {
  static const std::optional<std::string> why = []() -> std::optional<std::string> {
    const std::string cmd =
        std::string(kNibabelPython) + " -c 'import nibabel, numpy' >/dev/null 2>&1";
    if (std::system(cmd.c_str()) == 0) return std::nullopt;
    return std::string(kNibabelPython) + " cannot import nibabel and numpy (python3-nibabel)";
  }();
  return why;
}

// Runs `script` (Python source) with `args` and returns what it prints on
// stdout; throws with its stderr when it fails.
inline std::string runPython(const TempDir& dir, const std::string& script,
                             const std::string& args = "") {
  const auto scriptPath = dir / "script.py";
  const auto errPath = dir / "script.err";
  std::ofstream(scriptPath) << script;
  const std::string cmd = std::string(kNibabelPython) + " " + scriptPath.string() + " " + args +
                          " 2>" + errPath.string();
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) throw std::runtime_error("cannot run " + cmd);
  std::string out;
  std::array<char, 4096> buf{};
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  if (pclose(p) != 0) {
    std::ostringstream err;
    err << std::ifstream(errPath).rdbuf();
    throw std::runtime_error("python failed: " + err.str());
  }
  return out;
}

// A 4x4 affine printed as nested rows (numpy's tolist()) -> glm (m[col][row]).
inline glm::dmat4 affineFromRows(const nlohmann::json& rows) {
  glm::dmat4 m(1.0);
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m[c][r] = rows.at(r).at(c).get<double>();
  }
  return m;
}

}  // namespace tessera::test
