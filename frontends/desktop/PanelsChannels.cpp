// The channel list (docs/channels.md): a store with several channels is
// shown as session::ChannelView draws it, and the panel turns each
// channel's visibility toggle, colour picker and window into that view's
// calls; the 3D view shows its frame in place of the viewer's.
#include <algorithm>
#include <cstdint>
#include <cstdio>

#include "DesktopApp.h"

namespace tessera::desktop {

namespace {

bool channelsShown(const DesktopApp& ds) {
  return ds.session && ds.session->hasChannelView() && ds.session->channelView().isOpen();
}

void channelRow(DesktopApp& ds, session::ChannelView& view, int i) {
  const Channel& c = view.channels()[i];
  ImGui::PushID(i);
  bool on = c.visible;
  if (ImGui::Checkbox("##visible", &on)) reportErrors(ds, [&] { view.setVisible(i, on); });
  ImGui::SameLine();
  float rgb[3] = {static_cast<float>(c.color.r), static_cast<float>(c.color.g),
                  static_cast<float>(c.color.b)};
  if (ImGui::ColorEdit3("##colour", rgb, ImGuiColorEditFlags_NoInputs)) {
    reportErrors(ds, [&] { view.setColor(i, glm::dvec3(rgb[0], rgb[1], rgb[2])); });
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
    reportErrors(ds, [&] { view.setWindow(i, {lo, hi}); });
  }
  ImGui::PopID();
}

}  // namespace

void openChannels(DesktopApp& ds, const std::string& spec) {
  // A series over bricks plays the one channel it was opened at (--channel):
  // the list reads every channel of each time point in core.
  if (ds.session->streamedSeries()) return;
  // --time chooses within the file given on the command line.
  const int time = spec == ds.options.file ? ds.options.time : 0;
  reportErrors(ds, [&] { ds.session->channelView().open(spec, time); });
}

void panelChannels(DesktopApp& ds) {
  if (!channelsShown(ds)) return;
  session::ChannelView& view = ds.session->channelView();
  section("Channels");
  for (int i = 0; i < view.channels().size(); ++i) channelRow(ds, view, i);
  int mode = view.channels().mode == ChannelMode::Max ? 1 : 0;
  if (ImGui::Combo("mode", &mode, "additive\0max\0")) {
    reportErrors(ds, [&] { view.setMode(mode == 1 ? ChannelMode::Max : ChannelMode::Additive); });
  }
  if (ImGui::Button("Show one channel")) reportErrors(ds, [&] { view.close(); });
}

bool drawChannelView(DesktopApp& ds, const Rect& rect, int viewW, int viewH) {
  if (!channelsShown(ds)) return false;
  try {
    const gpu::Texture& frame = ds.session->channelView().render(viewW, viewH);
    // Row 0 of the frame is its bottom row: ImGui's v runs down.
    ImGui::GetBackgroundDrawList()->AddImage(
        reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(frame.id())), rect.p0, rect.p1,
        ImVec2(0.0f, 1.0f), ImVec2(1.0f, 0.0f));
  } catch (const Error& e) {
    ds.error = e.what();
    return false;
  }
  char line[160];
  std::snprintf(line, sizeof line, "%d channels of %s (%s)",
                ds.session->channelView().channels().size(),
                ds.session->channelView().name().c_str(), ds.context().caps().renderer.c_str());
  ds.status = line;
  return true;
}

}  // namespace tessera::desktop
