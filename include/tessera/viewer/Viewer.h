#pragma once
// The viewer core both front ends (desktop `tessera view`, the web page)
// drive: it holds the volume on the GPU, the camera and its controller, the
// TF editor, window/level, render mode, technique and quality, draws the
// bounding box and axes, and times every frame. A front end only turns its
// input events into calls here and shows the frame.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "tessera/core/Camera.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/core/Volume.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/layout/Planner.h"
#include "tessera/render/LabelTable.h"
#include "tessera/render/Overlay.h"
#include "tessera/render/QualityController.h"
#include "tessera/render/RowCosts.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/viewer/CameraController.h"
#include "tessera/viewer/TransferFunctionEditor.h"

namespace tessera::viewer {

// What a frame does while the user interacts. Full: every frame at full
// quality. Adaptive: while a pointer is down, render::QualityController
// picks the resolution and sample distance that meet its frame-time goal
// (starting at half the resolution); once released, full quality again.
enum class Quality { Full, Adaptive };

struct FrameStats {
  double ms = 0.0;      // the whole frame, up to a 1-pixel read-back (GL may not block on glFinish)
  int renderWidth = 0;  // what the technique rendered (smaller while adaptive quality interacts)
  int renderHeight = 0;
  // False for a progressive frame's preview or a part of its refinement:
  // the full-quality frame is still being rendered (Viewer::refine).
  bool complete = true;
};

class Viewer {
 public:
  // `context` must be current and outlive the viewer. The profile is applied
  // as `tessera render --profile` applies it (gpu::applyProfile): the
  // effective limits, the GPU ledger's budget and the process's host budget.
  Viewer(gpu::GlContext& context, const gpu::DeviceProfile& profile);
  ~Viewer();
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;

  // Uploads the volume for the technique (render::createTechnique) and
  // frames it. On any error (InputError, BudgetError, GpuError) the previous
  // volume stays and the error propagates with its message. Keeps the TF;
  // resets window and camera; leaves label mode (the TF editor back to
  // its mr-default preset).
  void setVolume(Volume volume, const std::string& name);
  // The same, sharing the caller's voxels (a session's volume): no copy.
  void setVolume(std::shared_ptr<Volume> volume, const std::string& name);
  bool hasVolume() const { return active_.technique != nullptr; }
  const Volume& volume() const { return *volume_; }  // empty before the first setVolume
  // The same volume, shared (an exploration keeps it as its overview).
  std::shared_ptr<const Volume> sharedVolume() const { return volume_; }
  const std::string& volumeName() const { return volumeName_; }
  // Counts setVolume calls: a front end caching frames keys them by it (a
  // time series swaps volumes of one name).
  std::uint64_t volumeRevision() const { return volumeRevision_; }
  // How the technique's upload stored the volume (empty for a technique with
  // its own storage: see storageName()).
  const layout::Plan& plan() const { return active_.upload.plan; }
  // The layout, or the technique's own storage ("slice-stacks").
  std::string storageName() const;
  const gpu::DeviceLimits& limits() const { return limits_; }
  gpu::GlContext& context() { return context_; }

  Camera& camera() { return camera_; }
  CameraController& controller() { return controller_; }
  void resetCamera();
  TransferFunctionEditor& tfEditor() { return tfEditor_; }
  RenderSettings& settings() { return settings_; }

  // Value window (raw values) that maps to the TF's [0,1]; recomputes the
  // editor's histogram. Window/level: level = centre, window = width.
  void setWindow(ValueRange w);
  void setWindowLevel(double window, double level) {
    setWindow({level - 0.5 * window, level + 0.5 * window});
  }
  void resetWindow();
  ValueRange window() const { return volume_->window(); }
  ValueRange valueRange() const { return volume_->valueRange(); }

  // A technique of render::TechniqueRegistry; the volume is uploaded again
  // for its requirements. InputError if unknown; on any error the old stays.
  void setTechnique(const std::string& name);
  // A second volume over this one (docs/fusion.md), mixed into the technique's
  // composite samples; null: none. A technique that cannot fuse shows the
  // volume alone, and fusionNote() says why.
  void setFusion(std::shared_ptr<const FusedVolume> fused);
  const std::string& fusionNote() const { return fusionNote_; }
  const std::string& technique() const { return techniqueName_; }

  // Label volumes (atlases), rendered as `tessera render --labels` renders
  // them (render::prepareLabelVolume, render::applyLabelSettings, the
  // table's categorical TF in a render::kLabelLutSize-entry table).
  // setLabels checks the current volume (InputError if it is not one; the
  // previous state stays), re-uploads it for the label table once, and sets
  // the TF editor to the table's TF; called again it only updates the TF
  // (visibility, colours). clearLabels goes back to an ordinary volume
  // (window reset, linear interpolation, the TF editor's preset `tf`).
  void setLabels(render::LabelTable table);
  void setLabelsDefault() { setLabels(render::LabelTable::defaultFor(*volume_)); }
  void clearLabels(const std::string& tf = "mr-default");
  bool labelsOn() const { return labels_.has_value(); }
  // The colours of the 2D slice views: the TF's when `asked`, and always for
  // a label volume (its label colours); null: grey.
  const TransferFunction* sliceColours(bool asked) const {
    return asked || labelsOn() ? &tfEditor_.transferFunction() : nullptr;
  }
  const render::LabelTable& labelTable() const { return *labels_; }  // only when labelsOn()
  void setLabelVisible(int value, bool visible);
  void setAllLabelsVisible(bool visible);
  Quality quality = Quality::Adaptive;
  // At most this many pixels of volume per frame (0: no cap): on a HiDPI
  // screen the frame (lines, compositing) has the screen's pixels while the
  // volume is rendered smaller and upscaled, as the hybrid compositor does;
  // adaptive quality reduces it further while the user interacts.
  int maxVolumePixels = 0;
  // The adaptive quality's feedback loop (goal: qualityController().options()).
  render::QualityController& qualityController() { return qualityController_; }
  // Lines drawn at the frame's full resolution and composed with the volume
  // by depth: hidden behind opaque parts, faded behind translucent ones.
  bool showBoundingBox = true;
  bool showAxes = true;
  // More lines in the volume's model frame (viewer/Explorer.h: the picked
  // region or grid block, the crosshair), drawn like the bounding box.
  std::vector<render::OverlayLine> extraLines;
  // A clip plane facing the viewer that turns with the camera: it cuts away
  // what lies nearer the viewer than `followingPlaneDistance` (world units
  // from the volume's centre along the view direction), on top of
  // settings().clipping's planes.
  bool clipPlaneFollowsCamera = false;
  double followingPlaneDistance = 0.0;
  // settings() as the next frame renders them (the following plane added).
  RenderSettings frameSettings() const;

