#include "tessera/viewer/TransferFunctionEditor.h"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>

#include "tessera/core/Error.h"

namespace tessera::viewer {

namespace {
double clamp01(double v) {
  return std::clamp(v, 0.0, 1.0);
}

// x limits that keep point i between its neighbours (so indices stay stable).
template <class Points>
std::pair<double, double> neighbourLimits(const Points& points, int i) {
  const double lo = i > 0 ? points[static_cast<std::size_t>(i) - 1].x : 0.0;
  const double hi =
      i + 1 < static_cast<int>(points.size()) ? points[static_cast<std::size_t>(i) + 1].x : 1.0;
  return {lo, hi};
}
}  // namespace

TransferFunctionEditor::TransferFunctionEditor() : tf_(TransferFunction::preset("mr-default")) {}

void TransferFunctionEditor::setTransferFunction(const TransferFunction& tf) {
  tf_ = tf;
  selection_ = {};
  dragging_ = false;
  changed();
}

void TransferFunctionEditor::loadPreset(const std::string& name) {
  setTransferFunction(TransferFunction::preset(name));
}

void TransferFunctionEditor::loadJson(const std::string& json) {
  setTransferFunction(TransferFunction::fromJson(json, "transfer function JSON"));
}

void TransferFunctionEditor::setHistogram(const Histogram& histogram) {
  counts_ = histogram.counts();
}

std::vector<double> TransferFunctionEditor::histogramHeights(bool logScale) const {
  std::vector<double> h(counts_.size(), 0.0);
  if (counts_.empty()) return h;
  const double maxCount = static_cast<double>(*std::max_element(counts_.begin(), counts_.end()));
  if (maxCount <= 0.0) return h;
  for (std::size_t i = 0; i < counts_.size(); ++i) {
    const double c = static_cast<double>(counts_[i]);
    h[i] = logScale ? std::log1p(c) / std::log1p(maxCount) : c / maxCount;
  }
  return h;
}

std::optional<int> TransferFunctionEditor::hit(TfChannel channel, glm::dvec2 p,
                                               glm::dvec2 radius) const {
  std::optional<int> best;
  double bestD = 1.0;  // in units of the radius
  if (channel == TfChannel::Opacity) {
    for (std::size_t i = 0; i < tf_.opacities.size(); ++i) {
      const double dx = (tf_.opacities[i].x - p.x) / radius.x;
      const double dy = (tf_.opacities[i].alpha - p.y) / radius.y;
      const double d = std::sqrt(dx * dx + dy * dy);
      if (d <= bestD) {
        bestD = d;
        best = static_cast<int>(i);
      }
    }
  } else {
    for (std::size_t i = 0; i < tf_.colors.size(); ++i) {
      const double d = std::abs(tf_.colors[i].x - p.x) / radius.x;
      if (d <= bestD) {
        bestD = d;
        best = static_cast<int>(i);
      }
    }
  }
  return best;
}

int TransferFunctionEditor::addOpacityPoint(double x, double alpha) {
  x = clamp01(x);
  auto it = std::upper_bound(tf_.opacities.begin(), tf_.opacities.end(), x,
                             [](double v, const OpacityPoint& q) { return v < q.x; });
  it = tf_.opacities.insert(it, OpacityPoint{x, clamp01(alpha)});
  changed();
  return static_cast<int>(it - tf_.opacities.begin());
}

int TransferFunctionEditor::addColorPoint(double x, glm::dvec3 rgb) {
  x = clamp01(x);
  auto it = std::upper_bound(tf_.colors.begin(), tf_.colors.end(), x,
                             [](double v, const ColorPoint& q) { return v < q.x; });
  it = tf_.colors.insert(it, ColorPoint{x, glm::clamp(rgb, 0.0, 1.0)});
  changed();
  return static_cast<int>(it - tf_.colors.begin());
}

void TransferFunctionEditor::moveOpacityPoint(int index, double x, double alpha) {
  if (index < 0 || index >= static_cast<int>(tf_.opacities.size())) return;
  const auto [lo, hi] = neighbourLimits(tf_.opacities, index);
  OpacityPoint& p = tf_.opacities[static_cast<std::size_t>(index)];
  p.x = std::clamp(x, lo, hi);
  p.alpha = clamp01(alpha);
  changed();
}

void TransferFunctionEditor::moveColorPoint(int index, double x) {
  if (index < 0 || index >= static_cast<int>(tf_.colors.size())) return;
  const auto [lo, hi] = neighbourLimits(tf_.colors, index);
  tf_.colors[static_cast<std::size_t>(index)].x = std::clamp(x, lo, hi);
  changed();
}

void TransferFunctionEditor::setColor(int index, glm::dvec3 rgb) {
  if (index < 0 || index >= static_cast<int>(tf_.colors.size())) return;
  tf_.colors[static_cast<std::size_t>(index)].rgb = glm::clamp(rgb, 0.0, 1.0);
  changed();
}

bool TransferFunctionEditor::removePoint(TfChannel channel, int index) {
  if (channel == TfChannel::Opacity) {
    if (tf_.opacities.size() <= 1 || index < 0 || index >= static_cast<int>(tf_.opacities.size()))
      return false;
    tf_.opacities.erase(tf_.opacities.begin() + index);
  } else {
    if (tf_.colors.size() <= 1 || index < 0 || index >= static_cast<int>(tf_.colors.size()))
      return false;
    tf_.colors.erase(tf_.colors.begin() + index);
  }
  if (selection_.channel == channel && selection_.index == index) selection_ = {};
  changed();
  return true;
}

void TransferFunctionEditor::pointerDown(TfChannel channel, glm::dvec2 p, glm::dvec2 radius) {
  std::optional<int> i = hit(channel, p, radius);
  if (!i) {
    i = channel == TfChannel::Opacity ? addOpacityPoint(p.x, p.y)
                                      : addColorPoint(p.x, tf_.color(clamp01(p.x)));
  }
  selection_ = {channel, *i};
  dragging_ = true;
}

void TransferFunctionEditor::pointerMove(glm::dvec2 p) {
  if (!dragging_ || selection_.index < 0) return;
  if (selection_.channel == TfChannel::Opacity) {
    moveOpacityPoint(selection_.index, p.x, p.y);
  } else {
    moveColorPoint(selection_.index, p.x);
  }
}

void TransferFunctionEditor::pointerUp(glm::dvec2 p) {
  if (!dragging_) return;
  dragging_ = false;
  if (selection_.channel == TfChannel::Opacity && p.y < -kRemoveMargin) removeSelected();
}

bool TransferFunctionEditor::removeSelected() {
  if (selection_.index < 0) return false;
  return removePoint(selection_.channel, selection_.index);
}

void TransferFunctionEditor::setSelectedColor(glm::dvec3 rgb) {
  if (selection_.channel == TfChannel::Color) setColor(selection_.index, rgb);
}

}  // namespace tessera::viewer
