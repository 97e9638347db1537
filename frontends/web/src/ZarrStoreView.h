#pragma once
// An OME-Zarr store read over fetch() (ZarrFetchStorage.h) and rendered in
// the page through the bricks layout, coarse to fine: the same
// lod::LevelSelection and lod::BrickStreamer as `tessera render STORE`
// (layout/BricksLayout.h), whose reads never wait: a brick whose chunks
// have not arrived is skipped (MultiresSource::prefetch) and its chunks
// are listed for the page to fetch. The viewer core's camera, transfer
// function and render settings drive it, so the page's controls work on it.
#include <memory>
#include <string>
#include <vector>

#include "ZarrFetchStorage.h"
#include "tessera/core/Camera.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/io/ZarrStore.h"
#include "tessera/layout/StreamingLayout.h"
#include "tessera/lod/ZarrMultiresSource.h"
#include "tessera/render/HybridCompositor.h"
#include "tessera/render/Overlay.h"
#include "tessera/render/TechniqueRegistry.h"

namespace tessera::web {

// A store's levels read through a FetchStorage: prefetch() lists the
// chunks a box needs that have not arrived.
class FetchedZarrSource final : public lod::MultiresSource {
 public:
  FetchedZarrSource(std::shared_ptr<const ZarrStore> store,
                    std::shared_ptr<const FetchStorage> storage);
  const Volume& shape() const override { return zarr_.shape(); }
  int levelCount() const override { return zarr_.levelCount(); }
  lod::LevelInfo levelInfo(int level) const override { return zarr_.levelInfo(level); }
  Volume readBox(int level, const lod::VoxelBox& box) const override {
    return zarr_.readBox(level, box);
  }
  bool prefetch(int level, const lod::VoxelBox& box) const override;
  // Whether every chunk of the box has arrived, asking for none.
  bool resident(int level, const lod::VoxelBox& box) const;
  std::string describe() const override { return zarr_.describe(); }

 private:
  lod::ZarrMultiresSource zarr_;
  std::shared_ptr<const ZarrStore> store_;
  std::shared_ptr<const FetchStorage> storage_;
};

struct StoreFrame {
  layout::BricksFrame bricks;
  double ms = 0.0;
  int renderWidth = 0, renderHeight = 0;
};

class ZarrStoreView {
 public:
  ZarrStoreView(gpu::GlContext& context, const gpu::DeviceLimits& limits, const std::string& url);

  FetchStorage& storage() { return *storage_; }
  // One step of opening: the metadata, then the coarsest level (pinned in
  // the atlas). False while keys are wanted (storage().takeWanted(): the
  // page fetches them and calls again); throws the store's errors.
  bool open();
  bool isOpen() const { return active_.technique != nullptr; }
  const ZarrStore& store() const { return *store_; }
  const layout::StreamingLayout& bricks() const { return *bricks_; }
  // The store's levels; readBox of a box whose chunks have arrived
  // (prefetch true) reads without the network.
  const FetchedZarrSource& source() const { return *source_; }
  std::shared_ptr<const FetchedZarrSource> sharedSource() const { return source_; }
  // The coarsest level, read once at open (for the page's histogram).
  const Volume& coarsest() const { return coarsest_; }

  // Selects levels for the view, uploads the bricks that arrived, requests
  // the missing ones (storage().takeWanted()), and draws into the canvas
  // (width x height), the volume at most maxVolumePixels (0: all) and
  // upscaled with the overlay lines as the viewer core draws them.
  // `marks`: more lines (level-0 model frame), composed by depth like the box.
  StoreFrame frame(const Camera& viewerCamera, const RenderSettings& settings,
                   const TransferFunction& tf, std::uint64_t tfRevision, bool box, bool axes,
                   int width, int height, int maxVolumePixels,
                   const std::vector<render::OverlayLine>& marks = {});

 private:
  gpu::GlContext& context_;
  gpu::DeviceLimits limits_;
  std::shared_ptr<FetchStorage> storage_;
  std::shared_ptr<const ZarrStore> store_;
  std::shared_ptr<const FetchedZarrSource> source_;
  Volume coarsest_;
  render::TechniqueOnVolume active_;
  layout::StreamingLayout* bricks_ = nullptr;
  std::unique_ptr<render::HybridCompositor> compositor_;
  std::uint64_t tfRevision_ = 0;
};

}  // namespace tessera::web
