#pragma once
// Interactive quality control: while the user interacts, each frame is
// rendered at a reduced offscreen resolution and, below a floor, with a
// larger sample distance, chosen so that the frame time meets a goal; when
// the interaction stops, one frame at full quality follows (progressive
// refinement), after which nothing needs rendering until something changes.
//
// The choice is a feedback loop on the measured frame time. Rendering cost is
// nearly linear in pixels x samples (Moser & Weiskopf 2008, Figures 3 and 4;
// docs/benchmarks.md), so a level is summarised by its work fraction
//   w = resolutionScale^2 / stepScale   (1 = full quality),
// and after each frame w is multiplied by (goal / measured)^gain. With a
// fixed per-frame overhead a (compositing, lines) and t(w) = a + b w, the
// iteration converges to t = goal whenever a < goal (its slope there is
// 1 - gain (1 - a / goal) in (0, 1)).
#include <string>

namespace tessera::render {

struct QualityLevel {
  double resolutionScale = 1.0;  // offscreen size / screen size, per axis
  double stepScale = 1.0;        // sample distance / the full-quality distance
  bool full() const { return resolutionScale >= 1.0 && stepScale <= 1.0; }
  double work() const { return resolutionScale * resolutionScale / stepScale; }
};

class QualityController {
 public:
  enum class State { Interacting, Idle };

  struct Options {
    double goalMs = 100.0;              // frame-time goal while interacting
    double minResolutionScale = 0.125;  // below this, the sample distance grows instead
    double maxStepScale = 4.0;
    double gain = 0.8;  // fraction of the log error corrected per frame
    // > 0: reduced resolutions are rounded down to a ladder of this many
    // steps per octave from minResolutionScale, so that the frames' sizes
    // repeat (a front end that keeps a render target per size then makes
    // few: in a browser each is an allocation checked by round trips to
    // the GPU process). 0: any resolution.
    double resolutionStepsPerOctave = 0.0;
  };

  QualityController() : QualityController(Options{}) {}
  explicit QualityController(Options options);

  // Starts or ends an interaction. Ending it schedules the full-quality frame.
  void setInteracting(bool interacting);
  State state() const { return state_; }

  // Whether a frame should be rendered now: always while interacting; when
  // idle, until the full-quality frame has been reported.
  bool needsFrame() const { return state_ == State::Interacting || !idleFrameDone_; }
  // The level of the next frame: full quality when idle.
  QualityLevel next() const;
  // The next level for a frame that must take at most `ms`, less than the
  // goal (an input that has already waited, due within its deadline): its
  // work shrunk in proportion, which meets `ms` when the frame costs only
  // its work (a fixed cost makes it take longer; the cheapest level at
  // most). next() for `ms` at or above the goal, and when idle. Such a
  // frame's time is not a measure of the goal's level: not reported.
  QualityLevel nextWithin(double ms) const;
  // The measured time of a frame rendered at `level` (as returned by next()).
  void report(const QualityLevel& level, double ms);

  // The work fraction the controller aims for while interacting.
  double targetWork() const { return work_; }
  const Options& options() const { return options_; }

  // The level for a work fraction: resolution first (on the ladder, when
  // the options ask for one), then sample distance.
  QualityLevel levelFor(double work) const;

 private:
  Options options_;
  State state_ = State::Idle;
  bool idleFrameDone_ = false;
  double work_ = 0.25;  // until a frame has been measured
  bool measured_ = false;
};

std::string qualityStateName(QualityController::State state);  // "interacting" / "idle"

}  // namespace tessera::render
