// A DICOM file named on its own that its series cannot hold (copies of it
// at its position, no position to order it by) is read alone with a note;
// a broken neighbour is an error naming both files; a folder keeps the
// error; every message names the file given.
// Built from pydicom's test files (python3-pydicom), where several
// encodings of one slice share a Series Instance UID, and from series
// written here and damaged through DCMTK.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcdatset.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>

#include "io/IoFixtures.h"
#include "tessera/core/Error.h"
#include "tessera/io/ByteSource.h"
#include "tessera/io/DicomBasicReader.h"
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/io/VolumeReader.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

const fs::path kPydicomTestFiles = "/usr/lib/python3/dist-packages/pydicom/data/test_files";
const fs::path kPydicomCharsetFiles = "/usr/lib/python3/dist-packages/pydicom/data/charset_files";

std::vector<fs::path> filesIn(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file()) out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

void expectSameVolume(const Volume& a, const Volume& b) {
  ASSERT_EQ(a.dims(), b.dims());
  EXPECT_EQ(a.type(), b.type());
  EXPECT_EQ(a.spacing(), b.spacing());
  EXPECT_EQ(a.origin(), b.origin());
  EXPECT_EQ(a.direction(), b.direction());
  ASSERT_EQ(a.byteSize(), b.byteSize());
  EXPECT_EQ(std::memcmp(a.bytes().data(), b.bytes().data(), a.byteSize()), 0);
}

// What `read` gives and prints on stderr.
struct Read {
  Volume volume;
  std::string stderrText;
};

Read readCapturingStderr(const std::function<Volume()>& read) {
  testing::internal::CaptureStderr();
  try {
    Volume v = read();
    return {std::move(v), testing::internal::GetCapturedStderr()};
  } catch (...) {
    testing::internal::GetCapturedStderr();
    throw;
  }
}

// How many of `names` the message contains.
int namesIn(const std::string& message, const std::vector<std::string>& names) {
  return static_cast<int>(std::count_if(names.begin(), names.end(), [&](const std::string& n) {
    return message.find(n) != std::string::npos;
  }));
}

// pydicom's MR_small.dcm beside its other encodings (the same slice, the
// same Series Instance UID): named, it is read alone, voxel for voxel as
// from a folder holding nothing else, by both readers and from memory, with
// a note on stderr and in the description. The folder is still refused,
// naming two of the copies.
TEST(DicomReadAlone, PydicomFileBesideItsCopiesIsReadAloneWithANote) {
  if (!fs::is_directory(kPydicomTestFiles)) {
    GTEST_SKIP() << kPydicomTestFiles << " missing (apt install python3-pydicom)";
  }
  test::TempDir beside;
  test::TempDir alone;
  std::vector<std::string> copied;
  for (const auto& f : filesIn(kPydicomTestFiles)) {
    const std::string n = f.filename().string();
    if (n.rfind("MR_small", 0) == 0 || n == "MR_truncated.dcm") {
      fs::copy_file(f, beside / n);
      copied.push_back(n);
    }
  }
  ASSERT_GE(copied.size(), 3u);
  fs::copy_file(kPydicomTestFiles / "MR_small.dcm", alone / "MR_small.dcm");
  const fs::path named = beside / "MR_small.dcm";

  const Read reference = readCapturingStderr([&] { return readDicomSeries(alone.path()); });
  EXPECT_EQ(reference.volume.dims(), glm::ivec3(64, 64, 1));
  EXPECT_EQ(reference.stderrText, "");

  const std::vector<std::pair<const char*, std::function<Volume()>>> readers = {
      {"DCMTK", [&] { return readDicomSeries(named); }},
      {"basic", [&] { return readDicomSeriesBasic(named); }},
      {"readVolume", [&] { return readVolume(named.string()); }},
  };
  for (const auto& [name, read] : readers) {
    SCOPED_TRACE(name);
    const Read r = readCapturingStderr(read);
    expectSameVolume(r.volume, reference.volume);
    EXPECT_EQ(r.stderrText.rfind("note: " + named.string() + ": read alone: ", 0), 0u)
        << r.stderrText;
    EXPECT_NE(r.stderrText.find("at its position (duplicate slices, e.g. "), std::string::npos)
        << r.stderrText;
    EXPECT_EQ(namesIn(r.stderrText, copied), 2) << r.stderrText;  // itself and one copy
    EXPECT_NE(r.volume.description().find(named.string() + ": read alone: "), std::string::npos)
        << r.volume.description();
  }

  // The page's path: the files of a dropped folder in memory.
  MemoryFiles files;
  for (const auto& n : copied) {
    const std::string b = test::fileBytes(beside / n);
    std::vector<std::byte> bytes(b.size());
    std::memcpy(bytes.data(), b.data(), b.size());
    files.add("drop/" + n, std::move(bytes));
  }
  const Read memory =
      readCapturingStderr([&] { return readVolume(*files.open("drop/MR_small.dcm"), files); });
  expectSameVolume(memory.volume, reference.volume);
  EXPECT_EQ(memory.stderrText.rfind("note: drop/MR_small.dcm: read alone: ", 0), 0u)
      << memory.stderrText;

  // Named as a folder, the copies are the error they always were.
  for (const auto& read : std::vector<std::function<void()>>{
           [&] { readDicomSeries(beside.path()); }, [&] { readDicomSeriesBasic(beside.path()); }}) {
    try {
      read();
      ADD_FAILURE() << "the folder of copies was read";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("are at the same position"), std::string::npos) << m;
      EXPECT_EQ(namesIn(m, copied), 2) << m;
    }
  }
}

