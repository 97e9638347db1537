// NIfTI and ANALYZE files written by nibabel (an independent writer) read
// with nibabel's affine, and files written by writeNifti read back by
// nibabel with ours. Skipped when Debian's python3 has no nibabel.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/GeometryFixtures.h"
#include "support/Nibabel.h"
#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/io/NiftiReader.h"
#include "tessera/io/NiftiWriter.h"

namespace tessera {
namespace {

using test::TempDir;

// Writes one file per case into argv[1] and prints {name: affine rows}.
// Voxel (i, j, k) holds (i + 2j + 3k) % 251, stored i-fastest as NIfTI says.
constexpr const char* kWriteCases = R"PY(
import json, sys
import numpy as np
import nibabel as nib
out = sys.argv[1]
shape = (5, 4, 3)
i, j, k = np.indices(shape)
data = ((i + 2 * j + 3 * k) % 251).astype(np.uint8)

def rot(axis, deg):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    a = np.radians(deg)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K

def affine(R, zooms, origin):
    A = np.eye(4)
    A[:3, :3] = R @ np.diag(zooms)
    A[:3, 3] = origin
    return A

oblique = affine(rot([1, 2, 3], 25), [0.75, 1.25, 2.5], [-40.5, 12.25, 30.125])
reflected = oblique.copy(); reflected[:3, 0] *= -1
las = affine(np.eye(3), [2.0, 2.0, 2.2], [0, 0, 0]); las[0, 0] = -2.0
las[:3, 3] = [98.5, -134.25, -72.0]
result = {}

def save(name, img):
    nib.save(img, out + '/' + name)
    back = nib.load(out + '/' + name)
    result[name] = {'affine': back.affine.tolist(),
                    'axcodes': ''.join(nib.aff2axcodes(back.affine))}

# sform != qform, both coded: the sform wins.
img = nib.Nifti1Image(data, None)
img.header.set_qform(oblique, code=1)
img.header.set_sform(affine(rot([0, 0, 1], -30), [1.5, 1.5, 3.0], [10.5, -20.25, 5.0]), code=4)
save('sform_and_qform.nii', img)
# sform_code 0: the qform, here a left-handed frame (qfac -1).
img = nib.Nifti1Image(data, None)
img.header.set_qform(reflected, code=1)
img.header.set_sform(np.diag([9, 9, 9, 1]), code=0)
save('qform_only.nii', img)
# both codes 0: nibabel's centred, x-flipped pixdim affine.
img = nib.Nifti1Image(data, None)
img.header.set_zooms((2.0, 3.0, 4.0))
img.header.set_qform(None, code=0)
img.header.set_sform(None, code=0)
save('no_forms.nii', img)
# LAS storage, as FSL/MNI atlases and nibabel's tests/data/anatomical.nii.
save('las.nii.gz', nib.Nifti1Image(data, las))
save('nifti2.nii', nib.Nifti2Image(data, oblique))
# ANALYZE 7.5 pairs: SPM's origin, and none.
hdr = nib.Spm2AnalyzeHeader(); hdr.set_data_shape(shape); hdr.set_zooms((2, 3, 4))
hdr['origin'][:3] = [2, 1, 3]
save('spm.hdr', nib.Spm2AnalyzeImage(data, None, hdr))
hdr = nib.AnalyzeHeader(); hdr.set_data_shape(shape); hdr.set_zooms((2, 3, 4))
save('analyze.hdr', nib.AnalyzeImage(data, None, hdr))
print(json.dumps(result))
)PY";

// Loads argv[1] and prints its affines, codes, axis codes and whether its
// data equal the pattern above.
constexpr const char* kReadBack = R"PY(
import json, sys
import numpy as np
import nibabel as nib
img = nib.load(sys.argv[1])
h = img.header
shape = img.shape
i, j, k = np.indices(shape)
print(json.dumps({'affine': img.affine.tolist(),
                  'qform': h.get_qform().tolist(),
                  'codes': [int(h['sform_code']), int(h['qform_code'])],
                  'axcodes': ''.join(nib.aff2axcodes(img.affine)),
                  'data_equal': bool(np.array_equal(np.asarray(img.dataobj),
                                                    (i + 2 * j + 3 * k) % 251))}))
)PY";

