#pragma once
// Exploring a volume at native resolution (Schultz 2016 §7.3-7.4): the
// state both viewers keep while a user goes from the overview to a
// bread-slice region or a grid block and back, and the steps between those
// states. One object per explored volume; the desktop viewer and the web page
// hold one each and only present what it says.
//
// A step is asked for (region, enterGrid, move), shown by the front end
// (show() reads and swaps the 3D view in one go; a page that fetches chunks
// first calls read() and showIn() when they have arrived), or given up
// (failed(): the grid point goes back to where it was). The overview is the
// finest level of the pyramid that the profile's overview budget allows, or
// the volume itself when it is handed over in memory.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

#include "tessera/core/Camera.h"
#include "tessera/core/Volume.h"
#include "tessera/lod/GridNavigator.h"
#include "tessera/lod/MultiresSource.h"
#include "tessera/render/Overlay.h"
#include "tessera/viewer/Explorer.h"
#include "tessera/viewer/ZoomSwap.h"

namespace tessera::session {

enum class ExploreMode { Overview, Region, Grid };
const char* exploreModeName(ExploreMode mode);

// How the camera follows a swap of the 3D view's volume (its direction
// always stays). Keep: every point of the patient stays where it was on
// screen (the zoom swap: the data changes, not the view). Centre: the new
// volume's centre, the zoom kept (a grid move). Fill: the new volume's
// centre at zoom 1. Back: the camera the overview had when it was left.
enum class Follow { Keep, Centre, Fill, Back };

// What the 3D view is to show next: a level-0 box in a mode.
struct ExploreStep {
  lod::VoxelBox box;
  ExploreMode mode = ExploreMode::Region;
  Follow follow = Follow::Fill;
};

// The overlay colours of the overview: the picked region, the grid block
// and the crosshair.
inline constexpr glm::vec4 kRegionColour{1.0f, 0.25f, 0.2f, 1.0f};
inline constexpr glm::vec4 kGridBlockColour{0.25f, 0.85f, 0.95f, 1.0f};
inline constexpr glm::vec4 kCrosshairColour{1.0f, 0.85f, 0.2f, 1.0f};

class Exploration {
 public:
  // Over a pyramid: reads its overview level (the finest with at most
  // `overviewVoxels` voxels; 0: none is read, e.g. a store the page draws
  // itself). `regionBudgetBytes`: what a region or grid block may take.
  Exploration(std::shared_ptr<const lod::MultiresSource> source, std::uint64_t regionBudgetBytes,
              std::uint64_t overviewVoxels, std::string label);
  // Over a volume in memory: the volume is the overview (level 0).
  Exploration(std::shared_ptr<const Volume> volume, std::uint64_t regionBudgetBytes,
              std::string label);

  viewer::Explorer& explorer() { return *explorer_; }
  const viewer::Explorer& explorer() const { return *explorer_; }
  glm::ivec3 dims() const { return explorer_->dims(); }
  const std::string& label() const { return label_; }

  // The overview's volume (null when none was read) and level, and the
  // name the 3D view shows for it ("ch2.nii.gz (level 1)").
  const std::shared_ptr<const Volume>& overview() const { return overview_; }
  int overviewLevel() const { return overviewLevel_; }
  std::string overviewName() const;

  ExploreMode mode() const { return mode_; }
  // The box the 3D view shows (null in the overview) and its name there.
  const std::optional<lod::VoxelBox>& shown() const { return shown_; }
  const std::string& shownName() const { return shownName_; }
  // The bread-slice region marked in the slice views and the overview.
  const std::optional<lod::VoxelBox>& picked() const { return picked_; }
  void pick(const std::optional<lod::VoxelBox>& box) { picked_ = box; }
  // The grid view's last block (null before the first).
  const std::optional<lod::VoxelBox>& gridBlock() const { return gridBlock_; }
  // The last grid step or refusal, and whether it was refused.
  const std::string& note() const { return note_; }
  bool refused() const { return refused_; }
  // A step asked for and not yet shown (a page fetching its chunks).
  const std::optional<ExploreStep>& pending() const { return pending_; }

  // `asked` with its ends clamped to the volume; InputError naming the axis
  // (after `what`) for a range that is empty or starts outside it.
  lod::VoxelBox clampBox(lod::VoxelBox asked, const std::string& what) const;

  // The steps. region(): `box` (clamped) becomes the picked region.
  ExploreStep region(const lod::VoxelBox& box, Follow follow);
  // The picked region, or the default cube around the crosshair.
  ExploreStep pickedRegion(Follow follow);
  // The grid point nearest the centre of `voxel` (the crosshair).
  ExploreStep enterGrid(glm::ivec3 voxel);
  // One move relative to a view of `basis`; null when refused (note says why).
  std::optional<ExploreStep> move(lod::ViewMove move, const glm::dmat3& basis);
  // Replaces the grid (another cell size); the last block is forgotten.
  void setGrid(lod::GridNavigator grid);

