// Every format that can hold an index -> world affine writes one and reads
// it back: an LAS volume with an origin, an oblique rotation, and an oblique
// left-handed frame, through writeVolume/readVolume by file name.
#include <gtest/gtest.h>

#include <string>
#include <tuple>

#include "io/GeometryFixtures.h"
#include "support/TestSupport.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/VolumeWriter.h"

namespace tessera {
namespace {

using test::TempDir;

enum class Frame { Las, Oblique, ObliqueReflected };

glm::dmat4 affineOf(Frame f) {
  switch (f) {
    case Frame::Las:
      return test::lasAffine();
    case Frame::Oblique:
      return test::obliqueAffine();
    case Frame::ObliqueReflected:
      break;
  }
  return test::obliqueReflectedAffine();
}

class GeometryRoundTrip
    : public ::testing::TestWithParam<std::tuple<std::string, Frame, ScalarType>> {};

TEST_P(GeometryRoundTrip, AffineAndVoxelsComeBack) {
  const auto& [extension, frame, type] = GetParam();
  TempDir dir;
  const Volume v = test::volumeWithAffine({6, 5, 4}, type, affineOf(frame));
  const auto path = dir / ("v" + extension);
  writeVolume(v, path);
  const Volume back = readVolume(path.string());
  // NIfTI-1 keeps the affine as float32: ~1e-7 relative on these values.
  test::expectAffineNear(back.indexToWorld(), v.indexToWorld(), 1e-6);
  EXPECT_EQ(orientationOf(back.direction()).code, orientationOf(v.direction()).code);
  test::expectSameVoxels(back, v);
  EXPECT_FALSE(back.geometrySource().empty());
}

std::string paramName(
    const ::testing::TestParamInfo<std::tuple<std::string, Frame, ScalarType>>& info) {
  std::string ext = std::get<0>(info.param);
  std::string name;
  for (char c : ext) name += c == '.' ? '_' : c;
  const char* frames[] = {"Las", "Oblique", "ObliqueReflected"};
  return name.substr(1) + "_" + frames[static_cast<int>(std::get<1>(info.param))] + "_" +
         std::string(scalarTypeName(std::get<2>(info.param)));
}

INSTANTIATE_TEST_SUITE_P(
    Formats, GeometryRoundTrip,
    ::testing::Combine(::testing::Values(".nii", ".nii.gz", ".nrrd", ".mha", ".vti", ".raw"),
                       ::testing::Values(Frame::Las, Frame::Oblique, Frame::ObliqueReflected),
                       ::testing::Values(ScalarType::U8, ScalarType::I16)),
    paramName);

TEST(GeometryLossNotes, PvmNamesTheLostOrientationAndTheOrigin) {
  const Volume las = test::volumeWithAffine({4, 4, 4}, ScalarType::U8, test::lasAffine());
  const auto notes = writeLossNotes(las, "out.pvm");
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("PVM stores spacing only"), std::string::npos) << notes[0];
  EXPECT_NE(notes[0].find("orientation LAS"), std::string::npos) << notes[0];
  EXPECT_NE(notes[0].find("(90.5, -126.25, -72)"), std::string::npos) << notes[0];
}

TEST(GeometryLossNotes, PvmWithOnlyAnOriginSaysWhereItIsKept) {
  Volume v = test::volumeWithAffine({4, 4, 4}, ScalarType::U8, glm::dmat4(1.0));
  v.setOrigin({1.0, 2.0, 3.0});
  const auto notes = writeLossNotes(v, "OUT.PVM");
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("origin (1, 2, 3)"), std::string::npos) << notes[0];
  EXPECT_EQ(notes[0].find("orientation"), std::string::npos) << notes[0];
}

TEST(GeometryLossNotes, EmptyWhenTheFormatHoldsTheAffine) {
  const Volume obl = test::volumeWithAffine({4, 4, 4}, ScalarType::U8, test::obliqueAffine());
  for (const char* out : {"a.nii", "a.nii.gz", "a.nrrd", "a.mha", "a.vti", "a.raw", "dir/"}) {
    EXPECT_TRUE(writeLossNotes(obl, out).empty()) << out;
  }
  const Volume plain = test::volumeWithAffine({4, 4, 4}, ScalarType::U8, glm::dmat4(1.0));
  EXPECT_TRUE(writeLossNotes(plain, "a.pvm").empty());
}

}  // namespace
}  // namespace tessera
