#include "tessera/lod/ZarrMultiresSource.h"

#include <algorithm>

#include "tessera/core/HostBudget.h"
#include "tessera/io/ZarrCachedStorage.h"

namespace tessera::lod {

ZarrMultiresSource::ZarrMultiresSource(std::shared_ptr<const ZarrStore> store)
    : store_(std::move(store)), wanted_(store_->chunkCacheBytes()) {}

std::uint64_t ZarrMultiresSource::decodedChunkBudget(const ZarrStore& store,
                                                     std::uint64_t hostBudget) {
  return std::min(store.allChunkBytes(), hostBudget / kDecodedChunkShare);
}

#ifndef __EMSCRIPTEN__
std::unique_ptr<ZarrMultiresSource> ZarrMultiresSource::open(const std::string& spec,
                                                             ZarrSelection selection) {
  // Bricks read with an apron touch their neighbours' chunks: keep the
  // stored bytes of the last few MiB of chunks (inside the bricks layout's
  // fixed overhead; compressed, so many chunks), for a chunk the decoded
  // cache let go and a server would be asked for again. The decoded chunks
  // are what the bricks layout then limits to its share of the host budget.
  constexpr std::uint64_t kChunkCacheBytes = 8ull << 20;
  auto storage = std::make_shared<const CachedStorage>(openZarrStorage(spec), kChunkCacheBytes);
  auto store = std::make_shared<ZarrStore>(std::move(storage), selection);
  store->keepDecodedChunks(decodedChunkBudget(*store, HostBudget::global().limitBytes()));
  return std::make_unique<ZarrMultiresSource>(std::move(store));
}
#endif

std::shared_ptr<ZarrMultiresSource> ZarrMultiresSource::atTime(int time) const {
  ZarrSelection selection = store_->selection();
  selection.time = time;
  auto store = std::make_shared<ZarrStore>(store_->sharedStorage(), selection);
  if (wanted_ > 0) store->keepDecodedChunks(wanted_);
  return std::make_shared<ZarrMultiresSource>(std::move(store));
}

LevelInfo ZarrMultiresSource::levelInfo(int level) const {
  const ZarrLevel& l = store_->level(level);
  return {.dims = l.dims, .spacing = glm::vec3(l.spacing), .chunk = l.chunk};
}

Volume ZarrMultiresSource::readBox(int level, const VoxelBox& box) const {
  return store_->readBox(level, box.begin, box.end);
}

}  // namespace tessera::lod