  // Renders one frame into `framebuffer` (0: the window / canvas) at
  // width x height with its lower-left corner at `origin`, and times it.
  FrameStats render(int width, int height, unsigned framebuffer = 0, glm::ivec2 origin = {0, 0});
  const FrameStats& lastFrame() const { return last_; }

  // Progressive full-quality frames, so that a slow technique never blocks
  // the front end's input: when a full-quality frame is expected to cost
  // more than frameBudgetMs (learnt from the frames before), render() shows
  // a preview at adaptive quality's interaction level and starts the full
  // frame, which refine() renders off screen in horizontal strips
  // (gpu::RegionScope) of about frameBudgetMs each and shows once the last
  // strip is done. The next render() cancels what is left. Between render()
  // and the end of the refinement nothing else may draw with this viewer's
  // technique (the strips accumulate in its target).
  bool progressive = false;
  double frameBudgetMs = 12.0;  // leaves most of a 60 Hz animation frame to the page
  bool refining() const { return pending_.active; }
  // One strip (about frameBudgetMs of work) of the pending frame, into the
  // framebuffer render() was given; shows the frame when it is done.
  FrameStats refine();

  // Patient directions at the view's edges (R/L, A/P, S/I) for the current
  // camera; empty strings when the volume's file carries no orientation
  // (PVM, raw, generated volumes), where letters would be a guess.
  EdgeLabels orientationLabels() const;

  // "ch2.nii.gz 181x217x181 u8, texture3d (...)" for a status bar.
  std::string description() const;

 private:
  struct Gpu;  // present and overlay programs
  void updateHistogram();
  render::TechniqueOnVolume createActive(const std::string& technique,
                                         const lod::VolumeSource& source) const;
  // The settings and size the technique renders a frame of width x height at.
  struct VolumePass {
    RenderSettings settings;
    int width = 0;
    int height = 0;
  };
  VolumePass volumePass(int width, int height, const render::QualityLevel& level) const;
  void syncTransferFunction();
  // The technique's image of `pass`, ray casts scissored to the volume.
  const gpu::Texture& renderVolume(const VolumePass& pass);
  // The technique's last whole frame: its target, size and the part of the
  // view that can hold the volume (render/camera_ray.glsl's rays).
  struct DrawnRegion {
    const render::Technique* technique = nullptr;
    int width = 0, height = 0;
    glm::vec4 region{0.0f};
  };
  DrawnRegion drawn_;
  // Renders the volume at `level` and composes it into the framebuffer.
  FrameStats presentFrame(int width, int height, unsigned framebuffer, glm::ivec2 origin,
                          const render::QualityLevel& level);
  void compose(const gpu::Texture& image, int width, int height, unsigned framebuffer,
               glm::ivec2 origin);
  // A progressive frame being refined.
  struct Pending {
    bool active = false;
    int width = 0, height = 0;
    unsigned framebuffer = 0;
    glm::ivec2 origin{0, 0};
    VolumePass pass;
    double done = 0.0;       // fraction of the rows rendered
    double ms = 0.0;         // spent on its strips
    render::RowCosts costs;  // what its rows are expected to cost (at the first strip)
  };
  Pending pending_;
  double frameMsPerPixel_ = 0.0;   // last full-quality frame's cost (0: unknown)
  double stripMsPerWeight_ = 0.0;  // the refinement's strips', per render::RowCosts weight
  std::vector<render::OverlayLine> overlayLines() const;  // box and axes as shown

  gpu::GlContext& context_;
  gpu::DeviceLimits limits_;
  Camera camera_;
  CameraController controller_{camera_};
  TransferFunctionEditor tfEditor_;
  RenderSettings settings_ = defaultRenderSettings();  // what `tessera render` uses
  std::string techniqueName_ = "raycast";
  int lutSize_ = render::TechniqueOptions{}.lutSize;  // kLabelLutSize while labels are shown
  std::optional<render::LabelTable> labels_;
  std::shared_ptr<const FusedVolume> fusion_;
  mutable std::string fusionNote_;  // set where a technique is made (createActive)
  void applyFusion(render::Technique& technique) const;
  void recreateActive();  // the volume uploaded again for techniqueName_ and lutSize_
  std::uint64_t uploadedTfRevision_ = 0;
  FrameStats last_;
  render::QualityController qualityController_{{.goalMs = 66.0}};  // 15 frames/s

  // Shared: the upload holds the volume it rendered (this one, or its
  // reduction), and the technique refers to it.
  std::shared_ptr<Volume> volume_;  // as loaded
  std::string volumeName_;
  std::uint64_t volumeRevision_ = 0;
  render::TechniqueOnVolume active_;  // the volume on the GPU and the technique on it
  std::unique_ptr<Gpu> gpu_;
};

}  // namespace tessera::viewer
