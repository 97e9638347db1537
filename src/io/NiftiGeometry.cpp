#include "tessera/io/NiftiGeometry.h"

#include <cmath>
#include <cstdio>

#include <glm/matrix.hpp>

namespace tessera {

namespace {

constexpr const char* kCodeText = "code ";

bool usable(const glm::dmat4& a) {
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 3; ++r) {
      if (!std::isfinite(a[c][r])) return false;
    }
  }
  const glm::dmat3 m(a);
  for (int c = 0; c < 3; ++c) {
    if (glm::length(m[c]) <= 0.0) return false;
  }
  // The same test Volume::setDirection applies to the unit columns.
  glm::dmat3 unit;
  for (int c = 0; c < 3; ++c) unit[c] = m[c] / glm::length(m[c]);
  return std::abs(glm::determinant(unit)) >= 1e-6;
}

std::string formText(const char* form, int code) {
  return std::string("NIfTI ") + form + " (" + kCodeText + std::to_string(code) + ": " +
         niftiXformCodeName(code) + ")";
}

glm::dvec3 absPixdim(const NiftiGeometryFields& h) {
  return {std::fabs(h.pixdim[1]), std::fabs(h.pixdim[2]), std::fabs(h.pixdim[3])};
}

// nibabel's Spm99AnalyzeHeader.get_origin_affine: the SPM origin is used
// when it is set and lies within (-dim, 2 * dim) on every axis.
bool spmOriginUsable(const NiftiGeometryFields& h) {
  bool any = false;
  for (int a = 0; a < 3; ++a) {
    const auto o = static_cast<std::int64_t>(h.spmOrigin[static_cast<std::size_t>(a)]);
    const std::int64_t d = h.dim[static_cast<std::size_t>(a)];
    if (o != 0) any = true;
    if (!(o > -d && o < 2 * d)) return false;
  }
  return any;
}

}  // namespace

glm::dmat4 niftiQformAffine(const NiftiGeometryFields& h) {
  double b = h.quaternB, c = h.quaternC, d = h.quaternD;
  double a = 1.0 - (b * b + c * c + d * d);
  if (a < 1e-7) {
    // Not a unit quaternion's b, c, d: nifticlib (nifti_quatern_to_dmat44)
    // renormalises them and takes a 180 degree rotation (a = 0).
    const double n = 1.0 / std::sqrt(b * b + c * c + d * d);
    b *= n;
    c *= n;
    d *= n;
    a = 0.0;
  } else {
    a = std::sqrt(a);
  }
  const glm::dvec3 s = absPixdim(h);
  const double qfac = h.pixdim[0] < 0.0 ? -1.0 : 1.0;
  const glm::dvec3 scale(s.x, s.y, qfac * s.z);
  // R's rows as the NIfTI-1 header gives them; glm is column-major (m[col][row]).
  const double r[3][3] = {
      {a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)},
      {2 * (b * c + a * d), a * a + c * c - b * b - d * d, 2 * (c * d - a * b)},
      {2 * (b * d - a * c), 2 * (c * d + a * b), a * a + d * d - c * c - b * b}};
  glm::dmat4 m(1.0);
  for (int col = 0; col < 3; ++col) {
    for (int row = 0; row < 3; ++row) m[col][row] = r[row][col] * scale[col];
  }
  m[3] = glm::dvec4(h.qoffset, 1.0);
  return m;
}

glm::dmat4 niftiSformAffine(const NiftiGeometryFields& h) {
  glm::dmat4 m(1.0);
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 4; ++col) {
      m[col][row] = h.srow[static_cast<std::size_t>(row)][static_cast<std::size_t>(col)];
    }
  }
  return m;
}

glm::dmat4 niftiBaseAffine(const NiftiGeometryFields& h) {
  // x_flip: ANALYZE's (and nibabel's) default radiological storage.
  const glm::dvec3 s = absPixdim(h);
  const glm::dvec3 zoom(-s.x, s.y, s.z);
  glm::dvec3 centre;
  const bool spm = h.version == 0 && spmOriginUsable(h);
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    // SPM's origin is a 1-based (MATLAB) voxel index.
    centre[a] = spm ? static_cast<double>(h.spmOrigin[i]) - 1.0
                    : (static_cast<double>(h.dim[i]) - 1.0) / 2.0;
  }
  glm::dmat4 m(1.0);
  for (int a = 0; a < 3; ++a) m[a][a] = zoom[a];
  m[3] = glm::dvec4(-centre * zoom, 1.0);
  return m;
}

NiftiGeometry niftiGeometry(const NiftiGeometryFields& h) {
  if (h.version == 0) {
    return {niftiBaseAffine(h), spmOriginUsable(h)
                                    ? "ANALYZE 7.5 pixdim and SPM origin (x flipped, as nibabel)"
                                    : "ANALYZE 7.5 pixdim only (x flipped, centred, as nibabel)"};
  }
  std::string skipped;
  if (h.sformCode != 0) {
    const glm::dmat4 s = niftiSformAffine(h);
    if (usable(s)) return {s, formText("sform", h.sformCode)};
    skipped = "; " + formText("sform", h.sformCode).substr(6) + " is singular, ignored";
  }
  if (h.qformCode != 0) {
    const glm::dmat4 q = niftiQformAffine(h);
    if (usable(q)) return {q, formText("qform", h.qformCode) + skipped};
    skipped += "; " + formText("qform", h.qformCode).substr(6) + " is not finite, ignored";
  }
  return {niftiBaseAffine(h),
          "NIfTI pixdim only (sform and qform codes 0: x flipped, centred, as nibabel)" + skipped};
}

std::string niftiXformCodeName(int code) {
  switch (code) {
    case 0:
      return "unknown";
    case 1:
      return "scanner";
    case 2:
      return "aligned";
    case 3:
      return "Talairach";
    case 4:
      return "MNI_152";
    case 5:
      return "template";
    default:
      return "not a NIfTI code";
  }
}

int niftiXformCodeFor(const std::string& geometrySource) {
  // Parses what niftiGeometry() wrote: "NIfTI sform (code 4: ...)".
  if (geometrySource.rfind("NIfTI sform (", 0) != 0 &&
      geometrySource.rfind("NIfTI qform (", 0) != 0) {
    return 1;
  }
  int code = 0;
  if (std::sscanf(geometrySource.c_str() + 13, "code %d:", &code) != 1) return 1;
  return code >= 1 && code <= 5 ? code : 1;
}

}  // namespace tessera
