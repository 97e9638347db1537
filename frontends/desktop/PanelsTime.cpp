// The time panel: a time series' time point shown (a slider), play / pause
// and the rate. The session reads ahead and decides what is shown
// (Session::stepPlayback); a time point not read yet is asked for and shown
// when read, late, never skipped. tests/desktop/PanelsTimeTest.cpp moves
// the slider and plays without a window.
#include <string>

#include "Panels.h"

namespace tessera::desktop {

bool stepTime(session::Session& s, TimeUi& ui, PanelHost& host, double nowMs) {
  if (!s.series()) {
    ui.asked.reset();
    return false;
  }
  const int before = s.timePoint();
  reportFailure(host, [&] {
    if (ui.asked && !s.playback().playing()) {
      if (s.showTimePoint(*ui.asked)) ui.asked.reset();
    } else {
      ui.asked.reset();
      s.stepPlayback(nowMs);
    }
  });
  if (s.timePoint() == before) return false;
  host.viewChanged();
  return true;
}

void panelTime(session::Session& s, TimeUi& ui, PanelHost& host, double nowMs) {
  const session::TimeSeries* series = s.series();
  if (!series || !ImGui::CollapsingHeader("Time", ImGuiTreeNodeFlags_DefaultOpen)) return;
  int t = ui.asked.value_or(s.timePoint());
  if (ImGui::SliderInt("time point", &t, 0, series->count() - 1)) {
    s.playback().pause();
    ui.asked = t;
    reportErrors(host, [&] {
      if (s.showTimePoint(t)) {
        ui.asked.reset();
        host.viewChanged();
      }
    });
  }
  session::Playback& play = s.playback();
  if (ImGui::Button(play.playing() ? "Pause" : "Play")) {
    if (play.playing()) {
      play.pause();
    } else {
      ui.asked.reset();
      play.play(nowMs);
    }
  }
  ImGui::SameLine();
  float fps = static_cast<float>(play.fps());
  ImGui::SetNextItemWidth(120.0f);
  if (ImGui::SliderFloat("per second", &fps, 1.0f, 60.0f, "%.0f")) {
    reportErrors(host, [&] { play.setFps(fps); });
  }
  ImGui::TextDisabled("%d time points, %d read ahead; %llu late frames", series->count(),
                      series->keep() - 1, static_cast<unsigned long long>(play.lateFrames()));
}

}  // namespace tessera::desktop
