#include "tessera/io/NrrdGeometry.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "io/HeaderText.h"
#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"

namespace tessera {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

using io_detail::numberString;

std::string vectorString(const std::vector<double>& v) {
  std::string s = "(";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? "," : "") + numberString(v[i]);
  return s + ")";
}

// Teem's nrrdSpace names and their abbreviations (enumsNrrd.c).
enum class Frame { Ras, Las, Lps, Unnamed };

std::optional<Frame> frameOf(const std::string& space) {
  const std::string s = lower(space);
  if (s == "right-anterior-superior" || s == "ras") return Frame::Ras;
  if (s == "left-anterior-superior" || s == "las") return Frame::Las;
  if (s == "left-posterior-superior" || s == "lps") return Frame::Lps;
  if (s == "scanner-xyz" || s == "3d-right-handed" || s == "3d-left-handed") {
    return Frame::Unnamed;
  }
  return std::nullopt;
}

glm::dmat3 toRas(Frame f) {
  switch (f) {
    case Frame::Las:
      return glm::dmat3(glm::dvec3(-1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1));
    case Frame::Lps:
      return lpsToRas();
    case Frame::Ras:
    case Frame::Unnamed:
      break;
  }
  return glm::dmat3(1.0);
}

glm::dvec3 spatialVector(const std::vector<double>& v, const std::string& field,
                         const std::string& what) {
  if (v.size() != 3) {
    throw InputError(what + ": " + field + " " + vectorString(v) + " has " +
                     std::to_string(v.size()) + " components; Tessera reads 3-D spaces");
  }
  for (double x : v) {
    if (!std::isfinite(x)) {
      throw InputError(what + ": " + field + " " + vectorString(v) +
                       " is not finite (unknown); expected 3 numbers");
    }
  }
  return {v[0], v[1], v[2]};
}

std::string sourceText(const NrrdGeometryFields& h, Frame frame) {
  if (!h.hasSpaceDirections) {
    return "NRRD spacings only (no space directions: axes along R, A, S)";
  }
  const std::string name = h.space.empty() ? "space dimension 3" : h.space;
  switch (frame) {
    case Frame::Ras:
      return "NRRD space directions (" + name + ")";
    case Frame::Las:
    case Frame::Lps:
      return "NRRD space directions (" + name + ", converted to RAS)";
    case Frame::Unnamed:
      break;
  }
  return "NRRD space directions (" + name + ": no patient frame, taken as RAS)";
}

}  // namespace

glm::dmat3 nrrdSpaceToRas(const std::string& space, const std::string& what) {
  if (const auto f = frameOf(space)) return toRas(*f);
  const std::string s = lower(space);
  if (s.size() > 5 && s.compare(s.size() - 5, 5, "-time") == 0) {
    throw InputError(what + ": space '" + space +
                     "' is a space-time; Tessera reads 3-D spaces (e.g. right-anterior-superior)");
  }
  throw InputError(what + ": space '" + space +
                   "' is not a NRRD 3-D space; expected right-anterior-superior, "
                   "left-anterior-superior, left-posterior-superior (or RAS, LAS, LPS), "
                   "scanner-xyz, 3D-right-handed or 3D-left-handed");
}

NrrdGeometry nrrdGeometry(const NrrdGeometryFields& h, const std::string& what) {
  Frame frame = Frame::Unnamed;
  if (!h.space.empty()) {
    nrrdSpaceToRas(h.space, what);  // throws for the spaces we cannot place
    frame = *frameOf(h.space);
  } else if (h.spaceDimension != 0 && h.spaceDimension != 3) {
    throw InputError(what + ": space dimension is " + std::to_string(h.spaceDimension) +
                     "; Tessera reads 3-D spaces");
  }
  const glm::dmat3 m = toRas(frame);

  glm::dmat4 affine(1.0);
  if (h.hasSpaceDirections) {
    if (h.spaceDirections.size() != 3) {
      throw InputError(what + ": 'space directions' gives " +
                       std::to_string(h.spaceDirections.size()) + " spatial axes, expected 3");
    }
    for (int a = 0; a < 3; ++a) {
      const std::string axis = "axis " + std::to_string(h.firstAxis + a);
      const auto& dir = h.spaceDirections[static_cast<std::size_t>(a)];
      if (!dir) throw InputError(what + ": space direction of spatial " + axis + " is 'none'");
      const glm::dvec3 d = spatialVector(*dir, "space direction of " + axis, what);
      // §5 "space directions": the vector's length is the sample spacing.
      if (!(glm::length(d) > 0.0)) {
        throw InputError(what + ": length of space direction of " + axis + " is " +
                         numberString(glm::length(d)) + ", expected a finite value > 0");
      }
      affine[a] = glm::dvec4(m * d, 0.0);
    }
  } else {
    for (int a = 0; a < 3; ++a) {
      const double s = h.spacings[a];
      if (!std::isfinite(s) || s <= 0.0) {
        throw InputError(what + ": spacing of axis " + std::to_string(h.firstAxis + a) + " is " +
                         numberString(s) + ", expected a finite value > 0");
      }
      affine[a][a] = s;
    }
  }
  if (h.spaceOrigin) {
    affine[3] = glm::dvec4(m * spatialVector(*h.spaceOrigin, "space origin", what), 1.0);
  }
  glm::dmat3 unit;
  for (int a = 0; a < 3; ++a) unit[a] = glm::normalize(glm::dvec3(affine[a]));
  if (std::abs(glm::determinant(unit)) < 1e-6) {
    throw InputError(what + ": space directions are (nearly) parallel; the voxels would lie " +
                     "in a plane");
  }
  return {affine, sourceText(h, frame)};
}

}  // namespace tessera
