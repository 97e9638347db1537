// The NIfTI header -> affine maths (io/NiftiGeometry) against nifticlib's
// own qto_xyz / sto_xyz, and the choice between them against nibabel's
// get_best_affine rules.
#include "tessera/io/NiftiGeometry.h"

#include <gtest/gtest.h>
#include <nifti2_io.h>

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "io/GeometryFixtures.h"
#include "io/IoFixtures.h"
#include "tessera/io/NiftiReader.h"

namespace tessera {
namespace {

using test::NiftiFields;
using test::TempDir;

glm::dmat4 fromNifti(const nifti_dmat44& m) {
  glm::dmat4 g;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) g[c][r] = m.m[r][c];
  }
  return g;
}

struct NiftiImageFree {
  void operator()(nifti_image* nim) const { nifti_image_free(nim); }
};

TEST(NiftiGeometry, QformMatchesNifticlibForRandomQuaternionsAndQfac) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> size(0.2, 4.0);
  for (int i = 0; i < 500; ++i) {
    NiftiGeometryFields h;
    // A fifth of them have |(b, c, d)| > 1, which nifticlib renormalises.
    const double scale = i % 5 == 0 ? 1.5 : 0.57;
    h.quaternB = unit(rng) * scale;
    h.quaternC = unit(rng) * scale;
    h.quaternD = unit(rng) * scale;
    h.qoffset = {unit(rng) * 100, unit(rng) * 100, unit(rng) * 100};
    h.pixdim = {i % 2 == 0 ? 1.0 : -1.0, size(rng), size(rng), size(rng)};
    const glm::dmat4 expected = fromNifti(
        nifti_quatern_to_dmat44(h.quaternB, h.quaternC, h.quaternD, h.qoffset.x, h.qoffset.y,
                                h.qoffset.z, h.pixdim[1], h.pixdim[2], h.pixdim[3], h.pixdim[0]));
    test::expectAffineNear(niftiQformAffine(h), expected, 1e-12);
  }
}

TEST(NiftiGeometry, BaseAffineIsNibabelsCentredXFlippedDefault) {
  // nibabel: shape_zoom_affine((3, 5, 7), (3, 2, 1)) = [[-3,0,0,3], [0,2,0,-4], [0,0,1,-3]].
  NiftiGeometryFields h;
  h.dim = {3, 5, 7};
  h.pixdim = {1, 3, 2, 1};
  glm::dmat4 expected(1.0);
  expected[0][0] = -3;
  expected[1][1] = 2;
  expected[2][2] = 1;
  expected[3] = glm::dvec4(3, -4, -3, 1);
  test::expectAffineNear(niftiBaseAffine(h), expected, 0.0);
  const NiftiGeometry g = niftiGeometry(h);
  test::expectAffineNear(g.indexToWorld, expected, 0.0);
  EXPECT_NE(g.source.find("pixdim only"), std::string::npos) << g.source;
}

TEST(NiftiGeometry, AnalyzeUsesSpmOriginWhenNibabelWould) {
  // nibabel's Spm99AnalyzeHeader.get_origin_affine docstring: shape (3, 5, 7),
  // zooms (3, 2, 1), origin [3, 4, 5] -> translations (6, -6, -4).
  NiftiGeometryFields h;
  h.version = 0;
  h.dim = {3, 5, 7};
  h.pixdim = {0, 3, 2, 1};
  h.spmOrigin = {3, 4, 5};
  EXPECT_EQ(glm::dvec3(niftiGeometry(h).indexToWorld[3]), glm::dvec3(6, -6, -4));
  h.spmOrigin = {3, 4, 99};  // outside (-dim, 2 * dim): the centre instead
  EXPECT_EQ(glm::dvec3(niftiGeometry(h).indexToWorld[3]), glm::dvec3(3, -4, -3));
}

