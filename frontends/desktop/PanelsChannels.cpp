// The channel list (docs/channels.md): a store with several channels is
// shown as session::ChannelView draws it, and the panel turns each
// channel's visibility toggle, colour picker and window into that view's
// calls. The window shows the view's frame in the 3D view
// (VolumeView.cpp, drawChannelView); tests/desktop/PanelsChannelsTest.cpp clicks
// these widgets without one.
#include <algorithm>

#include "Panels.h"
#include "tessera/session/ChannelView.h"

namespace tessera::desktop {

namespace {

void channelRow(session::ChannelView& view, PanelHost& host, int i) {
  const Channel& c = view.channels()[i];
  ImGui::PushID(i);
  bool on = c.visible;
  if (ImGui::Checkbox("##visible", &on)) reportErrors(host, [&] { view.setVisible(i, on); });
  ImGui::SameLine();
  float rgb[3] = {static_cast<float>(c.color.r), static_cast<float>(c.color.g),
                  static_cast<float>(c.color.b)};
  if (ImGui::ColorEdit3("##colour", rgb, ImGuiColorEditFlags_NoInputs)) {
    reportErrors(host, [&] { view.setColor(i, glm::dvec3(rgb[0], rgb[1], rgb[2])); });
  }
  ImGui::SameLine();
  ImGui::TextUnformatted(c.label.c_str());
  // The window over the channel's values (stored units), lo < hi kept.
  const ValueRange values = c.volume->valueRange();
  float lo = static_cast<float>(c.window.min), hi = static_cast<float>(c.window.max);
  const float speed = static_cast<float>(std::max(1e-6, (values.max - values.min) / 500.0));
  if (ImGui::DragFloatRange2("window", &lo, &hi, speed, static_cast<float>(values.min),
                             static_cast<float>(values.max), "%.0f", "%.0f",
                             ImGuiSliderFlags_AlwaysClamp) &&
      hi > lo) {
    reportErrors(host, [&] { view.setWindow(i, {lo, hi}); });
  }
  ImGui::PopID();
}

}  // namespace

void panelChannels(session::ChannelView& view, PanelHost& host) {
  section("Channels");
  for (int i = 0; i < view.channels().size(); ++i) channelRow(view, host, i);
  int mode = view.channels().mode == ChannelMode::Max ? 1 : 0;
  if (ImGui::Combo("mode", &mode, "additive\0max\0")) {
    reportErrors(host, [&] { view.setMode(mode == 1 ? ChannelMode::Max : ChannelMode::Additive); });
  }
  if (ImGui::Button("Show one channel")) reportErrors(host, [&] { view.close(); });
}

}  // namespace tessera::desktop
