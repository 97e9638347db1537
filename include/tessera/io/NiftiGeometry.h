#pragma once
// Where a NIfTI (or ANALYZE 7.5) header puts its voxels in the world: the
// header fields -> index-to-world affine maths of io/NiftiReader, which the
// tests compare with nifticlib's qto_xyz / sto_xyz and nibabel. Pure
// arithmetic on decoded fields: no file access, no nifticlib.
//
// NIfTI's world frame is RAS+ (nifti1.h, "3D IMAGE (VOLUME) ORIENTATION AND
// LOCATION IN SPACE"), which is Tessera's (core/PatientFrame.h): no
// conversion is needed, and voxels are never reordered.
#include <array>
#include <cstdint>
#include <string>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace tessera {

// The header fields that place the image, decoded from either byte order and
// either header version (NIfTI-1 stores them as float, NIfTI-2 as double).
struct NiftiGeometryFields {
  int version = 1;  // 0 = ANALYZE 7.5 (no qform/sform), 1 = NIfTI-1, 2 = NIfTI-2
  std::array<std::int64_t, 3> dim{1, 1, 1};  // dim[1..3]
  std::array<double, 4> pixdim{1, 1, 1, 1};  // pixdim[0..3]; pixdim[0] is qfac
  int qformCode = 0;
  int sformCode = 0;
  double quaternB = 0.0, quaternC = 0.0, quaternD = 0.0;
  glm::dvec3 qoffset{0.0};
  std::array<std::array<double, 4>, 3> srow{};  // srow_x, srow_y, srow_z
  // ANALYZE 7.5 only: SPM's "origin" (hist.originator as 3 int16, 1-based
  // voxel of the world origin); all zero when unset.
  std::array<int, 3> spmOrigin{0, 0, 0};
};

// The affine a reader should use, and where it came from.
struct NiftiGeometry {
  glm::dmat4 indexToWorld{1.0};
  // For `tessera info`, e.g. "NIfTI sform (code 4: MNI_152)".
  std::string source;
};

// nibabel's Nifti1Header.get_best_affine(): the sform when sform_code != 0,
// else the qform when qform_code != 0, else the pixdim-only base affine. A
// sform that is singular or not finite is skipped (and `source` says so),
// rather than making the file unreadable. ANALYZE headers have neither form:
// they get nibabel's Spm99AnalyzeHeader affine (SPM origin, else centred).
NiftiGeometry niftiGeometry(const NiftiGeometryFields& h);

// The three candidates, exactly as the NIfTI-1 header documents them (and
// nifticlib's qto_xyz / sto_xyz compute them):
// qform = R(quatern) * diag(pixdim[1], pixdim[2], qfac * pixdim[3]) + qoffset,
// with a = sqrt(1 - b^2 - c^2 - d^2) (b, c, d renormalised when that is < 0,
// as nifticlib does), qfac = -1 when pixdim[0] < 0 else 1, and |pixdim|.
glm::dmat4 niftiQformAffine(const NiftiGeometryFields& h);
// sform = the rows srow_x, srow_y, srow_z.
glm::dmat4 niftiSformAffine(const NiftiGeometryFields& h);
// nibabel's shape_zoom_affine(dim, pixdim, x_flip=True): diag(-|pixdim1|,
// |pixdim2|, |pixdim3|) with the volume's centre voxel at world (0, 0, 0);
// with an SPM origin (ANALYZE only, when nibabel would use it) that voxel is
// origin - 1 instead.
glm::dmat4 niftiBaseAffine(const NiftiGeometryFields& h);

// nifti1.h's name for an xform code: 1 "scanner", 2 "aligned", 3
// "Talairach", 4 "MNI_152", 5 "template"; others "not a NIfTI code".
std::string niftiXformCodeName(int code);

// The xform code a writer should give `indexToWorld` for a volume whose
// geometry came from `geometrySource`: the code of the NIfTI sform/qform it
// was read from (so an MNI atlas stays MNI_152 through a round trip), else
// 1 (NIFTI_XFORM_SCANNER_ANAT).
int niftiXformCodeFor(const std::string& geometrySource);

}  // namespace tessera
