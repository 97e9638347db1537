#include "tessera/lod/ZarrMultiresSource.h"

namespace tessera::lod {

ZarrMultiresSource::ZarrMultiresSource(std::shared_ptr<const ZarrStore> store)
    : store_(std::move(store)) {}

std::unique_ptr<ZarrMultiresSource> ZarrMultiresSource::open(const std::string& spec,
                                                             ZarrSelection selection) {
  return std::make_unique<ZarrMultiresSource>(
      std::make_shared<const ZarrStore>(openZarrStorage(spec), selection));
}

LevelInfo ZarrMultiresSource::levelInfo(int level) const {
  const ZarrLevel& l = store_->level(level);
  return {.dims = l.dims, .spacing = glm::vec3(l.spacing), .chunk = l.chunk};
}

Volume ZarrMultiresSource::readBox(int level, const VoxelBox& box) const {
  return store_->readBox(level, box.begin, box.end);
}

}  // namespace tessera::lod
