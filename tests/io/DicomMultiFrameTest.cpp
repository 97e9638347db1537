// Multi-frame DICOM objects, written by pydicom (tests/io/make_multiframe.py),
// read by both readers: an Enhanced CT of the marked head equals the same
// anatomy as single-frame files (voxels identical, affine within 1e-4 mm,
// the marker where nibabel finds it after conversion to NIfTI); the stacks
// of a two-stack object are listed and each selectable; classic NM
// multi-frame is placed by its Detector Information Sequence and step; a
// frame without a position and a Number of Frames that lies are refused in
// one line naming the file and the frame.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "support/Nibabel.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/DicomBasicReader.h"
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/io/VolumeWriter.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

const std::string kPython = "/usr/bin/python3";
const std::string kTestsDir = std::string(TESSERA_TEST_DATA_DIR) + "/..";

using Reader = std::function<Volume(const fs::path&, const std::string&)>;

struct NamedReader {
  const char* name;
  Reader read;
};

const std::vector<NamedReader>& readers() {
  static const std::vector<NamedReader> r = {
      {"DCMTK", [](const fs::path& p, const std::string& s) { return readDicomSeries(p, s); }},
      {"basic", [](const fs::path& p, const std::string& s) { return readDicomSeriesBasic(p, s); }},
  };
  return r;
}

// The generated files, made once for the suite (about 4 s).
class DicomMultiFrame : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (std::system((kPython + " -c 'import numpy, nibabel, pydicom' 2>/dev/null").c_str()) != 0) {
      return;
    }
    dir_ = new test::TempDir();
    const std::string cmd =
        kPython + " " + kTestsDir + "/io/make_multiframe.py " + dir_->path().string();
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    truth_ = nlohmann::json::parse(std::ifstream(dir_->path() / "truth.json"));
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    if (dir_ == nullptr) GTEST_SKIP() << kPython << " cannot import numpy, nibabel and pydicom";
  }
  static fs::path at(const std::string& name) { return dir_->path() / name; }

  static test::TempDir* dir_;
  static nlohmann::json truth_;
};

test::TempDir* DicomMultiFrame::dir_ = nullptr;
nlohmann::json DicomMultiFrame::truth_;

double largestAffineDifference(const Volume& a, const Volume& b) {
  const glm::dmat4 x = a.indexToWorld();
  const glm::dmat4 y = b.indexToWorld();
  double d = 0;
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 3; ++r) d = std::max(d, std::abs(x[c][r] - y[c][r]));
  }
  return d;
}

void expectSameVoxels(const Volume& a, const Volume& b) {
  ASSERT_EQ(a.dims(), b.dims());
  ASSERT_EQ(a.type(), b.type());
  ASSERT_EQ(a.byteSize(), b.byteSize());
  EXPECT_EQ(std::memcmp(a.bytes().data(), b.bytes().data(), a.byteSize()), 0);
}

TEST_F(DicomMultiFrame, EnhancedCtEqualsTheSingleFrameSeries) {
  const Volume single = readDicomSeries(at("single"));
  const glm::ivec3 dims(truth_["head_dims"][0], truth_["head_dims"][1], truth_["head_dims"][2]);
  ASSERT_EQ(single.dims(), dims);
  for (const auto& r : readers()) {
    for (const char* file : {"enhanced.dcm", "enhanced-rle.dcm"}) {
      SCOPED_TRACE(std::string(r.name) + " " + file);
      const Volume v = r.read(at(file), "");
      expectSameVoxels(v, single);
      EXPECT_LT(largestAffineDifference(v, single), 1e-4);
      // The rescale came from the shared Pixel Value Transformation.
      EXPECT_EQ(v.valueRange().min, single.valueRange().min);
      EXPECT_EQ(v.valueRange().max, 255.0);
      EXPECT_NE(v.description().find("rescale slope 1 intercept -1024 applied"), std::string::npos)
          << v.description();
    }
  }
}

// After writing NIfTI (what `tessera convert` does), nibabel finds the marker
// where the single-frame series (read by pydicom) puts it.
TEST_F(DicomMultiFrame, MarkerAfterConversionToNiftiIsWhereTheSeriesPutsIt) {
  const Volume v = readDicomSeries(at("enhanced.dcm"));
  const fs::path nifti = at("enhanced.nii.gz");
  writeVolume(v, nifti);
  const std::string cmd = kPython + " " + kTestsDir + "/geometry/marked_head.py marker " +
                          at("single").string() + " " + nifti.string();
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  ASSERT_EQ(pclose(p), 0) << cmd;
  const auto j = nlohmann::json::parse(out);
  const auto centre = [&](const fs::path& f) {
    const auto& c = j.at(f.string());
    return glm::dvec3(c[0], c[1], c[2]);
  };
  const double mm = glm::length(centre(nifti) - centre(at("single")));
  RecordProperty("marker_distance_mm", std::to_string(mm));
  std::printf("marker: single-frame series (pydicom) vs enhanced CT -> NIfTI (nibabel): %.6f mm\n",
              mm);
  EXPECT_LT(mm, 0.5);
  const glm::dvec3 truth(truth_["marker_ras"][0], truth_["marker_ras"][1], truth_["marker_ras"][2]);
  EXPECT_LT(glm::length(centre(nifti) - truth), 0.5);
}