TEST(NiftiGeometry, PrefersSformThenQformAsNibabelAndNamesTheCode) {
  NiftiGeometryFields h;
  h.dim = {4, 4, 4};
  h.sformCode = 4;
  h.srow = {{
      {-1, 0, 0, 90},
      {0, 1, 0, -126},
      {0, 0, 1, -72},
  }};
  h.qformCode = 1;
  h.qoffset = {5, 6, 7};
  NiftiGeometry g = niftiGeometry(h);
  EXPECT_EQ(g.source, "NIfTI sform (code 4: MNI_152)");
  EXPECT_EQ(glm::dvec3(g.indexToWorld[3]), glm::dvec3(90, -126, -72));
  h.sformCode = 0;
  g = niftiGeometry(h);
  EXPECT_EQ(g.source, "NIfTI qform (code 1: scanner)");
  EXPECT_EQ(glm::dvec3(g.indexToWorld[3]), glm::dvec3(5, 6, 7));
  // A singular sform is skipped for the qform, and said so.
  h.sformCode = 2;
  h.srow = {};
  g = niftiGeometry(h);
  EXPECT_EQ(glm::dvec3(g.indexToWorld[3]), glm::dvec3(5, 6, 7));
  EXPECT_NE(g.source.find("sform (code 2: aligned) is singular, ignored"), std::string::npos)
      << g.source;
}

TEST(NiftiGeometry, WriterCodeKeepsANiftiSourcesCode) {
  EXPECT_EQ(niftiXformCodeFor("NIfTI sform (code 4: MNI_152)"), 4);
  EXPECT_EQ(niftiXformCodeFor("NIfTI qform (code 3: Talairach)"), 3);
  EXPECT_EQ(niftiXformCodeFor("NIfTI sform (code 9: not a NIfTI code)"), 1);
  EXPECT_EQ(niftiXformCodeFor("NRRD space directions (left-posterior-superior)"), 1);
  EXPECT_EQ(niftiXformCodeFor(""), 1);
}

// Hand-built NIfTI-1 and NIfTI-2 files read by readNifti and by nifticlib:
// the affine is nifticlib's sto_xyz when sform_code > 0, else its qto_xyz.
TEST(NiftiReader, AffineIsNifticlibsStoXyzOrQtoXyz) {
  TempDir dir;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < 40; ++i) {
    NiftiFields f;
    f.version = i % 2 == 0 ? 1 : 2;
    f.pixdim[0] = i % 3 == 0 ? -1 : 1;
    for (int a = 1; a <= 3; ++a) f.pixdim[a] = 0.5 + (unit(rng) + 1.0);
    for (double& q : f.quatern) q = unit(rng) * 0.57;
    for (double& o : f.qoffset) o = unit(rng) * 100;
    f.qformCode = i % 4 == 3 ? 0 : 1 + i % 5;
    f.sformCode = i % 4 == 1 ? 0 : 2;
    for (auto& row : f.srow) {
      for (double& x : row) x = unit(rng) * 3;
    }
    std::string name = "h";  // built piecewise: GCC 12 warns falsely on "h" + string
    name += std::to_string(i);
    name += ".nii";
    const auto path = dir / name;
    test::writeFile(path, test::niftiHeader(f) + std::string(24, '\x05'));
    SCOPED_TRACE("file " + std::to_string(i) + ", NIfTI-" + std::to_string(f.version) +
                 ", qform_code " + std::to_string(f.qformCode) + ", sform_code " +
                 std::to_string(f.sformCode));

    nifti_set_debug_level(0);
    std::unique_ptr<nifti_image, NiftiImageFree> nim(nifti_image_read(path.c_str(), 0));
    ASSERT_TRUE(nim);
    const Volume v = readNifti(path);
    if (f.sformCode > 0) {
      test::expectAffineNear(v.indexToWorld(), fromNifti(nim->sto_xyz), 1e-12);
    } else if (f.qformCode > 0) {
      test::expectAffineNear(v.indexToWorld(), fromNifti(nim->qto_xyz), 1e-12);
    } else {
      ADD_FAILURE() << "every case has a form";
    }
  }
}

}  // namespace
}  // namespace tessera
