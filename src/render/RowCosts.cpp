#include "tessera/render/RowCosts.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "tessera/core/Error.h"
#include "tessera/reference/ReferenceRaycaster.h"

namespace tessera::render {

RowCosts::RowCosts(const Camera& camera, glm::dvec3 extent, int width, int height,
                   Footprint footprint, int columns) {
  if (width <= 0 || height <= 0 || columns <= 0) {
    throw InputError("row costs of a " + std::to_string(width) + "x" + std::to_string(height) +
                     " frame sampled at " + std::to_string(columns) + " columns");
  }
  const int n = std::min(columns, width);
  // The view cube's frame: the camera's basis, its side the box's diagonal.
  const glm::dmat3 toView = glm::transpose(camera.basis());
  const glm::dvec3 cube(glm::length(extent));
  height_ = height;
  prefix_.assign(static_cast<std::size_t>(height) + 1, 0.0);
  for (int r = 0; r < height; ++r) {
    const int py = height - 1 - r;  // Camera::pixelRay counts rows from the top
    int hits = 0;
    for (int c = 0; c < n; ++c) {
      const int px = std::min(width - 1, static_cast<int>((c + 0.5) * width / n));
      const Ray ray = camera.pixelRay(px, py, width, height);
      // Texture space, t in world units, as the ray caster and the reference.
      const auto [enter, leave] =
          footprint == Footprint::VolumeBox
              ? unitBoxSpan(ray.origin / extent + 0.5, ray.direction / extent)
              : unitBoxSpan(toView * ray.origin / cube + 0.5, toView * ray.direction / cube);
      hits += enter < leave;
    }
    const double hitShare = static_cast<double>(hits) / n;
    prefix_[static_cast<std::size_t>(r) + 1] =
        prefix_[static_cast<std::size_t>(r)] +
        width * (kMissWeight + (1.0 - kMissWeight) * hitShare);
  }
}

double RowCosts::row(int fromBottom) const {
  const auto r = static_cast<std::size_t>(std::clamp(fromBottom, 0, height_ - 1));
  return prefix_[r + 1] - prefix_[r];
}

int RowCosts::edge(double fraction) const {
  return std::clamp(static_cast<int>(std::lround(fraction * height_)), 0, height_);
}

double RowCosts::weight(double from, double to) const {
  const int a = edge(from), b = edge(to);
  return b > a ? prefix_[static_cast<std::size_t>(b)] - prefix_[static_cast<std::size_t>(a)] : 0.0;
}

double RowCosts::reach(double from, double w) const {
  const int start = edge(from);
  if (start >= height_) return 1.0;
  const double goal = prefix_[static_cast<std::size_t>(start)] + w;
  // The first row end whose prefix reaches the goal, at least one row on.
  const auto it = std::lower_bound(prefix_.begin() + start + 1, prefix_.end(), goal);
  const auto end = it == prefix_.end() ? height_ : static_cast<int>(it - prefix_.begin());
  return static_cast<double>(end) / height_;
}

}  // namespace tessera::render