// Writes a 3-slice series (z = 30, 32, 34 mm) into `dir`, then a fourth
// file of the same series one step further, damaged by `damage`.
void seriesWithBrokenNeighbour(const fs::path& dir,
                               const std::function<void(const fs::path&)>& damage) {
  Volume v = test::randomVolume({6, 5, 3}, ScalarType::U16, 7,
                                {.spacing = {0.5, 0.75, 2.0}, .origin = {-10.0, 4.0, 30.0}});
  DicomWriteOptions o;
  o.seriesInstanceUid = "1.2.826.0.1.3680043.9.7.300";
  writeDicomSeries(v, dir, o);
  const fs::path broken = dir / "slice_0003.dcm";
  fs::copy_file(dir / "slice_0002.dcm", broken);
  DcmFileFormat ff;
  ASSERT_TRUE(ff.loadFile(broken.c_str()).good());
  ASSERT_TRUE(ff.loadAllDataIntoMemory().good());
  DcmDataset& ds = *ff.getDataset();
  // RAS z 36 is LPS z 36; x and y are negated (LPS).
  ds.putAndInsertString(DCM_ImagePositionPatient, "10\\-4\\36");
  ds.putAndInsertString(DCM_InstanceNumber, "4");
  ASSERT_TRUE(ff.saveFile(broken.c_str(), ds.getOriginalXfer(), EET_ExplicitLength).good());
  damage(broken);
}

