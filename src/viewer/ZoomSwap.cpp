#include "tessera/viewer/ZoomSwap.h"

#include <algorithm>
#include <string>

#include <glm/geometric.hpp>

#include "tessera/core/Error.h"
#include "tessera/gpu/Draw.h"
#include "tessera/gpu/TexelFormat.h"
#include "tessera/lod/LevelScale.h"

namespace tessera::viewer {

std::vector<lod::ZoomStage> zoomStagesFor(const Explorer& explorer, int mediumLevel,
                                          double viewPixels,
                                          const lod::ZoomPolicyOptions& options) {
  const glm::ivec3 d = explorer.dims();
  const glm::dvec3 sp = explorer.source().shape().spacing();
  const glm::ivec3 cell = explorer.grid().cellSize();
  const double volumeRadius = 0.5 * glm::length(glm::dvec3(d) * sp);
  const double blockRadius = 0.5 * glm::length(glm::dvec3(glm::min(2 * cell, d)) * sp);
  const int coarse = std::min(mediumLevel + 1, explorer.source().levelCount() - 1);
  const double pxPerVoxel = std::max(1.0, viewPixels) / glm::length(glm::dvec3(d));
  // Each level's voxel in level-0 voxels along its most reduced axis: a
  // (1, 2, 2) pyramid's level 1 shows its coarseness from zoom 1/2 as a
  // halving one's does, its level 2 from 1/4 only where z is halved too.
  std::vector<double> levelVoxels;
  for (int l = 0; l < explorer.source().levelCount(); ++l) {
    const glm::ivec3 s = lod::levelScale(explorer.source(), l);
    levelVoxels.push_back(static_cast<double>(std::max({s.x, s.y, s.z})));
  }
  return lod::ZoomLevelPolicy::overviewStages(coarse, mediumLevel, pxPerVoxel, volumeRadius,
                                              blockRadius, options, levelVoxels);
}

ZoomSwap::ZoomSwap(gpu::GlContext& context, Explorer& explorer, std::vector<lod::ZoomStage> stages,
                   const lod::ZoomPolicyOptions& options)
    : context_(context),
      explorer_(explorer),
      policy_(std::move(stages), options),
      triangle_(context.ledger()) {
  const gpu::ApiLevel api = context.caps().api;
  blend_ = gpu::Program::build(
      "zoom fade",
      {gpu::shaderPreamble(api, false, {}), gpu::embeddedShaderPart("render/fullscreen.vert.glsl")},
      {gpu::shaderPreamble(api, true, {}), gpu::embeddedShaderPart("viewer/zoom_fade.frag.glsl")});
}

double ZoomSwap::overviewZoom(const Camera& camera) const {
  const double zoom = camera.zoom;
  if (!box_) return zoom;
  const glm::ivec3 dims = explorer_.dims();
  const glm::dvec3 spacing = explorer_.source().shape().spacing();
  return zoom * boxFraming(std::nullopt, dims, spacing).radius /
         boxFraming(box_, dims, spacing).radius;
}

// Puts `stage` into the viewer: a whole level (read once, kept) or the
// native grid block nearest the point the view is centred on, the camera
// kept across the swap.
void ZoomSwap::show(Viewer& viewer, int stage) {
  const lod::ZoomStage& st = policy_.stages()[static_cast<std::size_t>(stage)];
  const glm::ivec3 dims = explorer_.dims();
  const glm::dvec3 spacing = explorer_.source().shape().spacing();
  std::optional<lod::VoxelBox> box;
  std::shared_ptr<const Volume> volume;
  std::string name = st.name;
  if (st.subVolume) {
    // The view's centre in level-0 voxels (the target is mm from the
    // centre of what is shown), and the grid point nearest it.
    const glm::dvec3 centre = viewer.camera().target + boxFraming(box_, dims, spacing).centre;
    const glm::dvec3 voxel = centre / spacing + 0.5 * glm::dvec3(dims);
    lod::GridNavigator& g = explorer_.grid();
    g.moveTo(glm::clamp(glm::ivec3(glm::round(voxel / glm::dvec3(g.cellSize()))), glm::ivec3(0),
                        g.cells()));
    box = g.blockBox(g.point());
    volume = std::make_shared<const Volume>(explorer_.readRegion(*box));
    voxelsRead_ += box->count();
    name += " block";
  } else {
    auto& kept = levels_[st.level];
    if (!kept) {
      kept = std::make_shared<const Volume>(explorer_.readLevel(st.level));
      voxelsRead_ += kept->voxelCount();
    }
    volume = kept;
    name += " level " + std::to_string(st.level);
  }
  if (!label_.empty()) name = label_ + " (" + name + ")";
  // The camera and the window (a user's window/level) stay across the swap.
  const Camera before = viewer.camera();
  const std::optional<ValueRange> window =
      viewer.hasVolume() ? std::optional<ValueRange>(viewer.window()) : std::nullopt;
  viewer.setVolume(*volume, name);
  if (window) viewer.setWindow(*window);
  const Camera kept = cameraAcrossSwap(before, box_, box, dims, spacing);
  viewer.camera() = kept;
  box_ = box;
  shown_ = stage;
}

void ZoomSwap::blendOld(double weight, int width, int height, unsigned framebuffer,
                        glm::ivec2 origin) {
  gpu::bindFramebuffer(framebuffer, {origin.x, origin.y, width, height});
  blend_.use();
  old_.color().bind(0);
  blend_.set("u_old", 0);
  blend_.set("u_origin", glm::vec2(origin));
  blend_.set("u_size", glm::vec2(width, height));
  blend_.set("u_weight", static_cast<float>(weight));
  gpu::apply({.blend = gpu::Blend::StraightAlpha});
  triangle_.draw();
  gpu::apply({});
  gpu::checkErrors("zoom fade");
}

lod::ZoomFrame ZoomSwap::frame(Viewer& viewer, double dtMs, int width, int height,
                               unsigned framebuffer, glm::ivec2 origin) {
  if (!viewer.hasVolume() && shown_ < 0) throw InputError("zoom swap: the viewer has no volume");
  const lod::ZoomFrame f = policy_.update(overviewZoom(viewer.camera()), dtMs);
  if (f.stage != shown_) {
    if (shown_ >= 0 && f.from != f.stage) {
      // The image on screen now, kept to fade from: the old stage rendered
      // once more into a colour texture (ES 2 can render to and sample it).
      if (old_.width() != width || old_.height() != height) {
        old_ = gpu::Framebuffer();
        old_ = gpu::Framebuffer::create(context_.ledger(), "zoom fade", width, height,
                                        gpu::rgba8For(context_.caps().api));
      }
      const bool progressive = viewer.progressive;
      viewer.progressive = false;
      viewer.render(width, height, old_.id());
      viewer.progressive = progressive;
    }
    show(viewer, f.stage);
  }
  viewer.render(width, height, framebuffer, origin);
  if (f.from != f.stage && old_.width() == width && old_.height() == height) {
    blendOld(1.0 - f.mix, width, height, framebuffer, origin);
  }
  return f;
}

}  // namespace tessera::viewer
