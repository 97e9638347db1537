#pragma once
// What the C API's exports (WebExports*.cpp) share: every call that can fail
// returns 0 (or -1, or "") and leaves the message in tessera_last_error();
// strings go out through one buffer valid until the next call that returns
// one. These buffers are the C API's, not the session's: the error of a
// failed tessera_init must outlive the session it could not make.
#include <emscripten/emscripten.h>

#include <exception>
#include <string>

#include <nlohmann/json.hpp>

#include "WebSession.h"

namespace tessera::web {

std::string& lastError();
std::string& scratch();

// Runs f; on an exception keeps its message and returns 0.
template <class F>
int guarded(F&& f) {
  try {
    f();
    lastError().clear();
    return 1;
  } catch (const std::exception& e) {
    lastError() = e.what();
    return 0;
  }
}

// The session's viewer, or null before tessera_init (the exports that
// cannot fail then do nothing).
inline viewer::Viewer* viewerIfAny() {
  WebSession* s = sessionIfAny();
  return s ? &s->viewer() : nullptr;
}

// `j` as the call's JSON string.
inline const char* jsonOut(const nlohmann::json& j) {
  scratch() = j.dump();
  return scratch().c_str();
}

inline nlohmann::json boxJson(const lod::VoxelBox& b) {
  return {{"begin", {b.begin.x, b.begin.y, b.begin.z}}, {"end", {b.end.x, b.end.y, b.end.z}}};
}

}  // namespace tessera::web
