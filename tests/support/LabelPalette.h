#pragma once
// Label renders checked against their colour table: how many pixels are
// drawn (not the black background) and how many carry a colour that is
// neither the background nor a table colour (within 1 of 255 per channel).
#include <cstdint>
#include <vector>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include "tessera/core/Image.h"
#include "tessera/render/LabelTable.h"

namespace tessera::test {

inline glm::ivec3 rgb8(glm::dvec3 c) {
  return glm::ivec3(glm::round(c * 255.0));
}

struct PaletteCount {
  int drawn = 0;    // pixels other than the black background
  int outside = 0;  // pixels in no table colour and not background
};

inline PaletteCount countAgainstPalette(const Image& img, const render::LabelTable& table) {
  std::vector<glm::ivec3> allowed{glm::ivec3(0)};  // the black background
  for (const auto& [value, label] : table.labels) allowed.push_back(rgb8(label.color));
  PaletteCount n;
  for (int py = 0; py < img.height(); ++py) {
    for (int px = 0; px < img.width(); ++px) {
      const std::uint8_t* q = img.pixel(px, py);
      const glm::ivec3 c(q[0], q[1], q[2]);
      bool found = false;
      for (const glm::ivec3& a : allowed) {
        const glm::ivec3 d = glm::abs(c - a);
        found = found || (d.x <= 1 && d.y <= 1 && d.z <= 1);
      }
      n.outside += found ? 0 : 1;
      n.drawn += c != glm::ivec3(0) ? 1 : 0;
    }
  }
  return n;
}

}  // namespace tessera::test
