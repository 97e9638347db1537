#pragma once
// What each row of a frame is expected to cost, for sizing the strips a
// progressive frame is drawn in (the page's store view, viewer::Viewer): a
// pixel outside what the technique draws (the volume's box, a slicer's
// proxy) costs a small fixed part of one inside it, so rows below and
// above the volume are cheap and rows across it dear. A cost learnt on
// the cheap rows then does not size a strip across the volume several
// times its budget, as a cost per pixel of the whole image did.
#include <glm/vec3.hpp>
#include <vector>

#include "tessera/core/Camera.h"

namespace tessera::render {

// Which pixels a technique's frames cost at: those whose rays enter the
// volume's box (ray casters, object-aligned slices), or those its proxy
// covers (view-aligned slices: a cube about the volume's bounding sphere,
// turned with the view, its side the box's diagonal).
enum class Footprint { VolumeBox, ViewCube };

class RowCosts {
 public:
  // A missing pixel's cost as a fraction of a covered one's.
  static constexpr double kMissWeight = 0.05;

  RowCosts() = default;
  // The rows of a width x height frame of a box of `extent` (centred at the
  // origin, model frame) seen by `camera`; each row's rays sampled at up to
  // `columns` evenly spaced pixels.
  RowCosts(const Camera& camera, glm::dvec3 extent, int width, int height,
           Footprint footprint = Footprint::VolumeBox, int columns = 32);

  bool empty() const { return height_ == 0; }
  int height() const { return height_; }
  // The weight of a row counted from the bottom: its pixels, each 1 when
  // its ray enters the footprint and kMissWeight when it misses.
  double row(int fromBottom) const;
  // The weight of the rows between fractions `from` and `to` of the height,
  // from the bottom (row edges at round(fraction x height), as
  // gpu::RegionScope draws them).
  double weight(double from, double to) const;
  // The fraction up to which the rows from `from` weigh about `w`: whole
  // rows, at least one, at most up to the top (1).
  double reach(double from, double w) const;

 private:
  int edge(double fraction) const;  // the row edge at round(fraction x height)
  int height_ = 0;
  std::vector<double> prefix_;  // prefix_[r]: the weight of rows [0, r)
};

}  // namespace tessera::render
