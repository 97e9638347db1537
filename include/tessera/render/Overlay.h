#pragma once
// Overlay lines drawn over a volume rendering: its bounding box, coordinate
// axes and a region-of-interest box (Moser & Weiskopf 2008 draw the box and
// axes at the screen's resolution while the volume is rendered smaller).
// Positions are world coordinates: the volume's box is extent() centred at
// the origin (DESIGN.md, Rendering semantics).
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "tessera/core/Volume.h"

namespace tessera::render {

struct OverlayLine {
  glm::dvec3 a;
  glm::dvec3 b;
  glm::vec4 color;  // opaque RGB (alpha 1)
};

struct OverlayOptions {
  bool box = false;   // the volume's bounding box, white
  bool axes = false;  // x red, y green, z blue from the box centre to 1.3x the half extent
  bool roi = false;   // the region of interest, yellow
  // Region of interest in normalised volume coordinates [0,1]^3.
  glm::dvec3 roiMin{0.3, 0.35, 0.45};
  glm::dvec3 roiMax{0.7, 0.75, 0.8};

  bool any() const { return box || axes || roi; }
  // "box,axes,roi" (any subset, comma separated) or "none"; InputError names
  // an unknown entry.
  static OverlayOptions parse(const std::string& list);
  // "x0:x1,y0:y1,z0:z1" in voxels of `volume` (as `tessera convert --crop`)
  // sets the ROI; InputError when it is malformed or outside the volume.
  void setRoiVoxels(const std::string& spec, const Volume& volume);
  std::string describe() const;  // "box,axes" / "none"
};

// Appends the 12 edges of the axis-aligned box [lo, hi] (world coordinates).
void addBoxEdges(std::vector<OverlayLine>& out, glm::dvec3 lo, glm::dvec3 hi, glm::vec4 color);

// The line segments of the chosen overlays for `volume`.
std::vector<OverlayLine> overlayLines(const Volume& volume, const OverlayOptions& options);

}  // namespace tessera::render
