// An OME-Zarr store's t axis in the page (frontends/web/store-time.js drives
// it), through the session (session/TimeSeries.h): the session asks for the
// time points ahead (TimeSeries::setArrival) and the page fetches their
// chunks with the store's own fetch() storage between its frames; one that
// has not arrived when due is shown late. A store whose level 0 fits a
// quarter of the host budget plays back as a dropped 4-D NIfTI does
// (Session::openSeries), each time point read in core. A larger one, or one
// the page asks to (?layout=bricks), plays over bricks
// (Session::drawStreamedSeries): the store view draws each time point
// through a bricks layout of its own (ZarrStoreView::showTime), and the
// next ones' levels are fetched and read ahead.
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
#include "tessera/session/StreamedSeries.h"
#include "tessera/session/TimeSeries.h"

namespace tessera::web {

namespace {

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
      // Lists every read it lacks.
      return s.holdsReads(0, glm::ivec3(0), s.level(0).dims, [&](const ZarrStoredRead& read) {
        return storage_->ready(FetchStorage::keyOf(read));
      });
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

// Whether time point t's levels that are read ahead (those whose voxels
// fit the bytes fetched ahead, StreamedSeries::levelsWithin) have all
// arrived; if not, their missing keys are wanted.
bool levelsArrived(ZarrStoreView& view, int t) {
  try {
    const std::shared_ptr<const FetchedZarrSource> source = view.sourceAt(t);
    bool ready = true;
    const std::uint64_t ahead = view.storage().budgetBytes() / 2;
    for (const int level : session::StreamedSeries::levelsWithin(*source, ahead)) {
      ready = source->prefetch(level, {glm::ivec3(0), source->levelInfo(level).dims}) && ready;
    }
    return ready;
  } catch (const KeyNotFetched&) {
    return false;  // its metadata: wanted
  }
}

// The store's t axis over bricks: a series the page draws
// (Session::drawStreamedSeries) of the store view's time points, read
// ahead one at a time as their levels arrive, as many held as two fit
// what the storage keeps. The time points are asked of the page's store
// view of the moment: after a lost WebGL context it is another one, over
// the same host side (ZarrStoreView::Host: the same time points' levels),
// and the series plays on (the session keeps it, and the time point it
// showed, over the loss). closeStore ends the series first.
void openBrickedSeries(WebSession& web) {
  ZarrStoreView& view = web.theStore();
  const int count = view.store().timePoints();
  session::Session& s = web.rendering();
  s.drawStreamedSeries(
      count,
      [&web](int t) -> std::shared_ptr<const lod::MultiresSource> {
        return web.theStore().sourceAt(t);
      },
      view.storage().budgetBytes() / 2, view.storage().budgetBytes(), view.storage().describe(),
      view.timePoint(), session::TimeSeries::Reading::OnPump);
  s.series()->setArrival([&web](int t) { return levelsArrived(web.theStore(), t); }, 1);
}

}  // namespace

// 1: the store's time series is open in the session, in core (its first
// time point read); 3: open over bricks; 0: keys are wanted (the page
// fetches them and calls again); 2: not a series (one time point).
// `bricks`: over bricks even when level 0 would fit in core.
int openStoreSeries(WebSession& web, bool bricks) {
  ZarrStoreView* view = web.store();
  if (!view || !view->isOpen()) throw Error("no OME-Zarr store is open");
  const ZarrStore& store = view->store();
  const int count = store.timePoints();
  if (count < 2) return 2;
  if (bricks || store.finestLevelWithin(HostBudget::global().limitBytes() / 4) != 0) {
    openBrickedSeries(web);
    return 3;
  }
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
      view->storage().budgetBytes() / 2 / each, 1, static_cast<std::uint64_t>(s.series()->keep())));
  s.series()->setArrival([points](int t) { return points->arrived(t); }, ahead);
  return 1;
}

}  // namespace tessera::web

extern "C" {

// The open store's t axis as a time series (openStoreSeries above): 1 open
// in core, 3 open over bricks (asked for with `bricks` 1, or level 0 too
// large), 0 keys wanted (tessera_zarr_wanted), 2 not a series (one time
// point), -1 failed (tessera_last_error).
EMSCRIPTEN_KEEPALIVE int tessera_store_time_open_step(int bricks) {
  int state = -1;
  const int ok = tessera::web::guarded(
      [&] { state = tessera::web::openStoreSeries(tessera::web::session(), bricks != 0); });
  return ok ? state : -1;
}

}  // extern "C"
