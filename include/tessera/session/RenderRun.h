#pragma once
// One render run of a session (session/Session.h), and of the benchmarks
// that time one: upload the volume for the technique
// (render::createTechnique), refine a streamed volume's first frame
// (session/BrickRefinement.h), render N frames (rotating), optionally compare
// with the CPU reference.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tessera/core/Image.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/layout/Planner.h"
#include "tessera/lod/VolumeSource.h"
#include "tessera/render/Technique.h"
#include "tessera/session/BrickRefinement.h"
#include "tessera/session/Settings.h"

namespace tessera::session {

struct RenderRequest {
  Settings settings;  // validated by runRender
  int width = 512;
  int height = 512;
  int repeat = 1;
  double rotateDeg = 0.0;
  bool reference = false;
  // > 0: judge quality against a fine reference instead of the render's twin:
  // the CPU reference at this step (voxels), post-classified, every sample
  // (no pre-integration, no adaptive steps), the render's other settings.
  double referenceStep = 0.0;
  // A layout that streams a pyramid (bricks): the level the reference reads
  // whole (0: the finest), within the host budget. Unset: the finest level
  // the refined frame 0 shows. Needs `reference`.
  std::optional<int> referenceLevel;
  // A streamed volume: where refining frame 0 stops.
  RefineLimits refine;
  // A second volume over this one (session/Fusion.h): composite,
  // post-classified frames; the reference fuses it too.
  std::shared_ptr<const FusedVolume> fusion;

  render::TechniqueOptions techniqueOptions() const {
    return settings.techniqueOptions({width, height});
  }
};

// The bricks layout's streaming (layout/BricksLayout.h): how frame 0 was
// refined until every brick the view wants was resident, and what the
// rotating frames then used.
struct BricksRun {
  int refineFrames = 0;       // frames drawn until complete (the first image is frame 1)
  double firstFrameMs = 0.0;  // to the first image (coarsest level)
  double completeMs = 0.0;    // to the refined image
  bool complete = false;      // false: stopped at the frame or time limit
  int failing = 0;            // bricks left at a coarser level because their reads keep failing
  std::vector<std::string> failedReads;  // their distinct errors (RefineRun::failedReads)
  std::size_t failedReadCount = 0;
  std::vector<int> wantedPerLevel;          // the final view's cut, bricks per level
  std::vector<int> cellsPerLevel;           // page-table cells per level (last: transparent)
  std::vector<std::string> rotatingLevels;  // per rotating frame, "L0:12 L1:40 ..."
  int slots = 0;
  std::uint64_t bytesRead = 0;
  std::uint64_t bricksRead = 0;
  std::uint64_t readErrors = 0;
  std::uint64_t cachePeakBytes = 0;
  std::string lastError;
};

struct RenderResult {
  std::vector<double> frameMs;
  double prepareMs = 0.0;  // shader compile + lookup tables, before the first frame
  std::string gradient;    // shaded ray casting: where the gradient came from and why
  Image first;             // the frame at the requested view
  std::optional<Image> referenceImage;
  double referenceMs = 0.0;
  std::uint64_t referenceSamples = 0;  // samples the reference took for frame 0
  std::uint64_t referenceRays = 0;     // rays of frame 0 that meet the volume
  double referenceStep = 0.0;          // the reference's step (voxels)
  // A layout that streams: the pyramid level the reference read, its dims,
  // and why that one (asked for, or the level frame 0 shows). A frame that
  // shows several (`referenceLevelMixed`): the reference reads, per level-0
  // cell, the level frame 0 shows there (reference/CellLevels.h); the level
  // here is the finest of them.
  std::optional<int> referenceLevel;
  glm::ivec3 referenceLevelDims{0};
  bool referenceLevelMixed = false;
  std::string referenceLevelNote;
  // What the render took (the twin reference walks its samples, see
  // ReferenceRaycaster.h): samples per ray hitting the volume, frame 0; set
  // with the twin reference only (not with --reference-step).
  double samplesPerRay = 0.0;
  // Sampling in effect (settings.sampling after the technique's support).
  bool preintegrated = false;
  bool adaptive = false;
  double preintegrationBuildMs = 0.0;  // the last table rebuild, CPU side
  double preintegrationUploadMs = 0.0;
  std::optional<double> psnrDb;
  std::optional<double> ssim;
  std::uint64_t textureBytes = 0;  // every GPU texture/buffer alive, from the ledger
  std::uint64_t volumeTextureBytes = 0;
  double occupiedBlockFraction = 1.0;
  std::string layout;
  std::string layoutReason;
  layout::Plan plan;
  std::string planNote;
  glm::ivec3 renderedDims{0};       // after any downsampling the plan asked for
  std::optional<BricksRun> bricks;  // when the layout is bricks

  double median() const;
  double min() const;
  double max() const;
};

// Frame 0's set-up on a technique holding `volume` (what runRender does before
// drawing, and Session::render before each frame on the technique it keeps):
// the TF, the camera framing the volume, the sampling the technique honours,
// prepare(). `req.settings` is left as drawn.
void prepareFrame(render::Technique& technique, const Volume& volume, RenderRequest& req);

// A fused volume is mixed into composite frames without gradient-opacity
// modulation (InputError otherwise), taking every sample post-classified:
// `s.sampling` is reset (no pre-integration, no adaptive steps).
void applyFusionSettings(RenderSettings& s);

// InputError "size WxH: width and height must be 1..16384" otherwise.
void checkImageSize(int width, int height);

// The TF is request.settings.tf; a label volume's is its table's.
RenderResult runRender(gpu::DeviceSession& device, const lod::VolumeSource& source,
                       RenderRequest request);

}  // namespace tessera::session
