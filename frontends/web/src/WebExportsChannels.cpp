// The C API of the page's channel list (frontends/web/channels-panel.js):
// an open OME-Zarr store with several channels is read through the store's
// own fetch() storage (the page fetches the keys a step wants, as for the
// store's bricks; a store with a t axis plays its channels together, the
// time points ahead fetched between frames) into session::ChannelView, whose calls the list's
// toggles, colours and windows marshal to; its frame goes on the canvas.
#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "WebExports.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/Draw.h"
#include "tessera/io/ZarrChannels.h"

using namespace tessera;
using web::guarded;

namespace {

session::ChannelView& channelView() {
  return web::session().rendering().channelView();
}

// The channels' keys all held: readZarrChannels reads without waiting.
bool channelKeysReady(const std::shared_ptr<const ZarrStorage>& storage,
                      const web::FetchStorage& fetch, const std::string& name,
                      const std::vector<int>& indices, int time) {
  // Lists every read still to fetch.
  return holdsZarrChannelReads(storage, name, indices, time, [&](const ZarrStoredRead& read) {
    return fetch.ready(web::FetchStorage::keyOf(read));
  });
}

// A store with a t axis: its channels play together (ChannelView::showSeries),
// each time point's set read once all its keys have arrived, the page
// fetching one time point ahead at a time between its frames. The storage
// is kept alive by the store's source (the lambdas hold it).
void showChannelSeries(web::ZarrStoreView& z, ChannelSet first, const std::string& name,
                       const std::vector<int>& indices, int time) {
  const std::shared_ptr<const web::FetchStorage> fetch(z.sharedSource(), &z.storage());
  const std::uint64_t each = std::max<std::uint64_t>(1, session::ChannelSeries::bytes(first));
  const int ahead = static_cast<int>(std::clamp<std::uint64_t>(
      web::kStoreFetchAheadBytes / each, 1, static_cast<std::uint64_t>(z.store().timePoints())));
  channelView().showSeries(
      z.store().timePoints(), std::move(first),
      [fetch, name, indices](int t) { return readZarrChannels(fetch, name, indices, t); }, name,
      time, session::TimeSeries::Reading::OnPump,
      [fetch, name, indices](int t) {
        try {
          return channelKeysReady(fetch, *fetch, name, indices, t);
        } catch (const web::KeyNotFetched&) {
          return false;  // metadata the storage let go of: wanted again
        }
      },
      ahead);
}

nlohmann::json channelJson(const Channel& c) {
  const ValueRange values = c.volume->valueRange();
  return {{"label", c.label},
          {"color", {c.color.r, c.color.g, c.color.b}},
          {"window", {c.window.min, c.window.max}},
          {"range", {values.min, values.max}},
          {"visible", c.visible}};
}

}  // namespace

extern "C" {

// One step of reading the open store's channels: 1 shown, 0 keys wanted
// (tessera_zarr_wanted lists them), 2 the store has one channel (no list),
// -1 failed (tessera_last_error).
EMSCRIPTEN_KEEPALIVE int tessera_channels_open_step() {
  int state = -1;
  guarded([&] {
    web::ZarrStoreView& z = web::session().theStore();
    if (z.store().channelCount() < 2) {
      state = 2;
      return;
    }
    // The store view owns the storage and outlives this call.
    const std::shared_ptr<const ZarrStorage> storage(std::shared_ptr<void>(), &z.storage());
    const std::string name = z.storage().describe();
    const int time = z.store().selection().time;
    const std::vector<int> indices = web::session().rendering().settings().channels.indices;
    try {
      if (!channelKeysReady(storage, z.storage(), name, indices, time)) {
        state = 0;
        return;
      }
    } catch (const web::KeyNotFetched&) {
      state = 0;  // metadata the storage let go of: wanted again
      return;
    }
    ChannelSet first = readZarrChannels(storage, name, indices, time);
    if (z.store().timePoints() > 1) {
      showChannelSeries(z, std::move(first), name, indices, time);
    } else {
      channelView().show(std::move(first), name);
    }
    state = 1;
  });
  return state;
}

// The channels shown: {"open", "name", "mode", "channels": [{"label",
// "color" [r, g, b] in 0..1, "window" [lo, hi], "range" [min, max],
// "visible"}]}.
EMSCRIPTEN_KEEPALIVE const char* tessera_channels_json() {
  nlohmann::json j = {{"open", false}};
  web::WebSession* s = web::sessionIfAny();
  if (s && s->rendering().hasChannelView() && s->rendering().channelView().isOpen()) {
    const session::ChannelView& v = s->rendering().channelView();
    j = {{"open", true},
         {"name", v.name()},
         {"mode", channelModeName(v.channels().mode)},
         {"channels", nlohmann::json::array()}};
    for (const Channel& c : v.channels().channels()) j["channels"].push_back(channelJson(c));
  }
  return web::jsonOut(j);
}

EMSCRIPTEN_KEEPALIVE int tessera_channels_set_visible(int i, int visible) {
  return guarded([&] { channelView().setVisible(i, visible != 0); });
}
EMSCRIPTEN_KEEPALIVE int tessera_channels_set_color(int i, double r, double g, double b) {
  return guarded([&] { channelView().setColor(i, {r, g, b}); });
}
EMSCRIPTEN_KEEPALIVE int tessera_channels_set_window(int i, double lo, double hi) {
  return guarded([&] { channelView().setWindow(i, {lo, hi}); });
}
// "additive" or "max".
EMSCRIPTEN_KEEPALIVE int tessera_channels_set_mode(const char* mode) {
  return guarded([&] { channelView().setMode(parseChannelMode(mode)); });
}
// Back to the store's first channel alone.
EMSCRIPTEN_KEEPALIVE void tessera_channels_close() {
  if (web::WebSession* s = web::sessionIfAny()) {
    if (s->rendering().hasChannelView()) s->rendering().channelView().close();
  }
}

// The channels' frame of width x height on the canvas (the viewer's camera,
// transfer function and settings); 1, or 0 on error (tessera_last_error).
EMSCRIPTEN_KEEPALIVE int tessera_channels_frame(int width, int height) {
  return guarded([&] {
    session::ChannelView& v = channelView();
    v.render(width, height);
    v.present(0, {0, 0, width, height});
    std::uint8_t pixel[4];
    gpu::readPixelsRgba8({0, 0, 1, 1}, pixel);  // waits for the frame (glFinish does not)
    gpu::checkErrors("channel frame");
  });
}

}  // extern "C"