double patternValue(int i, int j, int k) {
  return (i + 2 * j + 3 * k) % 251;
}

void expectPattern(const Volume& v) {
  ASSERT_EQ(v.dims(), glm::ivec3(5, 4, 3));
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 4; ++j) {
      for (int i = 0; i < 5; ++i) ASSERT_EQ(v.valueAt(i, j, k), patternValue(i, j, k));
    }
  }
}

TEST(NiftiNibabel, FilesNibabelWritesReadWithNibabelsAffineAndVoxelsAsStored) {
  if (const auto why = test::nibabelMissing()) GTEST_SKIP() << *why;
  TempDir dir;
  const auto cases = nlohmann::json::parse(test::runPython(dir, kWriteCases, dir.path().string()));
  ASSERT_EQ(cases.size(), 7u);
  const std::pair<const char*, const char*> expectedSource[] = {
      {"sform_and_qform.nii", "NIfTI sform (code 4: MNI_152)"},
      {"qform_only.nii", "NIfTI qform (code 1: scanner)"},
      {"no_forms.nii", "NIfTI pixdim only"},
      {"las.nii.gz", "NIfTI sform (code 2: aligned)"},
      {"nifti2.nii", "NIfTI sform (code 2: aligned)"},
      {"spm.hdr", "SPM origin"},
      {"analyze.hdr", "ANALYZE 7.5 pixdim only"}};
  for (const auto& [name, source] : expectedSource) {
    SCOPED_TRACE(name);
    const auto& c = cases.at(name);
    const Volume v = readNifti(dir / name);
    test::expectAffineNear(v.indexToWorld(), test::affineFromRows(c.at("affine")), 1e-6);
    EXPECT_EQ(orientationOf(v.direction()).code, c.at("axcodes").get<std::string>());
    EXPECT_NE(v.geometrySource().find(source), std::string::npos) << v.geometrySource();
    expectPattern(v);
  }
  EXPECT_EQ(cases.at("las.nii.gz").at("axcodes"), "LAS");
  EXPECT_EQ(cases.at("qform_only.nii").at("axcodes").get<std::string>().size(), 3u);
}

TEST(NiftiNibabel, AnLasFileWritesBackAsLasWithVoxelsUntouched) {
  if (const auto why = test::nibabelMissing()) GTEST_SKIP() << *why;
  TempDir dir;
  const auto cases = nlohmann::json::parse(test::runPython(dir, kWriteCases, dir.path().string()));
  const Volume las = readNifti(dir / "las.nii.gz");
  writeNifti(las, dir / "las_again.nii");
  const auto back =
      nlohmann::json::parse(test::runPython(dir, kReadBack, (dir / "las_again.nii").string()));
  EXPECT_EQ(back.at("axcodes"), "LAS");
  EXPECT_TRUE(back.at("data_equal").get<bool>()) << "voxels were reordered or changed";
  test::expectAffineNear(test::affineFromRows(back.at("affine")),
                         test::affineFromRows(cases.at("las.nii.gz").at("affine")), 1e-6);
  // The sform's code (2, aligned) is kept; the qform says the same.
  EXPECT_EQ(back.at("codes"), nlohmann::json::array({2, 2}));
  test::expectAffineNear(test::affineFromRows(back.at("qform")),
                         test::affineFromRows(back.at("affine")), 1e-6);
}

TEST(NiftiNibabel, NibabelReadsOurObliqueAndReflectedFramesFromBothForms) {
  if (const auto why = test::nibabelMissing()) GTEST_SKIP() << *why;
  TempDir dir;
  for (const glm::dmat4& affine : {test::obliqueAffine(), test::obliqueReflectedAffine()}) {
    Volume v = Volume::allocate({5, 4, 3}, ScalarType::U8);
    for (int k = 0; k < 3; ++k) {
      for (int j = 0; j < 4; ++j) {
        for (int i = 0; i < 5; ++i) v.setValueAtIndex(v.index(i, j, k), patternValue(i, j, k));
      }
    }
    v.setIndexToWorld(affine);
    writeNifti(v, dir / "ours.nii");
    const auto back =
        nlohmann::json::parse(test::runPython(dir, kReadBack, (dir / "ours.nii").string()));
    SCOPED_TRACE(test::affineText(affine));
    EXPECT_TRUE(back.at("data_equal").get<bool>());
    EXPECT_EQ(back.at("codes"), nlohmann::json::array({1, 1}));  // scanner
    test::expectAffineNear(test::affineFromRows(back.at("affine")), affine, 1e-6);
    // The qform (quaternion + qfac) is the same frame: no shear here.
    test::expectAffineNear(test::affineFromRows(back.at("qform")), affine, 1e-6);
  }
}

