#pragma once
// The transfer-function editor's model, shared by both front ends (Moser &
// Weiskopf 2008, User Interface): opacity control points drawn over the data
// histogram, colour control points on a strip below it. Front ends draw what
// this class exposes and forward pointer gestures in editor units:
// x = normalised scalar in [0,1] (the volume's value window), y = opacity in
// [0,1] for the opacity area. The TF is the one the CLI reads and writes
// (TransferFunction, same JSON).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "tessera/core/Histogram.h"
#include "tessera/core/TransferFunction.h"

namespace tessera::viewer {

enum class TfChannel { Opacity, Color };

class TransferFunctionEditor {
 public:
  TransferFunctionEditor();

  const TransferFunction& transferFunction() const { return tf_; }
  void setTransferFunction(const TransferFunction& tf);
  void loadPreset(const std::string& name);  // InputError if unknown
  void loadJson(const std::string& json);    // InputError; the TF is kept on error
  std::string json() const { return tf_.toJson(); }
  // Increases with every change, so a renderer uploads the TF only when needed.
  std::uint64_t revision() const { return revision_; }

  // Histogram of the volume over its current window (bins span [0,1] in x).
  void setHistogram(const Histogram& histogram);
  // Bar heights in [0,1]: count / max count, or log(1+count) / log(1+max).
  std::vector<double> histogramHeights(bool logScale) const;

  // Index of the point of `channel` nearest to `p` within `radius` (editor
  // units per axis; for colour points only x counts); none if none is close.
  std::optional<int> hit(TfChannel channel, glm::dvec2 p, glm::dvec2 radius) const;

  int addOpacityPoint(double x, double alpha);  // returns its index
  int addColorPoint(double x, glm::dvec3 rgb);  // returns its index
  // Moves a point; x stays between its neighbours so indices stay stable,
  // and the values are clamped to [0,1].
  void moveOpacityPoint(int index, double x, double alpha);
  void moveColorPoint(int index, double x);
  void setColor(int index, glm::dvec3 rgb);
  // Removing is refused (returns false) for the last point of a channel.
  bool removePoint(TfChannel channel, int index);

  // Pointer gesture: press on a point selects and drags it; press elsewhere
  // adds a point there (colour: with the colour the TF has at x) and drags
  // it; dragging an opacity point below the area (y < -kRemoveMargin) and
  // releasing it there removes it.
  static constexpr double kRemoveMargin = 0.15;
  void pointerDown(TfChannel channel, glm::dvec2 p, glm::dvec2 radius);
  void pointerMove(glm::dvec2 p);
  void pointerUp(glm::dvec2 p);
  bool dragging() const { return dragging_; }
  struct Selection {
    TfChannel channel = TfChannel::Opacity;
    int index = -1;
  };
  const Selection& selection() const { return selection_; }
  bool removeSelected();
  // Colour of the selected colour point (or nothing when an opacity point is selected).
  void setSelectedColor(glm::dvec3 rgb);

 private:
  void changed() { ++revision_; }

  TransferFunction tf_;
  std::vector<std::uint64_t> counts_;
  std::uint64_t revision_ = 1;
  Selection selection_;
  bool dragging_ = false;
};

}  // namespace tessera::viewer
