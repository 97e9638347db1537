#pragma once
// The zoom-driven level swap of the overview (Schultz 2016 §7.3.1), the
// part both front ends share: lod::ZoomLevelPolicy decides from
// the camera's zoom which stage to show (coarse level, medium level, the
// native 2x2x2 grid block around the view's centre), this class reads that
// stage with bounded reads of the Explorer's source (a whole coarse level,
// or one box of level 0, never level 0 whole), puts it into the Viewer with
// the camera kept (every patient point stays where it was on screen), and
// cross-fades from the previous stage's image over the policy's fade time.
//
// The fade works on ES 2 / WebGL 1 as on ES 3: at a swap the old stage's
// image is rendered once more into an RGBA8 framebuffer (a colour texture,
// which ES 2 can render to and sample; no blit), and every frame of the
// fade draws that texture over the new stage's frame with straight-alpha
// blending at the old image's remaining weight (1 - mix): one full-screen
// triangle, GLSL 100 and 300 alike.
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <glm/vec2.hpp>

#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/Program.h"
#include "tessera/lod/ZoomLevelPolicy.h"
#include "tessera/viewer/Explorer.h"
#include "tessera/viewer/Viewer.h"

namespace tessera::viewer {

// The stages for `explorer`'s volume shown `viewPixels` high: the paper's
// coarse and medium overview levels (`mediumLevel` and the level above it,
// where the pyramid has one) and the native grid block (when mediumLevel > 0).
std::vector<lod::ZoomStage> zoomStagesFor(const Explorer& explorer, int mediumLevel,
                                          double viewPixels,
                                          const lod::ZoomPolicyOptions& options = {});

class ZoomSwap {
 public:
  // `context` current, outliving this; `explorer` outlives this.
  ZoomSwap(gpu::GlContext& context, Explorer& explorer, std::vector<lod::ZoomStage> stages,
           const lod::ZoomPolicyOptions& options = {});

  // One frame of width x height into `framebuffer` at `origin` (as
  // Viewer::render): the policy advances by dtMs at the camera's zoom (in
  // the overview's terms), a stage change swaps the viewer's volume, and
  // during a fade the old image is blended over the new. The first call
  // shows the stage the zoom asks for without a fade.
  lod::ZoomFrame frame(Viewer& viewer, double dtMs, int width, int height, unsigned framebuffer = 0,
                       glm::ivec2 origin = {0, 0});

  // A whole level the front end has already read (its overview): used
  // instead of reading it again.
  void keepLevel(int level, std::shared_ptr<const Volume> volume) {
    levels_[level] = std::move(volume);
  }

  // The viewer's volume is named "LABEL (medium level 1)" and so on (without
  // a label: "medium level 1").
  void setLabel(std::string label) { label_ = std::move(label); }

  const lod::ZoomLevelPolicy& policy() const { return policy_; }
  // The stage in the viewer (-1 before the first frame).
  int shownStage() const { return shown_; }
  // The native block the viewer shows (nullopt: a whole level).
  const std::optional<lod::VoxelBox>& shownBox() const { return box_; }
  bool fading() const { return policy_.frame().from != policy_.frame().stage; }
  // The camera's zoom in the overview's terms (the native block is framed
  // by its own radius: scaled back to the whole volume's).
  double overviewZoom(const Camera& camera) const;
  // Bytes read from the source by the swaps so far (bounded reads only).
  std::uint64_t voxelsRead() const { return voxelsRead_; }

 private:
  void show(Viewer& viewer, int stage);
  void blendOld(double weight, int width, int height, unsigned framebuffer, glm::ivec2 origin);

  gpu::GlContext& context_;
  Explorer& explorer_;
  lod::ZoomLevelPolicy policy_;
  int shown_ = -1;
  std::optional<lod::VoxelBox> box_;
  std::map<int, std::shared_ptr<const Volume>> levels_;  // whole levels read so far
  std::uint64_t voxelsRead_ = 0;
  std::string label_;
  gpu::Framebuffer old_;  // the previous stage's image during a fade
  gpu::Program blend_;
  gpu::FullscreenTriangle triangle_;
};

}  // namespace tessera::viewer
