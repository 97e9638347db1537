#pragma once
// Where a NRRD header puts its voxels in the world: the "space", "space
// directions" and "space origin" fields (Teem's NRRD format definition,
// teem.sourceforge.net/nrrd/format.html §4 "space" and §5 per-axis fields)
// -> index-to-world affine in Tessera's RAS+ frame (core/PatientFrame.h).
// Used by io/NrrdReader; pure arithmetic, no file access.
//
// Spaces: right-anterior-superior (RAS) is ours; left-anterior-superior (LAS)
// negates x; left-posterior-superior (LPS, DICOM's, what ITK and Slicer
// write) negates x and y. scanner-xyz, 3D-right-handed, 3D-left-handed and a
// bare "space dimension: 3" name no patient frame: their coordinates are
// taken as RAS unchanged, as Slicer's vtkTeemNRRDReader does (its
// ExecuteInformation converts only RAS/LAS/LPS and leaves other spaces as
// they are); ITK's NrrdImageIO leaves them unchanged in *its* LPS frame
// instead, so such files differ by diag(-1,-1,1) between the two.
#include <optional>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace tessera {

// The spatial part of a NRRD header, as decoded by a reader.
struct NrrdGeometryFields {
  std::string space;       // the "space" value, "" when the field is absent
  int spaceDimension = 0;  // the "space dimension" value, 0 when absent
  bool hasSpaceDirections = false;
  // "space directions" of the three spatial axes in index order; nullopt
  // for a "none" entry (which a spatial axis must not have).
  std::vector<std::optional<std::vector<double>>> spaceDirections;
  std::optional<std::vector<double>> spaceOrigin;
  // "spacings" of the three spatial axes (1 when absent), used only without
  // space directions.
  glm::dvec3 spacings{1.0};
  // File axis number of the first spatial axis, for messages (1 when a
  // size-1 non-spatial axis comes first).
  int firstAxis = 0;
};

struct NrrdGeometry {
  glm::dmat4 indexToWorld{1.0};
  // For `tessera info`, e.g. "NRRD space directions (left-posterior-superior,
  // converted to RAS)".
  std::string source;
};

// The frame a "space" value names, as the matrix that takes its coordinates
// to RAS (its own inverse). Full names are matched without regard to case,
// abbreviations as Teem spells them ("RAS", "LAS", "LPS"). InputError for
// space-time and unknown spaces.
glm::dmat3 nrrdSpaceToRas(const std::string& space, const std::string& what);

// The affine, validated: every spatial axis has a finite, non-zero direction
// of the space's dimension (3), the directions are independent, and the
// origin has 3 finite components. Without space directions: the spacings
// along RAS axes. InputError messages start with `what` (the file name).
NrrdGeometry nrrdGeometry(const NrrdGeometryFields& h, const std::string& what);

}  // namespace tessera
