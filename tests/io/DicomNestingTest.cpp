// Sequences nested deeper than the readers accept (io/DicomSeries.h
// kMaxSequenceNesting): refused in one line naming the file, whatever the
// depth and encoding, by DCMTK's reader (guarded by a walk before DCMTK
// recurses) and by the basic reader; skipped with a note beside a valid
// series; legal depths still read. Files from support/NestedDicom.h.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "io/IoFixtures.h"
#include "support/ExpectError.h"
#include "support/NestedDicom.h"
#include "tessera/core/Error.h"
#include "tessera/io/DicomBasicReader.h"
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/io/VolumeReader.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using test::NestedDicomOptions;
using test::NestedEncoding;

const char* name(NestedEncoding e) {
  switch (e) {
    case NestedEncoding::ExplicitUndefined:
      return "explicit VR, undefined lengths";
    case NestedEncoding::ExplicitDefined:
      return "explicit VR, defined lengths";
    case NestedEncoding::ImplicitUndefined:
      return "implicit VR, undefined lengths";
    case NestedEncoding::ImplicitDefined:
      return "implicit VR, defined lengths";
    case NestedEncoding::UnknownVr:
      return "UN of undefined length";
    case NestedEncoding::BigEndian:
      return "explicit VR big endian";
    case NestedEncoding::Deflated:
      return "deflated explicit VR";
  }
  return "?";
}

const std::vector<NestedEncoding> kEncodings = {
    NestedEncoding::ExplicitUndefined, NestedEncoding::ExplicitDefined,
    NestedEncoding::ImplicitUndefined, NestedEncoding::ImplicitDefined,
    NestedEncoding::UnknownVr,         NestedEncoding::BigEndian,
    NestedEncoding::Deflated};

std::string refusal(const fs::path& file) {
  return file.string() + ": sequences nested deeper than 64 levels; refused";
}

fs::path writeNested(const fs::path& file, const NestedDicomOptions& o) {
  test::writeFile(file, test::nestedDicomFile(o));
  return file;
}

using test::inputErrorMessage;

void expectImage(const Volume& v, const std::string& what) {
  ASSERT_EQ(v.dims(), glm::ivec3(test::kNestedImageSide, test::kNestedImageSide, 1)) << what;
  // Pixel (x=3, y=2): index 2 * 4 + 3.
  EXPECT_EQ(v.valueAt(3, 2, 0), test::nestedImagePixel(2 * test::kNestedImageSide + 3)) << what;
  EXPECT_EQ(v.valueAt(0, 0, 0), test::nestedImagePixel(0)) << what;
}

TEST(DicomNesting, RefusedInOneLineAtEveryDepthAndEncoding) {
  const test::TempDir dir;
  struct Case {
    int depth;
    NestedEncoding encoding;
    bool part10;
  };
  std::vector<Case> cases;
  for (const int depth : {65, 1000, 6000, 100000}) {
    cases.push_back({depth, NestedEncoding::ExplicitUndefined, true});
  }
  for (const NestedEncoding e : kEncodings) cases.push_back({6000, e, true});
  cases.push_back({100000, NestedEncoding::Deflated, true});
  cases.push_back({100000, NestedEncoding::ImplicitDefined, true});
  // Without preamble and meta information: DCMTK guesses the syntax.
  cases.push_back({6000, NestedEncoding::ImplicitUndefined, false});
  cases.push_back({6000, NestedEncoding::ExplicitUndefined, false});
  for (const Case& c : cases) {
    const std::string what = std::to_string(c.depth) + " levels, " + name(c.encoding) +
                             (c.part10 ? "" : ", bare dataset");
    const fs::path f = writeNested(dir / "deep.dcm",
                                   {.depth = c.depth, .encoding = c.encoding, .part10 = c.part10});
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_EQ(inputErrorMessage([&] { readDicomSeries(f); }), refusal(f)) << what;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // The walk reads headers only: a 3.6 MB file is refused in milliseconds.
    EXPECT_LT(s, 2.0) << what;
    if (c.part10) {
      // Through the format registry, as the CLI reads it.
      EXPECT_EQ(inputErrorMessage([&] { readVolume(f.string()); }), refusal(f)) << what;
    }
  }
}

TEST(DicomNesting, LegalDepthsStillRead) {
  const test::TempDir dir;
  for (const NestedEncoding e : kEncodings) {
    for (const int depth : {1, 10, 64}) {
      const std::string what = std::to_string(depth) + " levels, " + name(e);
      const fs::path f = writeNested(dir / "nested.dcm", {.depth = depth, .encoding = e});
      expectImage(readDicomSeries(f), what);
    }
  }
  // The limit is exact: 64 levels read, 65 refused.
  const test::TempDir atDir;
  const test::TempDir overDir;
  const fs::path at = writeNested(atDir / "at.dcm", {.depth = 64});
  const fs::path over = writeNested(overDir / "over.dcm", {.depth = 65});
  EXPECT_NO_THROW(readDicomSeries(at));
  EXPECT_EQ(inputErrorMessage([&] { readDicomSeries(over); }), refusal(over));
}

// The basic reader (browser, fuzzers) bounds its own walk the same way.
TEST(DicomNesting, BasicReaderRefusesTheSameFilesAndReadsTheLegalOnes) {
  const test::TempDir dir;
  for (const int depth : {65, 1000, 6000, 100000}) {
    const fs::path f = writeNested(dir / "deep.dcm", {.depth = depth});
    EXPECT_EQ(inputErrorMessage([&] { readDicomSeriesBasic(f); }), refusal(f)) << depth;
  }
  for (const NestedEncoding e : {NestedEncoding::ExplicitUndefined,
                                 NestedEncoding::ImplicitUndefined, NestedEncoding::UnknownVr}) {
    const fs::path f = writeNested(dir / "nested.dcm", {.depth = 64, .encoding = e});
    expectImage(readDicomSeriesBasic(f), std::string("64 levels, ") + name(e));
  }
}

// A clinician's folder: a valid series and one crafted file. The series is
// fine, so it is read; the file is skipped with a note that names it, as
// other unreadable files of unknown series are.
TEST(DicomNesting, DeepFileBesideAValidSeriesIsSkippedWithANote) {
  const test::TempDir dir;
  Volume series = test::randomVolume({6, 5, 4}, ScalarType::U16, 11);
  series.setSpacing({0.5, 0.5, 2.0});
  writeDicomSeries(series, dir.path());
  for (const int depth : {1000, 6000, 100000}) {
    const fs::path deep = writeNested(dir / "deep.dcm", {.depth = depth});
    const std::string note =
        "skipped 1 unreadable DICOM file(s) of other or unknown series, e.g. " + refusal(deep);
    const Volume dcmtk = readDicomSeries(dir.path());
    const Volume basic = readDicomSeriesBasic(dir.path());
    for (const Volume* v : {&dcmtk, &basic}) {
      ASSERT_EQ(v->dims(), series.dims()) << depth;
      EXPECT_EQ(v->valueAt(5, 4, 3), series.valueAt(5, 4, 3)) << depth;
      EXPECT_EQ(v->valueAt(1, 2, 0), series.valueAt(1, 2, 0)) << depth;
      EXPECT_NE(v->description().find(note), std::string::npos) << v->description();
    }
    // Named on its own, a slice of the series reads the series with the note.
    const Volume named = readDicomSeries(dir / "slice_0001.dcm");
    EXPECT_EQ(named.dims(), series.dims());
    EXPECT_NE(named.description().find(note), std::string::npos) << named.description();
  }
}

}  // namespace
}  // namespace tessera