TEST_F(DicomMultiFrame, TwoStacksAreListedAndEachSelectable) {
  const std::string uid = truth_["twostack"]["series"];
  const auto listed = listDicomSeries(at("twostack.dcm"));
  int found = 0;
  for (const auto& s : listed) {
    if (s.seriesInstanceUid != uid) continue;
    ++found;
    EXPECT_EQ(s.slices, truth_["twostack"]["stacks"][s.stack]["frames"].get<int>()) << s.stack;
    EXPECT_EQ(s.selector(), uid + ":" + s.stack);
  }
  EXPECT_EQ(found, 2);
  for (const auto& r : readers()) {
    for (const char* file : {"twostack.dcm", "twostack-rle.dcm"}) {
      SCOPED_TRACE(std::string(r.name) + " " + file);
      // The RLE copy is another series; its own UID (or none given) chooses it.
      const Volume byDefault = r.read(at(file), "");
      EXPECT_EQ(byDefault.dims(), glm::ivec3(32, 32, 24));  // the larger stack
      EXPECT_NE(byDefault.description().find("others: "), std::string::npos);
      const std::string ownUid = byDefault.description().substr(
          13, byDefault.description().find(':') - 13);  // "DICOM series UID:1 (..."
      for (const std::string stack : {"1", "2"}) {
        const Volume v = r.read(at(file), ownUid + ":" + stack);
        const auto& t = truth_["twostack"]["stacks"][stack];
        ASSERT_EQ(v.dims(), glm::ivec3(32, 32, t["frames"].get<int>())) << stack;
        const double base = stack == "1" ? 100 : 200;
        EXPECT_EQ(v.valueRange().min, base);
        EXPECT_EQ(v.valueRange().max, base + t["frames"].get<int>() - 1);
        // Frame z holds base + z: the stack's own frames, in their order.
        for (int z = 0; z < v.dims().z; ++z) {
          EXPECT_EQ(v.valueAt(5, 7, z), base + z) << stack << " z " << z;
        }
        const glm::dmat4 a = v.indexToWorld();
        double d = 0;
        for (int c = 0; c < 4; ++c) {
          for (int row = 0; row < 3; ++row) {
            d = std::max(d, std::abs(a[c][row] - t["affine"][row][c].get<double>()));
          }
        }
        EXPECT_LT(d, 1e-4) << stack;
      }
    }
  }
}

TEST_F(DicomMultiFrame, ClassicNmIsPlacedByItsDetectorPlaneAndStep) {
  for (const auto& r : readers()) {
    SCOPED_TRACE(r.name);
    const Volume v = r.read(at("classic-nm.dcm"), "");
    ASSERT_EQ(v.dims(), glm::ivec3(20, 16, 12));
    // Pixel Spacing 2.0 (rows) \ 2.5 (columns); Spacing Between Slices 3.5.
    EXPECT_EQ(v.spacing(), glm::dvec3(2.5, 2.0, 3.5));
    // IPP (10, -20, 30) LPS is (-10, 20, 30) RAS.
    EXPECT_LT(glm::length(v.origin() - glm::dvec3(-10, 20, 30)), 1e-9);
    for (int z = 0; z < 12; ++z) EXPECT_EQ(v.valueAt(3, 4, z), 10 + z);
  }
}

// The error of `read`, which must fail.
std::string errorOf(const std::function<void()>& read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "read without error";
  return "";
}

TEST_F(DicomMultiFrame, AFrameWithoutPositionIsRefusedNamingFileAndFrame) {
  for (const auto& r : readers()) {
    SCOPED_TRACE(r.name);
    const fs::path f = at("bad/no-position.dcm");
    const std::string m = errorOf([&] { r.read(f, ""); });
    EXPECT_NE(m.find(f.string() + ": frame 5 has no Plane Position (Patient) (0020,9113)"),
              std::string::npos)
        << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

TEST_F(DicomMultiFrame, NumberOfFramesThatLiesIsRefusedNamingFileAndFrame) {
  for (const auto& r : readers()) {
    SCOPED_TRACE(r.name);
    const fs::path f = at("bad/frames-lie.dcm");
    const std::string m = errorOf([&] { r.read(f, ""); });
    EXPECT_NE(m.find(f.string() + ": Number of Frames (0028,0008) is 26, but the pixel data has "
                                  "49152 bytes, 24 whole frames of 32x32 x 2 bytes: frame 25 "
                                  "has no pixels"),
              std::string::npos)
        << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

TEST_F(DicomMultiFrame, AnUnknownStackIsRefusedListingTheStacks) {
  const std::string uid = truth_["twostack"]["series"];
  test::TempDir alone;
  fs::copy_file(at("twostack.dcm"), alone / "twostack.dcm");
  const std::string m = errorOf([&] { readDicomSeries(alone.path(), uid + ":7"); });
  EXPECT_NE(m.find("no series " + uid + ":7"), std::string::npos) << m;
  EXPECT_NE(m.find(uid + ":1 (24 slices"), std::string::npos) << m;
  EXPECT_NE(m.find(uid + ":2 (20 slices"), std::string::npos) << m;
}

}  // namespace
}  // namespace tessera
