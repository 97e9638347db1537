// Session::renderChannels: a multi-channel frame of an OME-Zarr store
// (docs/channels.md) through the technique the settings name (one that draws
// channels: raycast, slice3d, slice2d) over layout::ChannelLayout or the
// bricks layout (BricksLayout::createChannels), and its CPU reference.
#include <chrono>
#include <cstdio>
#include <optional>

#include "tessera/io/ZarrChannels.h"
#include "tessera/layout/ChannelLayouts.h"
#include "tessera/layout/StreamingLayout.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/lod/ReadLevel.h"
#include "tessera/lod/ZarrMultiresSource.h"
#include "tessera/reference/ChannelReference.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/session/BrickRefinement.h"
#include "tessera/session/ChannelTechnique.h"
#include "tessera/session/Session.h"

namespace tessera::session {

namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::string describe(const Channel& c) {
  char s[160];
  std::snprintf(s, sizeof s, "%s %02x%02x%02x %g:%g %s", c.label.c_str(),
                static_cast<unsigned>(c.color.r * 255.0 + 0.5),
                static_cast<unsigned>(c.color.g * 255.0 + 0.5),
                static_cast<unsigned>(c.color.b * 255.0 + 0.5), c.window.min, c.window.max,
                c.visible ? "on" : "off");
  return s;
}

// One source per channel for the bricks layout: the store's levels, read
// brick by brick, when it has a pyramid; else (one level) a pyramid of the
// channels read in `set`, so that coarser levels stand in while the finest
// streams to the device.
layout::ChannelSources channelSources(const std::string& spec, std::vector<int> indices,
                                      const ChannelSet& set, int time) {
  if (indices.empty()) {
    for (int c = 0; c < set.size(); ++c) indices.push_back(c);
  }
  return [spec, indices, time, &set] {
    std::vector<std::shared_ptr<const lod::MultiresSource>> out;
    for (int c : indices) {
      auto store = lod::ZarrMultiresSource::open(spec, {.time = time, .channel = c});
      if (store->levelCount() < 2) break;
      out.push_back(std::move(store));
    }
    if (out.size() == indices.size()) return out;
    out.clear();
    for (const Channel& c : set.channels()) {
      out.push_back(std::make_shared<lod::InCoreMultiresSource>(c.volume));
    }
    return out;
  };
}

// The levels the refined frame shows, per level-0 cell (the page table
// as drawn), each read whole from the layout's sources: level 0 is the
// set's own channels. What the reference of a frame that mixes levels reads.
ChannelLevels levelsShown(const ChannelSet& set,
                          const std::vector<std::shared_ptr<const lod::MultiresSource>>& sources,
                          const layout::StreamingLayout& bricks) {
  const lod::BrickGrid& grid = bricks.grid();
  ChannelLevels out;
  out.cells.finestDims = grid.dims(0);
  out.cells.brickSize = grid.brickSize();
  out.cells.cells = grid.bricks(0);
  out.cells.levels = bricks.cellLevels();
  const std::vector<int> shown = out.cells.cellsPerLevel();
  for (int l = 0; l < grid.levelCount(); ++l) out.scales.push_back(grid.scale(l));
  for (int c = 0; c < set.size(); ++c) {
    std::vector<std::shared_ptr<const Volume>> levels(static_cast<std::size_t>(grid.levelCount()));
    for (std::size_t l = 0; l + 1 < shown.size(); ++l) {
      if (shown[l] == 0) continue;
      levels[l] = l == 0 ? set[c].volume
                         : std::make_shared<const Volume>(lod::readLevel(
                               *sources[static_cast<std::size_t>(c)], static_cast<int>(l)));
    }
    out.volumes.push_back(std::move(levels));
  }
  return out;
}

// "L0:528 L1:1264": the cells per level a frame shows.
std::string levelsText(const std::vector<int>& cellsPerLevel) {
  std::string text;
  for (std::size_t l = 0; l + 1 < cellsPerLevel.size(); ++l) {
    if (cellsPerLevel[l] == 0) continue;
    text +=
        (text.empty() ? "L" : " L") + std::to_string(l) + ":" + std::to_string(cellsPerLevel[l]);
  }
  if (cellsPerLevel.back() > 0) text += " empty:" + std::to_string(cellsPerLevel.back());
  return text;
}

}  // namespace

ChannelFrame Session::renderChannels(const std::string& spec, int width, int height, bool reference,
                                     int time) {
  const Settings& s = settings_;
  s.validate();
  const render::TechniqueEntry& entry = channelTechnique(s.technique);
  ChannelSet set = readZarrChannels(spec, s.channels.indices, time);
  s.channels.applyTo(set, spec);
  ChannelFrame frame;
  for (const Channel& c : set.channels()) frame.channels.push_back(describe(c));
  Camera camera = s.camera;
  camera.frame(set.geometry());
  gpu::GlContext& gl = *device_.context;
  gl.makeCurrent();
  std::vector<std::shared_ptr<const lod::MultiresSource>> sources;  // opened for bricks
  const layout::ChannelSources open = channelSources(spec, s.channels.indices, set, time);
  const auto layout = layout::createChannelLayout(
      s.layout, set, [&] { return sources = open(); }, device_.limits, gl.ledger());
  frame.layout = layout->plan().reason;
  if (layout->streaming()) requireChannelBricks(entry, frame.layout);
  const auto t0 = std::chrono::steady_clock::now();
  std::optional<ChannelLevels> levels;  // a streamed frame's, read after it is drawn
  {
    render::TechniqueOptions options = s.techniqueOptions({width, height});
    options.skipBlock = 0;  // the block grid is one volume's
    const std::unique_ptr<render::Technique> technique = render::TechniqueRegistry::global().create(
        s.technique, {gl, device_.limits, set.geometry(), layout.get(), options});
    technique->setTransferFunction(s.tf);
    RenderSettings render = s.render;
    render.mode = renderModeFor(set.mode);
    layout::StreamingLayout* bricks = layout->streaming();
    if (bricks) {
      // Refined before it is drawn (one frame, not a progressive view).
      const RefineRun r = BrickRefinement(*bricks).refine(camera, width, height, s.tf, [] {},
                                                          {});  // one frame: drawn once refined
      frame.layout += "; refined in " + std::to_string(r.frames) + " frames, page cells " +
                      levelsText(r.last.cellsPerLevel) +
                      (r.last.limitedByBudget ? " (atlas full)" : "");
    }
    frame.image = technique->renderImage(camera, render, width, height);
    if (bricks && reference) {
      levels = levelsShown(set, sources, *bricks);
      frame.layout += levels->cells.mixed()
                          ? "; the reference reads each cell's level, as the frame does"
                          : "; the reference reads the level the frame shows";
    }
  }
  frame.gpuMs = msSince(t0);
  if (reference) {
    const auto t1 = std::chrono::steady_clock::now();
    frame.reference =
        levels ? renderChannelsReference(set, *levels, s.tf, camera, s.render, width, height)
               : renderChannelsReference(set, s.tf, camera, s.render, width, height);
    frame.referenceMs = msSince(t1);
    frame.psnr = psnr(frame.image, *frame.reference);
  }
  return frame;
}

}  // namespace tessera::session
