#pragma once
// What every `tessera bench --json` report states about its run.
#include <string>

#include <nlohmann/json.hpp>

namespace tessera::app {

// A report naming the volume, the frame size and the GL renderer that drew
// the frames; the benchmark adds its own fields and rows.
inline nlohmann::json benchJson(const std::string& file, int width, int height,
                                const std::string& glRenderer) {
  nlohmann::json j;
  j["file"] = file;
  j["width"] = width;
  j["height"] = height;
  j["gl_renderer"] = glRenderer;
  return j;
}

}  // namespace tessera::app
