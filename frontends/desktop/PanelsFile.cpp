// The file panel: a path to open, the recent volumes (Ctrl+1..9 in
// Input.cpp), files dropped on the window, and the panel's error line.
#include <filesystem>
#include <string>

#include "DesktopApp.h"
#include "tessera/lod/ProceduralMultiresSource.h"

namespace tessera::desktop {

namespace {

bool generated(const std::string& spec) {
  return spec.rfind("gen:", 0) == 0 || lod::ProceduralMultiresSource::isSpec(spec);
}

// Files and folders (not generated volumes) go to the recent list, by their
// absolute path; one that cannot be opened because it is gone leaves it.
void rememberOpened(DesktopApp& ds, const std::string& spec) {
  if (generated(spec)) return;
  reportErrors(ds, [&] {
    std::error_code ec;
    const std::filesystem::path full = std::filesystem::absolute(spec, ec);
    ds.recent.add(ec ? spec : full.lexically_normal().string());
  });
}

void forgetIfGone(DesktopApp& ds, const std::string& spec) {
  std::error_code ec;
  if (std::filesystem::exists(spec, ec)) return;
  try {
    ds.recent.remove(spec);
  } catch (const Error&) {
    // The list could not be rewritten: the open error already says more.
  }
}

}  // namespace

// Shows the volume's overview (Exploring.cpp), and a store's channels
// together when it has several and `channels` asks for them; an error is
// shown in the panel and the previous volume stays.
void openVolume(DesktopApp& ds, const std::string& spec, bool channels) {
  try {
    loadVolume(ds, spec);
    ds.error.clear();
  } catch (const Error& e) {
    ds.error = std::string(e.what()) + " (the previous volume stays)";
    forgetIfGone(ds, spec);
    return;
  }
  rememberOpened(ds, spec);
  if (channels) openChannels(ds, spec);
}

void DesktopApp::openFile(const std::string& path) {
  openVolume(*this, path);
}

void openChannels(DesktopApp& ds, const std::string& spec) {
  // A series over bricks streams its channels together (the session's
  // streamed frames draw them); otherwise the list reads them in core.
  // --time chooses within the file given on the command line.
  const int time = spec == ds.options.file ? ds.options.time : 0;
  reportErrors(ds, [&] { ds.session->channelView().open(spec, time); });
}

void loadState(DesktopApp& ds, const std::string& path) {
  ds.session->loadState(path);
  ds.showCropBox = ds.view().settings().clipping.cropped();
  for (auto& tile : ds.slices) tile.key.clear();
  updateOverlay(ds);
}

void panelFile(DesktopApp& ds) {
  ImGui::TextWrapped("%s", ds.view().description().c_str());
  ImGui::InputText("##path", ds.pathBuf, sizeof ds.pathBuf);
  ImGui::SameLine();
  if (ImGui::Button("Open") && ds.pathBuf[0]) openVolume(ds, ds.pathBuf);
  ImGui::TextDisabled("or drop a file on the window; F1: keyboard shortcuts");
  if (!ds.recent.entries().empty() && ImGui::BeginCombo("recent", "open a recent volume")) {
    std::string chosen;
    for (std::size_t i = 0; i < ds.recent.entries().size(); ++i) {
      const std::string& path = ds.recent.entries()[i];
      const std::string label = std::to_string(i + 1) + "  " +
                                std::filesystem::path(path).filename().string() + "##" + path;
      if (ImGui::Selectable(label.c_str())) chosen = path;
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", path.c_str());
    }
    ImGui::EndCombo();
    if (!chosen.empty()) openVolume(ds, chosen);
  }
  // The session's state: camera, look, crosshair, region and grid.
  ImGui::InputText("##state", ds.statePathBuf, sizeof ds.statePathBuf);
  ImGui::SameLine();
  if (ImGui::Button("Save state")) {
    reportErrors(ds, [&] { ds.session->saveState(ds.statePathBuf); });
  }
  ImGui::SameLine();
  if (ImGui::Button("Load")) reportErrors(ds, [&] { loadState(ds, ds.statePathBuf); });
  if (!ds.error.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.45f, 0.4f, 1.0f));
    ImGui::TextWrapped("%s", ds.error.c_str());
    ImGui::PopStyleColor();
  }
}

// A time series: the time point shown (a slider), play / pause and the
// rate. The session reads ahead and decides what is shown (Session::
// stepPlayback); a time point not read yet is asked for and shown when read.
void panelTime(DesktopApp& ds) {
  session::Session& s = *ds.session;
  const session::TimeSeries* series = s.series();
  if (!series || !ImGui::CollapsingHeader("Time", ImGuiTreeNodeFlags_DefaultOpen)) return;
  int t = s.timePoint();
  if (ImGui::SliderInt("time point", &t, 0, series->count() - 1)) {
    s.playback().pause();
    reportErrors(ds, [&] { s.showTimePoint(t); });
  }
  session::Playback& play = s.playback();
  if (ImGui::Button(play.playing() ? "Pause" : "Play")) {
    if (play.playing()) {
      play.pause();
    } else {
      play.play(steadyNowMs());
    }
  }
  ImGui::SameLine();
  float fps = static_cast<float>(play.fps());
  ImGui::SetNextItemWidth(120.0f);
  if (ImGui::SliderFloat("per second", &fps, 1.0f, 60.0f, "%.0f")) play.setFps(fps);
  ImGui::TextDisabled("%d time points, %d read ahead; %llu late frames", series->count(),
                      series->keep() - 1, static_cast<unsigned long long>(play.lateFrames()));
}

}  // namespace tessera::desktop
