// DICOM series reading and writing. Fixtures are written on the fly with
// writeDicomSeries and then damaged through DCMTK, one defect per test.
#include "tessera/io/DicomSeriesReader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcdatset.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcmetinf.h>
#include <dcmtk/dcmdata/dcpixel.h>
#include <dcmtk/dcmdata/dcpixseq.h>
#include <dcmtk/dcmdata/dcpxitem.h>
#include <dcmtk/dcmjpeg/djencode.h>

#include "io/IoFixtures.h"
#include "tessera/core/Error.h"
#include "tessera/io/NiftiReader.h"
#include "tessera/io/VolumeReader.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

// value = linear voxel index (modulo 256 for u8): a misplaced slice, row or
// column shows.
Volume rampVolume(glm::ivec3 dims, ScalarType type, glm::dvec3 spacing, glm::dvec3 origin) {
  Volume v = Volume::allocate(dims, type);
  for (std::size_t i = 0; i < v.voxelCount(); ++i) {
    v.setValueAtIndex(i, static_cast<double>(type == ScalarType::U8 ? i % 256 : i));
  }
  v.invalidateRange();
  v.setSpacing(spacing);
  v.setOrigin(origin);
  return v;
}

Volume smallSeries(ScalarType type = ScalarType::U16) {
  return rampVolume({6, 5, 6}, type, {0.5, 0.75, 2.0}, {-10.0, 4.0, 30.0});
}

void expectSameVoxels(const Volume& a, const Volume& b) {
  ASSERT_EQ(a.dims(), b.dims());
  std::size_t mismatches = 0;
  std::size_t first = 0;
  for (std::size_t i = 0; i < a.voxelCount(); ++i) {
    if (a.valueAtIndex(i) != b.valueAtIndex(i) && mismatches++ == 0) first = i;
  }
  EXPECT_EQ(mismatches, 0u) << "first at index " << first << ": " << a.valueAtIndex(first) << " vs "
                            << b.valueAtIndex(first);
}

// Loads a slice, lets `edit` change its dataset, saves it again in the same
// transfer syntax.
void editSlice(const fs::path& file, const std::function<void(DcmDataset&)>& edit) {
  DcmFileFormat ff;
  ASSERT_TRUE(ff.loadFile(file.c_str()).good()) << file;
  ASSERT_TRUE(ff.loadAllDataIntoMemory().good());
  const E_TransferSyntax xfer = ff.getDataset()->getOriginalXfer();
  edit(*ff.getDataset());
  const OFCondition c = ff.saveFile(file.c_str(), xfer, EET_ExplicitLength);
  ASSERT_TRUE(c.good()) << c.text();
}

std::string storedTransferSyntax(const fs::path& file) {
  DcmFileFormat ff;
  if (ff.loadFile(file.c_str()).bad()) return "unreadable";
  OFString uid;
  ff.getMetaInfo()->findAndGetOFString(DCM_TransferSyntaxUID, uid);
  return uid.c_str();
}