  // The step's voxels: one bounded read of level 0, placed where the box
  // lies in the patient frame.
  Volume read(const ExploreStep& step) const;
  // Reads the step and swaps it into the 3D view (showIn); on error the
  // step is given up (failed) and the error rethrown.
  void show(viewer::Viewer& view, const ExploreStep& step);
  // Swaps `volume` (read() of the step) into the 3D view: the window, the
  // label table and the camera's direction stay; the camera follows as the
  // step says. The step is then the shown one.
  void showIn(viewer::Viewer& view, Volume volume, const ExploreStep& step);
  // Gives up the pending step: a grid point goes back to where it was.
  void failed(const std::string& why);
  // Back to the overview volume in the 3D view, the camera following.
  void showOverview(viewer::Viewer& view, Follow follow);
  // The overview is shown again by other means (a store's own frames).
  void overviewShown();
  // A step the front end showed itself (the zoom swap's stages).
  void shownBy(const std::optional<lod::VoxelBox>& box, ExploreMode mode);
  // The camera the overview had when it was left.
  const Camera& overviewCamera() const { return overviewCamera_; }

  // The zoom swap (viewer/ZoomSwap.h, Schultz 2016 §7.3.1): while it runs,
  // the camera's zoom alone decides what the 3D view shows (a coarse level,
  // the overview level, the native grid block around the view's centre).
  // Its lifetime is the exploration's: the front end only says whether it
  // is wanted; any other step (show, showOverview) ends it.
  //
  // makeLevels: a volume handed over in memory is explored as one level
  // (no coarser level is made until needed); the zoom swap needs its coarser
  // levels, made here once (lod::downsample). The crosshair, region side,
  // grid and picked region stay; a running swap ends. No-op for a pyramid.
  void makeLevels();
  // keepZoom: wanted with two stages or more, a swap for `stages` runs from
  // here on (made from the overview only, so after another step once the
  // view is back there; made again when `key`, naming the stages, changes);
  // otherwise none runs. The overview level is handed over, not read again.
  void keepZoom(gpu::GlContext& context, bool wanted, const std::vector<lod::ZoomStage>& stages,
                const std::string& key);
  // The running swap (null: none).
  const viewer::ZoomSwap* zoom() const { return zoom_.get(); }
  void endZoom();
  // One frame of the running swap into `framebuffer` (ZoomSwap::frame); the
  // mode follows the stage shown (the native stage is the grid's block). On
  // error the swap ends (rather than failing every frame) and the error is
  // rethrown; the last volume stays in the view.
  lod::ZoomFrame zoomFrame(viewer::Viewer& view, double dtMs, int width, int height,
                           unsigned framebuffer = 0, glm::ivec2 origin = {0, 0});

  // The 3D view's lines for a shown volume of `extent`: in the overview the
  // picked region, the grid block and the crosshair; in a region or block
  // the crosshair where it falls inside it.
  std::vector<render::OverlayLine> lines(glm::dvec3 extent) const;

  // Mode, crosshair, region side, picked and shown boxes, grid cell and point.
  nlohmann::json state() const;
  // Restores the crosshair, region side, picked box, grid cell and point
  // (InputError for a state of another volume). Returns the step that shows
  // the state's mode again (null for the overview): the caller shows it.
  std::optional<ExploreStep> restore(const nlohmann::json& state);

 private:
  Camera followed(const Camera& before, const Camera& framed, Follow follow,
                  const std::optional<lod::VoxelBox>& to) const;

  std::unique_ptr<viewer::Explorer> explorer_;
  std::uint64_t regionBudgetBytes_ = 0;
  std::string label_;
  std::shared_ptr<const Volume> overview_;
  int overviewLevel_ = 0;
  ExploreMode mode_ = ExploreMode::Overview;
  std::optional<lod::VoxelBox> shown_, picked_, gridBlock_;
  std::string shownName_;
  std::string note_;
  bool refused_ = false;
  std::optional<ExploreStep> pending_;
  glm::ivec3 pendingFrom_{0};  // the grid point before the pending step
  Camera overviewCamera_;
  // After explorer_, which it refers to.
  std::unique_ptr<viewer::ZoomSwap> zoom_;
  std::string zoomKey_;
};

// "x0:x1,y0:y1,z0:z1" (end exclusive), as --region takes it.
std::string boxText(const lod::VoxelBox& box);

}  // namespace tessera::session