// A good 3-slice series and a broken fourth slice of it. The user who names
// a good slice is told which neighbour spoils the series, and how, in one
// error naming both files: the series is never read short of a slice (the
// volume would be silently incomplete), nor replaced by the one slice named
// (a 300-slice CT shown as one slice because its slice 150 is damaged would
// hide the damage behind a note). Read alone is for a file its series cannot
// hold (copies at its position, no position), not for a broken neighbour.
// Naming the broken file gives its own error; naming the folder, the error
// naming the broken file.
TEST(DicomReadAlone, GoodSliceBesideABrokenNeighbourIsRefusedNamingBoth) {
  struct Case {
    const char* what;
    std::function<void(const fs::path&)> damage;
    const char* problem;
  };
  const std::vector<Case> cases = {
      {"truncated", [](const fs::path& f) { fs::resize_file(f, fs::file_size(f) - 20); },
       "truncated"},
      {"colour",
       [](const fs::path& f) {
         DcmFileFormat ff;
         ASSERT_TRUE(ff.loadFile(f.c_str()).good());
         ASSERT_TRUE(ff.loadAllDataIntoMemory().good());
         ff.getDataset()->putAndInsertUint16(DCM_SamplesPerPixel, 3);
         ff.getDataset()->putAndInsertString(DCM_PhotometricInterpretation, "RGB");
         ASSERT_TRUE(ff.saveFile(f.c_str(), EXS_LittleEndianExplicit, EET_ExplicitLength).good());
       },
       "Samples per Pixel is 3"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    test::TempDir dir;
    seriesWithBrokenNeighbour(dir.path(), c.damage);
    const fs::path named = dir / "slice_0001.dcm";
    const std::string broken = (dir / "slice_0003.dcm").string();
    for (const auto& read : std::vector<std::function<Volume()>>{
             [&] { return readDicomSeries(named); }, [&] { return readDicomSeriesBasic(named); },
             [&] { return readVolume(named.string()); }}) {
      test::expectRejected<InputError>(
          [&] { readCapturingStderr(read); },
          {named.string() + ": its series cannot be read from the files beside it: " + broken +
               ": ",
           c.problem});
    }
    test::expectRejected<InputError>([&] { readDicomSeries(broken); }, {broken + ": ", c.problem});
    test::expectRejected<InputError>([&] { readDicomSeries(dir.path()); }, {broken, c.problem});
  }
  // Without the broken file the series reads whole, with no note.
  test::TempDir dir;
  seriesWithBrokenNeighbour(dir.path(), [](const fs::path& f) { fs::remove(f); });
  const Read whole = readCapturingStderr([&] { return readDicomSeries(dir / "slice_0001.dcm"); });
  EXPECT_EQ(whole.volume.dims(), glm::ivec3(6, 5, 3));
  EXPECT_EQ(whole.stderrText, "");
}

// A copy of a slice of a good series (another encoding of it, the same
// position): named, the copy is read alone; a slice of the series without a
// copy, named, still gets the series' error (the copy is at fault), naming
// both.
TEST(DicomReadAlone, CopyOfASliceIsReadAloneAndTheOthersAreRefused) {
  test::TempDir dir;
  seriesWithBrokenNeighbour(dir.path(), [](const fs::path& f) { fs::remove(f); });
  fs::copy_file(dir / "slice_0001.dcm", dir / "copy_of_0001.dcm");
  test::TempDir alone;
  fs::copy_file(dir / "slice_0001.dcm", alone / "slice_0001.dcm");
  const Volume reference = readDicomSeries(alone.path());
  for (const char* name : {"copy_of_0001.dcm", "slice_0001.dcm"}) {
    SCOPED_TRACE(name);
    const Read r = readCapturingStderr([&] { return readDicomSeries(dir / name); });
    expectSameVolume(r.volume, reference);
    EXPECT_EQ(r.stderrText.rfind("note: " + (dir / name).string() +
                                     ": read alone: 1 other file of its series is at its position",
                                 0),
              0u)
        << r.stderrText;
  }
  const std::string other = (dir / "slice_0000.dcm").string();
  test::expectRejected<InputError>(
      [&] { readDicomSeries(other); },
      {other + ": its series cannot be read from the files beside it: ",
       (dir / "copy_of_0001.dcm").string(), (dir / "slice_0001.dcm").string(), "same position"});
}

// A file named with a Series Instance UID (--series) asks for that series:
// its errors are not turned into a read of the named file, and they name
// the named file too.
TEST(DicomReadAlone, ASeriesAskedForIsReadOrRefusedNamingTheFileGiven) {
  test::TempDir dir;
  seriesWithBrokenNeighbour(dir.path(),
                            [](const fs::path& f) { fs::resize_file(f, fs::file_size(f) - 20); });
  DicomWriteOptions o;
  o.seriesInstanceUid = "1.2.826.0.1.3680043.9.7.301";
  o.shuffleFileNames = true;
  writeDicomSeries(test::randomVolume({4, 4, 2}, ScalarType::U8, 3), dir / "other", o);
  for (const auto& f : filesIn(dir / "other")) fs::rename(f, dir / f.filename());
  const Volume other = readDicomSeries(dir / "slice_0001.dcm", "1.2.826.0.1.3680043.9.7.301");
  EXPECT_EQ(other.dims(), glm::ivec3(4, 4, 2));
  test::expectRejected<InputError>(
      [&] { readDicomSeries(dir / "slice_0001.dcm", "1.2.826.0.1.3680043.9.7.300"); },
      {(dir / "slice_0001.dcm").string() +
           ": series 1.2.826.0.1.3680043.9.7.300 cannot be read from the files beside it: " +
           (dir / "slice_0003.dcm").string() + ": ",
       "truncated"});
}

// Every pydicom test file named on its own: an error names that file
// (never only another one), and so does every note. The files that pydicom
// reads alone but that share a Series Instance UID with other files there
// are read.
TEST(DicomReadAlone, EveryPydicomFileNamedGivesMessagesNamingIt) {
  if (!fs::is_directory(kPydicomTestFiles) || !fs::is_directory(kPydicomCharsetFiles)) {
    GTEST_SKIP() << kPydicomTestFiles << " or " << kPydicomCharsetFiles
                 << " missing (apt install python3-pydicom)";
  }
  std::vector<std::string> read;
  int refused = 0;
  for (const fs::path& dir : {kPydicomTestFiles, kPydicomCharsetFiles}) {
    for (const auto& f : filesIn(dir)) {
      if (f.extension() != ".dcm") continue;
      const std::string name = f.filename().string();
      SCOPED_TRACE(name);
      try {
        const Read r = readCapturingStderr([&] { return readVolume(f.string()); });
        read.push_back(name);
        std::istringstream lines(r.stderrText);
        for (std::string line; std::getline(lines, line);) {
          EXPECT_NE(line.find(f.string()), std::string::npos) << line;
        }
      } catch (const InputError& e) {
        ++refused;
        EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      }
    }
  }
  for (const char* n :
       {"MR_small.dcm", "MR_small_RLE.dcm", "MR_small_bigendian.dcm", "MR_small_expb.dcm",
        "MR_small_implicit.dcm", "MR_small_jpeg_ls_lossless.dcm", "MR_small_padded.dcm",
        "JPEG-lossy.dcm", "JPGExtended.dcm", "chrFren.dcm", "chrFrenMulti.dcm", "CT_small.dcm"}) {
    EXPECT_NE(std::find(read.begin(), read.end(), n), read.end()) << n << " not read";
  }
  std::printf("pydicom files named alone: %zu read, %d refused naming the file\n", read.size(),
              refused);
}

}  // namespace
}  // namespace tessera
