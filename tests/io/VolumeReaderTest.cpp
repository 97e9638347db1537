#include "tessera/io/VolumeReader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "io/IoFixtures.h"
#include "tessera/core/Error.h"
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/io/NrrdReader.h"
#include "tessera/io/NrrdWriter.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/PvmReader.h"
#include "tessera/io/PvmWriter.h"
#include "tessera/io/RawSidecarReader.h"
#include "tessera/io/RawSidecarWriter.h"

namespace tessera {
namespace {

TEST(VolumeReader, DispatchesOnExtensionAndGeneratorSpecs) {
  test::TempDir dir;
  const Volume sphere = makeSphere({8, 8, 8});
  writeNrrd(sphere, dir / "s.nrrd");
  const Volume fromNrrd = readVolume((dir / "s.nrrd").string());
  EXPECT_EQ(fromNrrd.dims(), glm::ivec3(8));
  EXPECT_EQ(fromNrrd.valueAt(4, 4, 4), sphere.valueAt(4, 4, 4));

  test::NiftiFields f;
  test::writeFile(dir / "n.nii.gz",
                  test::gzipBytes(test::niftiHeader(f) + std::string(24, '\x05')));
  EXPECT_EQ(readVolume((dir / "n.nii.gz").string()).valueAt(3, 2, 1), 5.0);

  EXPECT_EQ(readVolume("gen:sphere:12").dims(), glm::ivec3(12));
}

TEST(VolumeReader, FindsRawSidecarsAndDicomFilesWithoutExtension) {
  test::TempDir dir;
  const Volume phantom = makeSheppLogan({9, 7, 5});
  // data.raw + data.json: the sidecar names the data file.
  writeRawWithSidecar(phantom, dir / "data.raw");
  std::filesystem::rename(dir / "data.raw.json", dir / "data.json");
  const Volume raw = readVolume((dir / "data.json").string());
  ASSERT_EQ(raw.dims(), phantom.dims());
  EXPECT_TRUE(std::equal(raw.bytes().begin(), raw.bytes().end(), phantom.bytes().begin()));

  // Scanners often write DICOM files with no extension at all.
  writeDicomSeries(phantom, dir / "series");
  const auto first = std::filesystem::directory_iterator(dir / "series")->path();
  const auto bare = dir / "series" / "IM0001";
  std::filesystem::rename(first, bare);
  const Volume dicom = readVolume(bare.string());
  ASSERT_EQ(dicom.dims(), phantom.dims());
  EXPECT_EQ(dicom.valueAt(4, 3, 2), phantom.valueAt(4, 3, 2));
}

TEST(VolumeReader, RejectsUnknownMissingAndDirectories) {
  test::TempDir dir;
  test::writeFile(dir / "v.xyz", "hello");
  test::expectRejected<InputError>([&] { readVolume((dir / "v.xyz").string()); },
                                   {"v.xyz", "unknown volume format"});
  test::expectRejected<InputError>([&] { readVolume((dir / "none.nii").string()); },
                                   {"none.nii", "no such file"});
  test::expectRejected<InputError>([&] { readVolume(dir.path().string()); }, {"is a directory"});
}

}  // namespace
}  // namespace tessera