// nibabel's own 4-D test files (fMRI time series, one gzipped, one plain):
// each time point is written by nibabel as float64 (scaling applied) for
// the reader's time point to be compared voxel for voxel.
constexpr const char* kTimeSeries = R"PY(
import json, os, sys
import numpy as np
import nibabel as nib
out = sys.argv[1]
data = os.path.join(os.path.dirname(nib.__file__), 'tests', 'data')
result = {}
for name in ('example4d.nii.gz', 'functional.nii'):
    path = os.path.join(data, name)
    if not os.path.exists(path):
        continue
    img = nib.load(path)
    n = img.shape[3]
    points = sorted({0, n // 2, n - 1})
    for t in points:
        np.asarray(img.dataobj[..., t], dtype=np.float64).ravel(order='F').tofile(
            os.path.join(out, '%s.%d.f64' % (name, t)))
    result[name] = {'path': path, 'shape': list(img.shape), 'points': points,
                    'affine': img.affine.tolist()}
print(json.dumps(result))
)PY";

TEST(NiftiNibabel, EachTimePointOfA4DFileIsNibabelsVolumeAtThatTime) {
  if (const auto why = test::nibabelMissing()) GTEST_SKIP() << *why;
  TempDir dir;
  const auto files = nlohmann::json::parse(test::runPython(dir, kTimeSeries, dir.path().string()));
  if (files.empty()) GTEST_SKIP() << "nibabel's test data (example4d.nii.gz) is not installed";
  for (const auto& [name, f] : files.items()) {
    SCOPED_TRACE(name);
    const auto shape = f.at("shape").get<std::vector<int>>();
    ASSERT_EQ(shape.size(), 4u);
    const FileSource file(f.at("path").get<std::string>());
    EXPECT_EQ(niftiTimePoints(file), shape[3]);
    for (const int t : f.at("points").get<std::vector<int>>()) {
      SCOPED_TRACE("time point " + std::to_string(t));
      const Volume v = readNifti(file, FolderFiles(), t);
      ASSERT_EQ(v.dims(), glm::ivec3(shape[0], shape[1], shape[2]));
      test::expectAffineNear(v.indexToWorld(), test::affineFromRows(f.at("affine")), 1e-5);
      EXPECT_NE(v.description().find("time point " + std::to_string(t) + " of " +
                                     std::to_string(shape[3])),
                std::string::npos)
          << v.description();
      std::ifstream in(dir / (name + "." + std::to_string(t) + ".f64"), std::ios::binary);
      std::vector<double> expected(v.voxelCount());
      in.read(reinterpret_cast<char*>(expected.data()),
              static_cast<std::streamsize>(expected.size() * sizeof(double)));
      ASSERT_TRUE(in) << "nibabel's time point is missing";
      std::size_t differing = 0;
      for (std::size_t i = 0; i < expected.size(); ++i) {
        if (std::abs(v.valueAtIndex(i) - expected[i]) > 1e-4 * (1.0 + std::abs(expected[i]))) {
          ++differing;
        }
      }
      EXPECT_EQ(differing, 0u);
    }
    // Past the last time point: refused, naming the file and the count.
    try {
      readNifti(file, FolderFiles(), shape[3]);
      ADD_FAILURE() << "time point " << shape[3] << " was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(
                    f.at("path").get<std::string>() + ": time point " + std::to_string(shape[3]) +
                    " asked for, but the file holds " + std::to_string(shape[3]) +
                    " (time points 0.." + std::to_string(shape[3] - 1) + ")"),
                std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace tessera
