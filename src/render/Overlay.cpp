#include "tessera/render/Overlay.h"

#include <array>
#include <cstdio>
#include <sstream>

#include "tessera/core/Error.h"

namespace tessera::render {

void addBoxEdges(std::vector<OverlayLine>& out, glm::dvec3 lo, glm::dvec3 hi, glm::vec4 color) {
  auto corner = [&](int i) {
    return glm::dvec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
  };
  for (int i = 0; i < 8; ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      const int bit = 1 << axis;
      if (i & bit) continue;
      out.push_back({corner(i), corner(i | bit), color});
    }
  }
}

OverlayOptions OverlayOptions::parse(const std::string& list) {
  OverlayOptions o;
  if (list.empty() || list == "none") return o;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item == "box")
      o.box = true;
    else if (item == "axes")
      o.axes = true;
    else if (item == "roi")
      o.roi = true;
    else
      throw InputError("--overlays '" + list + "': unknown overlay '" + item +
                       "' (expected a comma-separated subset of box, axes, roi, or none)");
  }
  return o;
}

void OverlayOptions::setRoiVoxels(const std::string& spec, const Volume& volume) {
  std::array<int, 6> v{};
  char tail = 0;
  if (std::sscanf(spec.c_str(), "%d:%d,%d:%d,%d:%d%c", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5],
                  &tail) != 6) {
    throw InputError("--roi '" + spec + "': expected x0:x1,y0:y1,z0:z1 in voxels");
  }
  const glm::ivec3 d = volume.dims();
  for (int axis = 0; axis < 3; ++axis) {
    const int lo = v[2 * axis], hi = v[2 * axis + 1];
    if (lo < 0 || hi > d[axis] || lo >= hi) {
      throw InputError("--roi '" + spec + "': axis " + std::string(1, "xyz"[axis]) + " range " +
                       std::to_string(lo) + ":" + std::to_string(hi) +
                       " is not within 0:" + std::to_string(d[axis]) + " (or is empty)");
    }
    roiMin[axis] = static_cast<double>(lo) / d[axis];
    roiMax[axis] = static_cast<double>(hi) / d[axis];
  }
  roi = true;
}

std::string OverlayOptions::describe() const {
  std::string s;
  if (box) s += "box";
  if (axes) s += std::string(s.empty() ? "" : ",") + "axes";
  if (roi) s += std::string(s.empty() ? "" : ",") + "roi";
  return s.empty() ? "none" : s;
}

std::vector<OverlayLine> overlayLines(const Volume& volume, const OverlayOptions& options) {
  std::vector<OverlayLine> lines;
  const glm::dvec3 half = 0.5 * volume.extent();
  if (options.box) addBoxEdges(lines, -half, half, glm::vec4(1.0f, 1.0f, 1.0f, 1.0f));
  if (options.axes) {
    // From the centre outwards, so that each axis runs inside the volume and
    // leaves it: the case of a line through the volume, which an opacity
    // image of the whole ray cannot attenuate correctly (Moser & Weiskopf).
    const std::array<glm::vec4, 3> colors{glm::vec4(1.0f, 0.15f, 0.15f, 1.0f),
                                          glm::vec4(0.2f, 1.0f, 0.2f, 1.0f),
                                          glm::vec4(0.3f, 0.45f, 1.0f, 1.0f)};
    for (int axis = 0; axis < 3; ++axis) {
      glm::dvec3 end(0.0);
      end[axis] = 1.3 * half[axis];
      lines.push_back({glm::dvec3(0.0), end, colors[static_cast<std::size_t>(axis)]});
    }
  }
  if (options.roi) {
    const glm::dvec3 extent = volume.extent();
    addBoxEdges(lines, (options.roiMin - 0.5) * extent, (options.roiMax - 0.5) * extent,
                glm::vec4(1.0f, 0.85f, 0.1f, 1.0f));
  }
  return lines;
}

}  // namespace tessera::render