std::vector<fs::path> filesIn(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

// The issue asks for bad input to be refused within a second.
template <class E = InputError, class F>
void expectRejectedFast(F&& f, const std::vector<std::string>& fragments) {
  const auto start = std::chrono::steady_clock::now();
  test::expectRejected<E>(f, fragments);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(s, 1.0) << "took " << s << " s";
}

TEST(DicomSeriesReader, ShuffledSeriesIsSortedByPositionAndSecondSeriesIsReported) {
  test::TempDir dir;
  const Volume big = rampVolume({20, 16, 12}, ScalarType::U16, {0.8, 0.7, 2.5}, {-8, 5, 30});
  const Volume small = rampVolume({8, 8, 5}, ScalarType::U8, {1.0, 1.0, 3.0}, {0, 0, 0});
  DicomWriteOptions o;
  o.shuffleFileNames = true;
  o.seriesInstanceUid = "1.2.826.0.1.3680043.9.7.100";
  o.seriesDescription = "ramp";
  writeDicomSeries(big, dir.path(), o);
  o.seriesInstanceUid = "1.2.826.0.1.3680043.9.7.200";
  o.seriesDescription = "localizer";
  writeDicomSeries(small, dir.path(), o);
  test::writeFile(dir / "README.txt", "not a DICOM file");

  const auto files = filesIn(dir.path());
  ASSERT_EQ(files.size(), 12u + 5u + 1u);
  for (const auto& f : files) EXPECT_EQ(f.filename().string().find("slice_"), std::string::npos);

  const Volume v = readDicomSeries(dir.path());
  EXPECT_EQ(v.dims(), glm::ivec3(20, 16, 12));
  EXPECT_EQ(v.type(), ScalarType::U16);
  EXPECT_EQ(v.spacing().x, 0.8);
  EXPECT_EQ(v.spacing().y, 0.7);
  EXPECT_NEAR(v.spacing().z, 2.5, 1e-9);
  EXPECT_EQ(v.origin(), glm::dvec3(-8, 5, 30));
  expectSameVoxels(v, big);
  const std::string d = v.description();
  EXPECT_NE(d.find("1.2.826.0.1.3680043.9.7.100"), std::string::npos) << d;
  EXPECT_NE(d.find("series 1 of 2"), std::string::npos) << d;
  EXPECT_NE(d.find("others: 1.2.826.0.1.3680043.9.7.200 (5 slices"), std::string::npos) << d;
  EXPECT_NE(d.find("localizer"), std::string::npos) << d;
  EXPECT_NE(d.find("skipped 1 non-DICOM file"), std::string::npos) << d;

  const Volume other = readDicomSeries(dir.path(), "1.2.826.0.1.3680043.9.7.200");
  EXPECT_EQ(other.dims(), glm::ivec3(8, 8, 5));
  EXPECT_EQ(other.type(), ScalarType::U8);
  EXPECT_NEAR(other.spacing().z, 3.0, 1e-9);
  expectSameVoxels(other, small);
  EXPECT_NE(other.description().find("series 2 of 2"), std::string::npos);

  const auto series = listDicomSeries(dir.path());
  ASSERT_EQ(series.size(), 2u);
  EXPECT_EQ(series[0].seriesInstanceUid, "1.2.826.0.1.3680043.9.7.100");
  EXPECT_EQ(series[0].slices, 12);
  EXPECT_EQ(series[1].slices, 5);
  EXPECT_NE(series[1].description.find("localizer"), std::string::npos);

  expectRejectedFast([&] { readDicomSeries(dir.path(), "1.2.3.999"); },
                     {"1.2.3.999", "1.2.826.0.1.3680043.9.7.100 (12 slices"});
}

TEST(DicomSeriesReader, OneFileReadsTheSeriesItBelongsTo) {
  test::TempDir dir;
  const Volume big = rampVolume({7, 6, 9}, ScalarType::I16, {1, 1, 1}, {0, 0, 0});
  const Volume small = rampVolume({5, 4, 3}, ScalarType::U16, {1, 1, 2}, {0, 0, 0});
  DicomWriteOptions o;
  o.shuffleFileNames = true;
  o.seriesInstanceUid = "1.2.3.4.1";
  writeDicomSeries(big, dir.path(), o);
  o.seriesInstanceUid = "1.2.3.4.2";
  writeDicomSeries(small, dir.path(), o);
  fs::path smallFile;
  for (const auto& f : filesIn(dir.path())) {
    DcmFileFormat ff;
    ASSERT_TRUE(ff.loadFile(f.c_str()).good());
    OFString uid;
    ff.getDataset()->findAndGetOFString(DCM_SeriesInstanceUID, uid);
    if (uid == "1.2.3.4.2") smallFile = f;
  }
  ASSERT_FALSE(smallFile.empty());
  const Volume v = readVolume(smallFile.string());
  EXPECT_EQ(v.dims(), glm::ivec3(5, 4, 3));
  expectSameVoxels(v, small);
  // readVolume on the folder picks the larger series.
  expectSameVoxels(readVolume(dir.path().string()), big);
  // An explicit list of files is grouped the same way.
  expectSameVoxels(readDicomFiles(filesIn(dir.path()), "1.2.3.4.2"), small);
}

TEST(DicomSeriesReader, Ch2RoundTripsThroughDicomExactly) {
  const fs::path ch2 = "/usr/share/mricron/templates/ch2.nii.gz";
  if (!fs::exists(ch2)) GTEST_SKIP() << ch2 << " not installed";
  const Volume nifti = readNifti(ch2);
  test::TempDir dir;
  DicomWriteOptions o;
  o.shuffleFileNames = true;
  writeDicomSeries(nifti, dir / "ch2", o);
  const Volume v = readDicomSeries(dir / "ch2");
  EXPECT_EQ(v.dims(), nifti.dims());
  EXPECT_EQ(v.type(), nifti.type());
  EXPECT_EQ(v.spacing(), nifti.spacing());
  ASSERT_EQ(v.byteSize(), nifti.byteSize());
  EXPECT_EQ(std::memcmp(v.bytes().data(), nifti.bytes().data(), v.byteSize()), 0);
}

TEST(DicomSeriesReader, SignedPixelsWithRescaleGiveTheOriginalValues) {
  test::TempDir dir;
  // Stored values s in [-600, 1000], written as value = 2 s - 1024.
  Volume v = Volume::allocate({9, 7, 4}, ScalarType::I16);
  for (std::size_t i = 0; i < v.voxelCount(); ++i) {
    const int s = -600 + static_cast<int>((i * 37) % 1601);
    v.setValueAtIndex(i, 2.0 * s - 1024.0);
  }
  v.invalidateRange();
  DicomWriteOptions o;
  o.rescaleSlope = 2;
  o.rescaleIntercept = -1024;
  writeDicomSeries(v, dir.path(), o);

  DcmFileFormat ff;
  ASSERT_TRUE(ff.loadFile((dir / "slice_0000.dcm").c_str()).good());
  Uint16 representation = 0;
  ff.getDataset()->findAndGetUint16(DCM_PixelRepresentation, representation);
  EXPECT_EQ(representation, 1);  // stored signed
  const Uint16* stored = nullptr;
  ASSERT_TRUE(ff.getDataset()->findAndGetUint16Array(DCM_PixelData, stored).good());
  EXPECT_EQ(static_cast<Sint16>(stored[0]), -600);  // (-2224 + 1024) / 2
  OFString slope;
  ff.getDataset()->findAndGetOFString(DCM_RescaleSlope, slope);
  EXPECT_EQ(slope, "2");

  const Volume r = readDicomSeries(dir.path());
  EXPECT_EQ(r.type(), ScalarType::I16);  // integer slope/intercept, values fit i16
  expectSameVoxels(r, v);
  EXPECT_NE(r.description().find("rescale slope 2 intercept -1024"), std::string::npos);

  // A fractional slope gives f32.
  test::TempDir dir2;
  o.rescaleSlope = 0.5;
  o.rescaleIntercept = -1024;
  writeDicomSeries(v, dir2.path(), o);
  const Volume f = readDicomSeries(dir2.path());
  EXPECT_EQ(f.type(), ScalarType::F32);
  expectSameVoxels(f, v);
}

TEST(DicomSeriesReader, CompressedSeriesReadBackExactly) {
  for (const char* syntax : {"jpeg-ls-lossless", "rle", "deflate"}) {
    for (ScalarType type : {ScalarType::U8, ScalarType::U16, ScalarType::I16}) {
      SCOPED_TRACE(std::string(syntax) + " " + std::string(scalarTypeName(type)));
      test::TempDir dir;
      // Odd sizes on purpose; noise is the hardest case for the encoders
      // (DCMTK's default JPEG-LS encoder failed on some signed noise slices).
      Volume v = Volume::allocate({33, 17, 12}, type);
      const std::string noise = test::noiseBytes(v.byteSize(), 7);
      std::memcpy(v.bytes().data(), noise.data(), noise.size());
      v.invalidateRange();
      DicomWriteOptions o;
      o.transferSyntax = syntax;
      writeDicomSeries(v, dir.path(), o);
      const std::string expectedUid = std::string(syntax) == "jpeg-ls-lossless"
                                          ? "1.2.840.10008.1.2.4.80"
                                      : std::string(syntax) == "rle" ? "1.2.840.10008.1.2.5"
                                                                     : "1.2.840.10008.1.2.1.99";
      EXPECT_EQ(storedTransferSyntax(dir / "slice_0002.dcm"), expectedUid);
      try {
        const Volume r = readDicomSeries(dir.path());
        EXPECT_EQ(r.type(), type);
        expectSameVoxels(r, v);
      } catch (const Error& e) {
        ADD_FAILURE() << e.what();
      }
    }
  }
}

// What scanners and archives write besides our writer's syntaxes: implicit
// VR (8-bit pixels then arrive as OW), big endian, datasets without the
// Part-10 preamble, and lossless JPEG (process 14, first-order prediction).
TEST(DicomSeriesReader, OtherEncodingsReadBackExactly) {
  DJEncoderRegistration::registerCodecs();
  struct Variant {
    const char* name;
    E_TransferSyntax xfer;
    E_FileWriteMode mode;
  };
  const Variant variants[] = {
      {"implicit little endian", EXS_LittleEndianImplicit, EWM_fileformat},
      {"explicit big endian", EXS_BigEndianExplicit, EWM_fileformat},
      {"dataset without preamble", EXS_LittleEndianImplicit, EWM_dataset},
      {"JPEG lossless", EXS_JPEGProcess14SV1, EWM_fileformat},
  };
  for (const Variant& variant : variants) {
    for (ScalarType type : {ScalarType::U8, ScalarType::U16, ScalarType::I16}) {
      SCOPED_TRACE(std::string(variant.name) + " " + std::string(scalarTypeName(type)));
      test::TempDir dir;
      Volume v = Volume::allocate({13, 11, 4}, type);
      const std::string noise = test::noiseBytes(v.byteSize(), 11);
      std::memcpy(v.bytes().data(), noise.data(), noise.size());
      v.invalidateRange();
      writeDicomSeries(v, dir.path());
      for (const auto& f : filesIn(dir.path())) {
        DcmFileFormat ff;
        ASSERT_TRUE(ff.loadFile(f.c_str()).good());
        ASSERT_TRUE(ff.loadAllDataIntoMemory().good());
        if (DcmXfer(variant.xfer).isEncapsulated()) {
          ASSERT_TRUE(ff.getDataset()->chooseRepresentation(variant.xfer, nullptr).good());
        }
        const OFCondition c = ff.saveFile(f.c_str(), variant.xfer, EET_ExplicitLength, EGL_recalcGL,
                                          EPD_noChange, 0, 0, variant.mode);
        ASSERT_TRUE(c.good()) << c.text();
      }
      const Volume r = readDicomSeries(dir.path());
      EXPECT_EQ(r.type(), type);
      expectSameVoxels(r, v);
      EXPECT_NE(r.description().find(DcmXfer(variant.xfer).getXferID()), std::string::npos)
          << r.description();
    }
  }
}

TEST(DicomSeriesReader, FloatVolumesAreQuantizedWithinHalfAStep) {
  test::TempDir dir;
  Volume v = Volume::allocate({10, 10, 3}, ScalarType::F32);
  for (std::size_t i = 0; i < v.voxelCount(); ++i) {
    v.setValueAtIndex(i, -3.25 + 0.0137 * static_cast<double>(i));
  }
  v.invalidateRange();
  writeDicomSeries(v, dir.path());
  const Volume r = readDicomSeries(dir.path());
  EXPECT_EQ(r.type(), ScalarType::F32);
  const double step = (v.valueRange().max - v.valueRange().min) / 65535.0;
  double worst = 0;
  for (std::size_t i = 0; i < v.voxelCount(); ++i) {
    worst = std::max(worst, std::abs(r.valueAtIndex(i) - v.valueAtIndex(i)));
  }
  EXPECT_LE(worst, 0.5 * step * 1.001);
}

TEST(DicomSeriesReader, RejectsAMissingSliceNamingItsNeighbours) {
  test::TempDir dir;
  writeDicomSeries(smallSeries(), dir.path());
  fs::remove(dir / "slice_0003.dcm");
  expectRejectedFast([&] { readDicomSeries(dir.path()); },
                     {"slice_0002.dcm", "slice_0004.dcm", "1 slice missing"});
}

TEST(DicomSeriesReader, RejectsTwoSlicesAtTheSamePosition) {
  test::TempDir dir;
  writeDicomSeries(smallSeries(), dir.path());
  fs::copy_file(dir / "slice_0002.dcm", dir / "slice_0002_copy.dcm");
  expectRejectedFast([&] { readDicomSeries(dir.path()); },
                     {"slice_0002.dcm", "slice_0002_copy.dcm", "same position"});
}

TEST(DicomSeriesReader, RejectsUnevenSliceSpacing) {
  test::TempDir dir;
  writeDicomSeries(smallSeries(), dir.path());  // z at 30, 32, 34, ...
  editSlice(dir / "slice_0004.dcm", [](DcmDataset& ds) {
    ds.putAndInsertString(DCM_ImagePositionPatient, "-10\\4\\38.5");
  });
  expectRejectedFast([&] { readDicomSeries(dir.path()); },
                     {"slice_0003.dcm", "slice_0004.dcm", "uneven slice spacing"});
}

TEST(DicomSeriesReader, RejectsASliceWithOtherRows) {
  test::TempDir dir;
  DicomWriteOptions o;
  o.seriesInstanceUid = "1.2.3.4.5";
  writeDicomSeries(smallSeries(), dir.path(), o);
  // One more slice of the same series, 6 x 9 pixels, right above the others.
  o.shuffleFileNames = true;
  writeDicomSeries(rampVolume({6, 9, 1}, ScalarType::U16, {0.5, 0.75, 2.0}, {-10, 4, 42}),
                   dir.path(), o);
  std::string odd;
  for (const auto& f : filesIn(dir.path())) {
    if (f.filename().string().rfind("slice_", 0) != 0) odd = f.filename().string();
  }
  ASSERT_FALSE(odd.empty());
  expectRejectedFast([&] { readDicomSeries(dir.path()); }, {odd, "Rows x Columns is 9x6"});
}

TEST(DicomSeriesReader, RejectsMixedOrientations) {
  test::TempDir dir;
  writeDicomSeries(smallSeries(), dir.path());
  editSlice(dir / "slice_0001.dcm", [](DcmDataset& ds) {
    ds.putAndInsertString(DCM_ImageOrientationPatient, "1\\0\\0\\0\\0\\1");
  });
  expectRejectedFast([&] { readDicomSeries(dir.path()); },
                     {"slice_0001.dcm", "Image Orientation (Patient)", "share an orientation"});
}

TEST(DicomSeriesReader, RejectsColourSlices) {
  test::TempDir dir;
  writeDicomSeries(smallSeries(ScalarType::U8), dir.path());
  editSlice(dir / "slice_0005.dcm", [](DcmDataset& ds) {
    ds.putAndInsertUint16(DCM_SamplesPerPixel, 3);
    ds.putAndInsertString(DCM_PhotometricInterpretation, "RGB");
    ds.putAndInsertUint16(DCM_PlanarConfiguration, 0);
  });
  expectRejectedFast([&] { readDicomSeries(dir.path()); },
                     {"slice_0005.dcm", "Samples per Pixel is 3"});
}

TEST(DicomSeriesReader, RejectsANumberOfFramesThePixelsDoNotHold) {
  test::TempDir dir;
  writeDicomSeries(smallSeries(), dir.path());
  editSlice(dir / "slice_0000.dcm",
            [](DcmDataset& ds) { ds.putAndInsertString(DCM_NumberOfFrames, "2"); });
  expectRejectedFast(
      [&] { readDicomSeries(dir.path()); },
      {"slice_0000.dcm", "Number of Frames (0028,0008) is 2", "frame 2 has no pixels"});
}

TEST(DicomSeriesReader, RejectsATruncatedFile) {
  test::TempDir dir;
  writeDicomSeries(smallSeries(), dir.path());
  const fs::path f = dir / "slice_0003.dcm";
  fs::resize_file(f, fs::file_size(f) - 20);  // cuts into the pixel data at the end
  expectRejectedFast([&] { readDicomSeries(dir.path()); }, {"slice_0003.dcm", "truncated"});
  // Alone in its folder, it is still the file named.
  test::TempDir alone;
  fs::copy_file(f, alone / "only.dcm");
  expectRejectedFast([&] { readDicomSeries(alone.path()); },
                     {"is a directory", "only.dcm", "truncated"});
}

TEST(DicomSeriesReader, SkipsUnreadableFilesOfOtherSeriesWithANote) {
  test::TempDir dir;
  DicomWriteOptions o;
  o.seriesInstanceUid = "1.2.3.4.10";
  writeDicomSeries(smallSeries(), dir.path(), o);
  o.seriesInstanceUid = "1.2.3.4.20";
  o.shuffleFileNames = true;
  const Volume other = rampVolume({4, 4, 2}, ScalarType::U16, {1, 1, 1}, {0, 0, 0});
  writeDicomSeries(other, dir.path(), o);
  std::vector<fs::path> otherFiles;
  for (const auto& f : filesIn(dir.path())) {
    if (f.filename().string().rfind("slice_", 0) != 0) otherFiles.push_back(f);
  }
  ASSERT_EQ(otherFiles.size(), 2u);
  fs::resize_file(otherFiles[0], fs::file_size(otherFiles[0]) - 10);
  const Volume v = readDicomSeries(dir.path(), "1.2.3.4.10");
  expectSameVoxels(v, smallSeries());
  EXPECT_NE(v.description().find("skipped 1 unreadable DICOM file"), std::string::npos);
  EXPECT_NE(v.description().find(otherFiles[0].filename().string()), std::string::npos);
  // The damaged file's own series is refused, naming it.
  expectRejectedFast([&] { readDicomSeries(dir.path(), "1.2.3.4.20"); },
                     {otherFiles[0].filename().string()});
}

TEST(DicomSeriesReader, RejectsPixelDataShorterThanRowsTimesColumns) {
  test::TempDir dir;
  writeDicomSeries(smallSeries(), dir.path());
  editSlice(dir / "slice_0002.dcm", [](DcmDataset& ds) {
    const Uint16 few[4] = {1, 2, 3, 4};
    ds.putAndInsertUint16Array(DCM_PixelData, few, 4);
  });
  expectRejectedFast([&] { readDicomSeries(dir.path()); },
                     {"slice_0002.dcm", "pixel data has 8 bytes", "60 bytes", "truncated"});
}

TEST(DicomSeriesReader, RejectsHugeRowsAndColumnsFromTheFileSizeBeforeAllocating) {
  test::TempDir dir;
  writeDicomSeries(smallSeries(), dir.path());
  for (const auto& f : filesIn(dir.path())) {
    editSlice(f, [](DcmDataset& ds) {
      ds.putAndInsertUint16(DCM_Rows, 60000);
      ds.putAndInsertUint16(DCM_Columns, 60000);
    });
  }
  // 60000 x 60000 x 6 x 2 bytes = 43 GB, claimed by files of 60 pixel bytes.
  expectRejectedFast([&] { readDicomSeries(dir.path()); },
                     {"pixel data has 60 bytes", "7200000000 bytes (truncated)"});
}

TEST(DicomSeriesReader, RejectsANonDicomFileGivenAlone) {
  test::TempDir dir;
  test::writeFile(dir / "scan.dcm", "this is a text file, not a DICOM slice");
  expectRejectedFast([&] { readDicomSeries(dir / "scan.dcm"); }, {"scan.dcm", "not a DICOM file"});
  expectRejectedFast([&] { readVolume((dir / "scan.dcm").string()); }, {"scan.dcm"});
}

TEST(DicomSeriesReader, RejectsFoldersWithoutDicom) {
  test::TempDir dir;
  expectRejectedFast([&] { readDicomSeries(dir.path()); },
                     {dir.path().string(), "is a directory", "no files"});
  test::writeFile(dir / "notes.txt", "hello");
  fs::create_directories(dir / "series1");
  expectRejectedFast([&] { readDicomSeries(dir.path()); },
                     {"is a directory", "1 non-DICOM file", "1 subfolder(s) not searched"});
}

TEST(DicomSeriesReader, RejectsATransferSyntaxWithoutDecoderNamingIt) {
  test::TempDir dir;
  writeDicomSeries(smallSeries(), dir.path());
  // Claim JPEG 2000 (DCMTK has no free decoder for it) with garbage fragments.
  const fs::path f = dir / "slice_0001.dcm";
  {
    DcmFileFormat ff;
    ASSERT_TRUE(ff.loadFile(f.c_str()).good());
    DcmDataset& ds = *ff.getDataset();
    auto* pixels = new DcmPixelData(DCM_PixelData);
    auto* sequence = new DcmPixelSequence(DcmTag(DCM_PixelData, EVR_OB));
    sequence->insert(new DcmPixelItem(DcmTag(DCM_Item, EVR_OB)));  // empty offset table
    auto* fragment = new DcmPixelItem(DcmTag(DCM_Item, EVR_OB));
    const std::string garbage = test::noiseBytes(64, 3);
    fragment->putUint8Array(reinterpret_cast<const Uint8*>(garbage.data()), 64);
    sequence->insert(fragment);
    pixels->putOriginalRepresentation(EXS_JPEG2000LosslessOnly, nullptr, sequence);
    ASSERT_TRUE(ds.insert(pixels, true).good());
    const OFCondition c = ff.saveFile(f.c_str(), EXS_JPEG2000LosslessOnly, EET_ExplicitLength);
    ASSERT_TRUE(c.good()) << c.text();
  }
  ASSERT_EQ(storedTransferSyntax(f), "1.2.840.10008.1.2.4.90");
  expectRejectedFast(
      [&] { readDicomSeries(dir.path()); },
      {"slice_0001.dcm", "JPEG 2000 (transfer syntax UID 1.2.840.10008.1.2.4.90) is not supported",
       "incomplete"});
}

TEST(DicomSeriesReader, RefusesASeriesLargerThanTheHostBudgetBeforeDecoding) {
  test::TempDir dir;
  writeDicomSeries(smallSeries(), dir.path());  // 6 x 5 x 6 x 2 bytes = 360 B
  test::BudgetOverride budget(100);
  expectRejectedFast<BudgetError>([&] { readDicomSeries(dir.path()); }, {"6x5x6"});
}

TEST(DicomSeriesWriter, RefusesValuesOutsideThePixelTypeAndExistingNames) {
  test::TempDir dir;
  DicomWriteOptions o;
  o.rescaleSlope = 0.5;  // 255 would be stored as 510 in 8 bits
  expectRejectedFast([&] { writeDicomSeries(smallSeries(ScalarType::U8), dir / "a", o); },
                     {"outside the 8-bit unsigned range"});
  EXPECT_FALSE(fs::exists(dir / "a"));

  writeDicomSeries(smallSeries(), dir / "b");
  expectRejectedFast([&] { writeDicomSeries(smallSeries(), dir / "b"); },
                     {"slice_0000.dcm", "already exists"});
  DicomWriteOptions bad;
  bad.transferSyntax = "jpeg2000";
  expectRejectedFast([&] { writeDicomSeries(smallSeries(), dir / "c", bad); }, {"jpeg2000"});
  // Only the finished series, no temporary folders, are left behind.
  const auto left = filesIn(dir.path());
  ASSERT_EQ(left.size(), 1u);
  EXPECT_EQ(left[0].filename(), "b");
  EXPECT_EQ(filesIn(dir / "b").size(), 6u);
}

}  // namespace
}  // namespace tessera
