// The overlay in the session's state (Session::state / restore) and the
// probe as JSON (tessera probe --json, the viewers' readouts).
#include <cmath>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"
#include "tessera/session/Fusion.h"
#include "tessera/session/Session.h"

namespace tessera::session {

namespace {

nlohmann::json orNull(const std::string& s) {
  if (s.empty()) return nullptr;
  return s;
}

std::string stringAt(const nlohmann::json& j, const char* key) {
  if (!j.contains(key) || j[key].is_null()) return {};
  if (!j[key].is_string()) {
    throw InputError(std::string("session state: overlay.") + key + ": expected a string, got " +
                     j[key].dump());
  }
  return j[key].get<std::string>();
}

}  // namespace

nlohmann::json overlayState(const Overlay* overlay) {
  if (!overlay || !overlay->fused) return nullptr;
  const OverlayOptions& o = overlay->options;
  nlohmann::json window = nullptr;
  if (o.window) window = {o.window->min, o.window->max};
  return {{"file", overlay->name},
          {"labels", o.labels},
          {"label_table", orNull(o.labelTable)},
          {"label_table_name", orNull(o.labelTableName)},
          {"tf", o.tf},
          {"alpha", o.opacity},
          {"window", window}};
}

OverlayOptions overlayOptionsFromState(const nlohmann::json& state, std::string& file) {
  if (!state.is_object()) {
    throw InputError("session state: overlay: expected an object or null, got " + state.dump());
  }
  file = stringAt(state, "file");
  if (file.empty()) throw InputError("session state: overlay.file: missing");
  OverlayOptions o;
  if (state.contains("labels")) {
    if (!state["labels"].is_boolean()) {
      throw InputError("session state: overlay.labels: expected true or false, got " +
                       state["labels"].dump());
    }
    o.labels = state["labels"].get<bool>();
  }
  o.labelTable = stringAt(state, "label_table");
  o.labelTableName = stringAt(state, "label_table_name");
  const std::string tf = stringAt(state, "tf");
  if (!tf.empty()) o.tf = tf;
  if (state.contains("alpha")) {
    if (!state["alpha"].is_number()) {
      throw InputError("session state: overlay.alpha: expected a number, got " +
                       state["alpha"].dump());
    }
    o.opacity = state["alpha"].get<double>();
  }
  if (state.contains("window") && !state["window"].is_null()) {
    const nlohmann::json& w = state["window"];
    if (!w.is_array() || w.size() != 2 || !w[0].is_number() || !w[1].is_number()) {
      throw InputError("session state: overlay.window: expected [lo, hi] or null, got " + w.dump());
    }
    o.window = ValueRange{w[0].get<double>(), w[1].get<double>()};
  }
  return o;
}

void Session::restoreOverlay(const nlohmann::json& state) {
  // None saved (or a state from before overlays): what is open stays, so
  // that an overlay given with the state (tessera view --overlay F --state
  // S) is kept.
  if (!state.contains("overlay") || state["overlay"].is_null()) return;
  const nlohmann::json& saved = state["overlay"];
  std::string file;
  const OverlayOptions options = overlayOptionsFromState(saved, file);
  try {
    if (overlay_ && overlay_->name == file) {
      restyleOpenOverlay(options);
    } else {
      openOverlay(file, options);
    }
  } catch (const InputError& e) {
    throw InputError("session state: overlay " + file + ": " + e.what());
  }
}

nlohmann::json probeJson(const ProbeResult& r) {
  nlohmann::json j = {{"world_mm", {r.worldMm.x, r.worldMm.y, r.worldMm.z}},
                      {"anatomy",
                       {{"index", {r.anatomyIndex.x, r.anatomyIndex.y, r.anatomyIndex.z}},
                        {"inside", r.inAnatomy},
                        {"value", r.inAnatomy ? nlohmann::json(r.anatomyValue) : nullptr}}}};
  if (r.hasOverlay) {
    j["overlay"] = {{"index", {r.overlayIndex.x, r.overlayIndex.y, r.overlayIndex.z}},
                    {"inside", r.inOverlay},
                    {"value", r.inOverlay ? nlohmann::json(r.overlayValue) : nullptr}};
    if (r.label >= 0) {
      j["overlay"]["label"] = r.label;
      j["overlay"]["label_name"] = r.labelName;
    }
    j["overlay_text"] = probeOverlayText(r);
  }
  return j;
}

}  // namespace tessera::session
