#pragma once
// The world frame of every volume: patient coordinates in millimetres, RAS+
// (as NIfTI and nibabel): +x towards the patient's Right, +y Anterior,
// +z Superior. Formats that use LPS+ (DICOM, ITK/MetaImage, NRRD
// "left-posterior-superior") are converted at the reader/writer boundary by
// negating x and y; nothing above `io` ever sees LPS numbers.
//
// A volume's geometry is its index -> world affine, for voxel centres:
//   world = direction * diag(spacing) * index + origin
// where `direction`'s column a is the unit world direction in which index a
// grows. Orientation codes follow nibabel's aff2axcodes: the letter says
// where each index axis points ("RAS": i -> Right, j -> Anterior,
// k -> Superior; "LPI": i -> Left, j -> Posterior, k -> Inferior).
#include <string>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace tessera {

// diag(-1, -1, 1): maps LPS coordinates to RAS and back (its own inverse).
glm::dmat3 lpsToRas();

// How the index axes lie in the patient frame.
struct Orientation {
  std::string code;            // nearest axis code, e.g. "RAS", "LPI"
  bool oblique = false;        // some axis is more than 1e-3 degrees off its code
  double maxObliqueDeg = 0.0;  // largest angle between an axis and its code's axis
  double shearDeg = 0.0;       // largest deviation of an axis pair from 90 degrees
  // "RAS", or "oblique (nearest LPS, 12.5 deg off)" for `info`.
  std::string describe() const;
};

// Orientation of a direction matrix (columns = index axes in RAS).
// Each index axis gets the letter of the world axis it is closest to, chosen
// so that no two index axes share a world axis (as nibabel's io_orientation).
Orientation orientationOf(const glm::dmat3& direction);

// The orthonormal frame nearest to `direction` (polar decomposition). Equals
// `direction` when its columns are already orthonormal (also with a
// reflection); for sheared (gantry-tilted) frames it is the rotation the
// renderer uses, which `info` and `render` report.
glm::dmat3 nearestOrthonormal(const glm::dmat3& direction);

// Letter of a unit direction's dominant world axis: R/L, A/P, S/I.
char directionLetter(const glm::dvec3& worldDirection);

// Letters of a (not necessarily axis-aligned) direction: its dominant axis
// first, then any other axis that contributes more than ~0.38 (22.5 deg),
// e.g. "L", "LA", "SPR". Used for orientation labels on screen edges.
std::string directionLabel(const glm::dvec3& worldDirection);

}  // namespace tessera
