// An OME-Zarr store's t axis in the page (frontends/web/store-time.js drives
// it). A store whose level 0 fits a quarter of the host budget plays back as
// a dropped 4-D NIfTI does, through the session (Session::openSeries,
// session/TimeSeries.h): each time point is read in core from the keys the
// page fetched with the store's own fetch() storage, the session asks for
// the time points ahead (TimeSeries::setArrival) and the page fetches their
// chunks between its frames; one that has not arrived when due is shown
// late. A store too large for that streams bricks at its first time point
// (ZarrStoreView), as `tessera view` explores such a store.
#include <emscripten/emscripten.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "WebExports.h"
#include "WebSession.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/session/TimeSeries.h"

namespace tessera::web {

namespace {

// The stored bytes the page fetches ahead at once: half of what the
// store's fetch() storage keeps (ZarrStoreView.cpp's kFetchedBytes), so a
// time point's chunks are not let go before it is read.
constexpr std::uint64_t kFetchAheadBytes = 24ull << 20;

// The store's time points, each a ZarrStore of one selection over the same
// fetched keys, made when first asked for (its metadata may have to be
// fetched again: the storage keeps keys least recently used first out).
class StoreTimePoints {
 public:
  StoreTimePoints(std::shared_ptr<const FetchStorage> storage, int channel)
      : storage_(std::move(storage)), channel_(channel) {}

  // Whether every level-0 chunk of time point t has arrived; if not, the
  // missing keys are wanted (tessera_zarr_wanted lists them for the page).
  bool arrived(int t) {
    try {
      const ZarrStore& s = at(t);
      bool ready = true;
      for (const std::string& key : s.chunkKeys(0, glm::ivec3(0), s.level(0).dims)) {
        ready = storage_->ready(key) && ready;  // lists every key it lacks
      }
      return ready;
    } catch (const KeyNotFetched&) {
      return false;
    }
  }

  // Level 0 of time point t, its chunks arrived (arrived(t)).
  Volume read(int t) {
    Volume v = at(t).readLevel(0);
    v.setDescription(at(t).describe() + ", time point " + std::to_string(t));
    return v;
  }

  // The bytes a time point's chunks hold once decoded.
  std::uint64_t bytesPerTimePoint(int t) {
    const ZarrStore& s = at(t);
    return s.chunkKeys(0, glm::ivec3(0), s.level(0).dims).size() * s.level(0).array.chunkBytes();
  }

 private:
  const ZarrStore& at(int t) {
    auto it = stores_.find(t);
    if (it == stores_.end()) {
      it = stores_.emplace(t, std::make_unique<ZarrStore>(storage_, ZarrSelection{t, channel_}))
               .first;
    }
    return *it->second;
  }

  std::shared_ptr<const FetchStorage> storage_;
  int channel_;
  std::map<int, std::unique_ptr<ZarrStore>> stores_;
};

}  // namespace

// 1: the store's time series is open in the session (its first time point
// read); 0: keys are wanted (the page fetches them and calls again); 2: not
// a series the page plays (one time point, or level 0 beyond a quarter of
// the host budget: the store streams bricks at its first time point).
int openStoreSeries(WebSession& web) {
  ZarrStoreView* view = web.store();
  if (!view || !view->isOpen()) throw Error("no OME-Zarr store is open");
  const ZarrStore& store = view->store();
  const int count = store.timePoints();
  if (count < 2 || store.finestLevelWithin(HostBudget::global().limitBytes() / 4) != 0) return 2;
  // The view's storage, kept alive by its source as long as the series is.
  const std::shared_ptr<const FetchStorage> storage(view->sharedSource(), &view->storage());
  auto points = std::make_shared<StoreTimePoints>(storage, store.selection().channel);
  const int first = store.selection().time;
  if (!points->arrived(first)) return 0;
  session::Session& s = web.rendering();
  s.openSeries(
      count, [points](int t) { return points->read(t); }, storage->describe(), first,
      session::TimeSeries::Reading::OnPump);
  const std::uint64_t each = std::max<std::uint64_t>(1, points->bytesPerTimePoint(first));
  const int ahead = static_cast<int>(std::clamp<std::uint64_t>(
      kFetchAheadBytes / each, 1, static_cast<std::uint64_t>(s.series()->keep())));
  s.series()->setArrival([points](int t) { return points->arrived(t); }, ahead);
  return 1;
}

}  // namespace tessera::web

extern "C" {

// The open store's t axis as a time series (openStoreSeries above): 1 open,
// 0 keys wanted (tessera_zarr_wanted), 2 not played (one time point, or
// streamed), -1 failed (tessera_last_error).
EMSCRIPTEN_KEEPALIVE int tessera_store_time_open_step() {
  int state = -1;
  const int ok = tessera::web::guarded(
      [&] { state = tessera::web::openStoreSeries(tessera::web::session()); });
  return ok ? state : -1;
}

}  // extern "C"
