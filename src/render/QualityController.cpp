#include "tessera/render/QualityController.h"

#include <algorithm>
#include <cmath>

#include "tessera/core/Error.h"

namespace tessera::render {

QualityController::QualityController(Options options) : options_(options) {
  if (!(options_.goalMs > 0.0)) throw InputError("quality: frame-time goal must be > 0 ms");
  if (!(options_.minResolutionScale > 0.0 && options_.minResolutionScale <= 1.0)) {
    throw InputError("quality: minimum resolution scale must be in (0, 1]");
  }
  if (!(options_.maxStepScale >= 1.0)) throw InputError("quality: maximum step scale must be >= 1");
  if (!(options_.gain > 0.0 && options_.gain <= 1.0)) {
    throw InputError("quality: gain must be in (0, 1]");
  }
  if (!(options_.resolutionStepsPerOctave >= 0.0 && options_.resolutionStepsPerOctave <= 64.0)) {
    throw InputError("quality: resolution steps per octave must be in [0, 64]");
  }
}

void QualityController::setInteracting(bool interacting) {
  if (interacting) {
    state_ = State::Interacting;
  } else if (state_ == State::Interacting) {
    state_ = State::Idle;
    idleFrameDone_ = false;
  }
}

QualityLevel QualityController::levelFor(double work) const {
  const double minWork =
      options_.minResolutionScale * options_.minResolutionScale / options_.maxStepScale;
  work = std::clamp(work, minWork, 1.0);
  QualityLevel level;
  const double floorWork = options_.minResolutionScale * options_.minResolutionScale;
  if (work >= floorWork) {
    level.resolutionScale = std::sqrt(work);
    const double steps = options_.resolutionStepsPerOctave;
    if (steps > 0.0 && work < 1.0) {
      // Rounded down (a small tolerance keeps a rung from rounding below
      // itself).
      const double k =
          std::floor(steps * std::log2(level.resolutionScale / options_.minResolutionScale) + 1e-9);
      level.resolutionScale = options_.minResolutionScale * std::exp2(std::max(0.0, k) / steps);
    }
  } else {
    level.resolutionScale = options_.minResolutionScale;
    level.stepScale = floorWork / work;
  }
  return level;
}

QualityLevel QualityController::next() const {
  if (state_ == State::Idle) return QualityLevel{};
  return levelFor(work_);
}

QualityLevel QualityController::nextWithin(double ms) const {
  if (state_ == State::Idle || !(ms < options_.goalMs)) return next();
  return levelFor(work_ * std::max(0.0, ms) / options_.goalMs);
}

void QualityController::report(const QualityLevel& level, double ms) {
  if (!(ms > 0.0) || !std::isfinite(ms)) return;
  if (state_ == State::Idle && level.full()) idleFrameDone_ = true;
  // Every measurement, idle ones included, says how much work fits the goal.
  const double measuredWork = level.work();
  const double ratio = options_.goalMs / ms;
  // The first measurement, and the full-quality idle frame (far from any
  // interactive level), jump straight to their proportional estimate.
  const double gain = measured_ && !level.full() ? options_.gain : 1.0;
  const double proposed = measuredWork * std::pow(ratio, gain);
  const double minWork =
      options_.minResolutionScale * options_.minResolutionScale / options_.maxStepScale;
  work_ = std::clamp(proposed, minWork, 1.0);
  measured_ = true;
}

std::string qualityStateName(QualityController::State state) {
  return state == QualityController::State::Interacting ? "interacting" : "idle";
}

}  // namespace tessera::render
