// DICOMweb against a real PACS: Orthanc with its DICOMweb plugin, started by
// the suite (tests/support/OrthancServer.h). One CT series written by
// writeDicomSeries is stored four times: uncompressed, JPEG lossless (DCMTK's
// dcmcjpeg), JPEG 2000 lossless (OpenJPEG's opj_compress) and HTJ2K lossless
// (OpenJPH's ojph_compress), each under its own Series Instance UID; read over
// WADO-RS (frames as stored; HTJ2K, whose frames Debian's Orthanc 1.10 does
// not send alone (HTTP 500), as whole instances), each must equal the folder
// read voxel for voxel with the same affine. An Enhanced CT object (one file,
// the marked head's frames in reverse order; native and RLE) read over
// DICOMweb equals the same file read from disk. QIDO lists them; 401 and 404
// are one line naming the URL.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>

#include "io/IoFixtures.h"
#include "support/ExpectError.h"
#include "support/OrthancServer.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/io/DicomWeb.h"
#include "tessera/io/VolumeReader.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

const fs::path kEncode = fs::path(TESSERA_TEST_DATA_DIR) / ".." / "io" / "DicomWebEncode.py";
const fs::path kMultiFrame = fs::path(TESSERA_TEST_DATA_DIR) / ".." / "io" / "make_multiframe.py";
// The enhanced objects stored, each read from its own folder too.
constexpr const char* kEnhanced[] = {"enhanced.dcm", "enhanced-rle.dcm"};
// An Enhanced MR object of two stacks (axial "1", 24 frames; sagittal "2", 20).
constexpr const char* kTwoStacks = "twostack.dcm";
constexpr const char* kSeriesUid = "1.2.826.0.1.3680043.10.543.77";

// A 40x32x12 CT-like i16 volume (-1024 air, noisy tissue, a bright marker
// at voxel (5,7,3)), oblique, anisotropic: what the reads must agree on.
Volume ctVolume() {
  Volume v = Volume::allocate({40, 32, 12}, ScalarType::I16, "ct");
  std::mt19937 rng(7);
  for (int z = 0; z < 12; ++z) {
    for (int y = 0; y < 32; ++y) {
      for (int x = 0; x < 40; ++x) {
        const double r = std::hypot(x - 20.0, y - 16.0);
        const int value = r < 14 ? 40 + static_cast<int>(rng() % 200) : -1024;
        v.setValueAtIndex(x + 40 * (y + 32 * static_cast<std::size_t>(z)), value);
      }
    }
  }
  v.setValueAtIndex(5 + 40 * (7 + 32 * 3), 3000);
  v.invalidateRange();
  v.setSpacing({0.7, 0.8, 2.5});
  v.setOrigin({-12.5, 30.25, 7.0});
  const double a = 0.3;
  v.setDirection(glm::dmat3(std::cos(a), std::sin(a), 0, -std::sin(a), std::cos(a), 0, 0, 0, 1));
  return v;
}

struct StoredSeries {
  std::string kind;
  std::string seriesUid;
  std::string transferSyntax;
};

class DicomWebOrthanc : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!test::OrthancServer::missing().empty()) return;
    dir_ = new test::TempDir;
    const fs::path plain = dir_->path() / "plain";
    DicomWriteOptions o;
    o.seriesInstanceUid = kSeriesUid;
    o.seriesDescription = "tessera dicomweb test";
    o.modality = "CT";
    writeDicomSeries(ctVolume(), plain, o);
    const std::pair<const char*, const char*> kinds[] = {
        {"jpeg-lossless", "2"}, {"j2k-lossless", "3"}, {"htj2k-lossless", "4"}};
    for (const auto& [kind, suffix] : kinds) {
      const std::string cmd = "/usr/bin/python3 '" + kEncode.string() + "' '" + plain.string() +
                              "' '" + (dir_->path() / kind).string() + "' " + kind + " " + suffix;
      if (std::system((cmd + " >/dev/null 2>&1").c_str()) != 0) {
        setupError_ = "encoding failed: " + cmd;
        return;
      }
    }
    const fs::path mf = dir_->path() / "multiframe";
    const std::string make =
        "/usr/bin/python3 '" + kMultiFrame.string() + "' '" + mf.string() + "'";
    if (std::system((make + " >/dev/null 2>&1").c_str()) != 0) {
      setupError_ = "writing the multi-frame objects failed: " + make;
      return;
    }
    for (const char* name : kEnhanced) {
      fs::create_directories(dir_->path() / "upload-mf" / name);
      fs::copy_file(mf / name, dir_->path() / "upload-mf" / name / name);
    }
    fs::create_directories(dir_->path() / "upload-mf" / kTwoStacks);
    fs::copy_file(mf / kTwoStacks, dir_->path() / "upload-mf" / kTwoStacks / kTwoStacks);
    orthanc_ = new test::OrthancServer(dir_->path() / "orthanc");
    for (const char* kind : {"plain", "jpeg-lossless", "j2k-lossless", "htj2k-lossless"}) {
      if (!orthanc_->upload(dir_->path() / kind)) setupError_ = std::string("upload of ") + kind;
    }
    for (const char* name : {kEnhanced[0], kEnhanced[1], kTwoStacks}) {
      if (!orthanc_->upload(dir_->path() / "upload-mf" / name)) {
        setupError_ = std::string("upload of ") + name;
      }
    }
  }
  static void TearDownTestSuite() {
    delete orthanc_;  // stopped here, also when a test failed
    orthanc_ = nullptr;
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    if (const std::string m = test::OrthancServer::missing(); !m.empty()) GTEST_SKIP() << m;
    ASSERT_TRUE(setupError_.empty()) << setupError_;
  }

  // The study that holds `seriesUid`, found through QIDO.
  static std::string studyUid(const std::string& seriesUid = kSeriesUid) {
    const DicomWebClient client(orthanc_->dicomWebRoot(), DicomWebOptions{});
    for (const DicomWebStudy& study : client.studies()) {
      for (const DicomWebSeries& s : client.series(study.uid)) {
        if (s.uid == seriesUid) return study.uid;
      }
    }
    return "";
  }
  static std::string seriesUrl(const std::string& seriesUid) {
    return orthanc_->dicomWebRoot() + "/studies/" + studyUid(seriesUid) + "/series/" + seriesUid;
  }

  static test::TempDir* dir_;
  static test::OrthancServer* orthanc_;
  static std::string setupError_;
};
test::TempDir* DicomWebOrthanc::dir_ = nullptr;
test::OrthancServer* DicomWebOrthanc::orthanc_ = nullptr;
std::string DicomWebOrthanc::setupError_;

const StoredSeries kStored[] = {
    {"uncompressed", kSeriesUid, "1.2.840.10008.1.2.1"},
    {"JPEG lossless", std::string(kSeriesUid) + ".2", "1.2.840.10008.1.2.4.70"},
    {"JPEG 2000 lossless", std::string(kSeriesUid) + ".3", "1.2.840.10008.1.2.4.90"},
    {"HTJ2K lossless", std::string(kSeriesUid) + ".4", "1.2.840.10008.1.2.4.201"},
};

// One test, as the suite's setup (encoding, Orthanc, uploads) is most of
// its time and ctest runs each test in its own process.
void expectEnhancedReadLikeTheFile(const fs::path& uploaded,
                                   const std::function<std::string(const std::string&)>& url);
void expectStacksChosenByUrlLikeTheFile(const fs::path& uploaded,
                                        const std::function<std::string(const std::string&)>& url);

TEST_F(DicomWebOrthanc, StoredSyntaxesAndEnhancedCtReadLikeTheFolderQidoListsThemUnknownIs404) {
  const Volume folder = readVolume((dir_->path() / "plain").string());
  const std::string study = studyUid();
  ASSERT_FALSE(study.empty());
  for (const StoredSeries& s : kStored) {
    SCOPED_TRACE(s.kind);
    DicomWebTransfer transfer;
    const Volume web = readDicomWebSeries(seriesUrl(s.seriesUid), &transfer);
    test::expectSameVolume(web, folder);
    EXPECT_EQ(web.indexToWorld(), folder.indexToWorld());
    EXPECT_EQ(web.direction(), folder.direction());
    EXPECT_EQ(web.valueAtIndex(5 + 40 * (7 + 32 * 3)), 3000.0);  // the marker, in place
    EXPECT_EQ(transfer.transferSyntaxes, std::vector<std::string>{s.transferSyntax});
    const bool htj2k = s.transferSyntax == "1.2.840.10008.1.2.4.201";
    // The metadata and one request per frame; for HTJ2K, which Orthanc 1.10
    // does not send as frames (HTTP 500), the first frame asked once and
    // then the 12 instances whole.
    EXPECT_EQ(transfer.requests, htj2k ? 14u : 13u);
    EXPECT_EQ(transfer.wholeInstances, htj2k ? 12u : 0u);
    EXPECT_NE(web.description().find(s.transferSyntax), std::string::npos) << web.description();
    if (htj2k) {
      EXPECT_NE(web.description().find("12 instances retrieved whole: the archive does not send "
                                       "their frames alone"),
                std::string::npos)
          << web.description();
    }
  }

  // QIDO: the CT study and its four series; the enhanced objects' study and
  // the two-stack object's.
  const DicomWebClient client(orthanc_->dicomWebRoot(), DicomWebOptions{});
  const auto studies = client.studies();
  ASSERT_EQ(studies.size(), 3u);
  const auto ct = std::find_if(studies.begin(), studies.end(),
                               [&](const DicomWebStudy& s) { return s.uid == study; });
  ASSERT_NE(ct, studies.end());
  EXPECT_EQ(ct->modalities, "CT");
  EXPECT_EQ(ct->series, 4);
  EXPECT_EQ(ct->instances, 48);
  const auto series = client.series(study);
  ASSERT_EQ(series.size(), 4u);
  for (const auto& s : series) {
    EXPECT_EQ(s.modality, "CT");
    EXPECT_EQ(s.instances, 12);
    EXPECT_EQ(s.description, "tessera dicomweb test");
    EXPECT_TRUE(isDicomWebSeriesUrl(s.url)) << s.url;
  }
  EXPECT_TRUE(client.studies("PatientName=NOBODY*").empty());

  // A series the archive does not hold.
  const std::string url = orthanc_->dicomWebRoot() + "/studies/" + study + "/series/1.2.3.999";
  const std::string m = test::inputErrorMessage([&] { readVolume(url); });
  EXPECT_EQ(m, url +
                   "/metadata: HTTP 404 Not Found: no such study, series or instance, or not a "
                   "DICOMweb service root");

  expectEnhancedReadLikeTheFile(dir_->path() / "upload-mf", seriesUrl);
  expectStacksChosenByUrlLikeTheFile(dir_->path() / "upload-mf", seriesUrl);
}

// Enhanced CT objects (one file of 90 frames stored in reverse z order,
// placed by their functional groups; native and RLE Lossless with two
// fragments per frame) over DICOMweb: the same volume and affine as the
// same file read from disk, its frames asked 64 to a request.
// (Part of the suite's one test: ctest runs each test in its own process,
// and the suite's setup is most of its time.)
void expectEnhancedReadLikeTheFile(const fs::path& uploaded,
                                   const std::function<std::string(const std::string&)>& url) {
  for (const char* name : kEnhanced) {
    SCOPED_TRACE(name);
    const fs::path folder = uploaded / name;
    const Volume local = readVolume((folder / name).string());
    const auto listed = listDicomSeries(folder);
    ASSERT_EQ(listed.size(), 1u);
    DicomWebTransfer transfer;
    const Volume web = readDicomWebSeries(url(listed[0].seriesInstanceUid), &transfer);
    test::expectSameVolume(web, local);
    EXPECT_EQ(web.indexToWorld(), local.indexToWorld());
    EXPECT_EQ(web.dims(), local.dims());
    EXPECT_GT(web.dims().z, 40);
    // The metadata, and the object's frames 64 to a request.
    EXPECT_EQ(transfer.requests, 1u + static_cast<std::uint64_t>(web.dims().z + 63) / 64)
        << web.description();
    EXPECT_EQ(transfer.wholeInstances, 0u);
  }
}

TEST(DicomWebAuth, OrthancWithAuthenticationWants401CredentialsAndNeverPrintsThem) {
  if (const std::string m = test::OrthancServer::missing(); !m.empty()) GTEST_SKIP() << m;
  test::TempDir dir;
  DicomWriteOptions o;
  o.seriesInstanceUid = kSeriesUid;
  o.modality = "CT";
  writeDicomSeries(ctVolume(), dir.path() / "plain", o);
  test::OrthancServer orthanc(dir.path() / "orthanc", "alice", "s3cret-pw");
  ASSERT_TRUE(orthanc.upload(dir.path() / "plain"));
  const std::string studies = orthanc.dicomWebRoot() +
                              "/studies?includefield=00081030&"
                              "includefield=00080061&includefield="
                              "00201206&includefield=00201208";
  // No credentials: 401, and how to give them.
  const std::string none = test::inputErrorMessage(
      [&] { DicomWebClient(orthanc.dicomWebRoot(), DicomWebOptions{}).studies(); });
  EXPECT_EQ(none.rfind(studies + ": HTTP 401 Unauthorized: the server wants credentials", 0), 0u)
      << none;
  EXPECT_NE(none.find("TESSERA_DICOMWEB_AUTH"), std::string::npos);
  // Wrong ones: refused, and the header's value is not in the message.
  DicomWebOptions wrong;
  wrong.headers = {"Authorization: Basic YWxpY2U6d3Jvbmc="};  // alice:wrong
  const std::string refused =
      test::inputErrorMessage([&] { DicomWebClient(orthanc.dicomWebRoot(), wrong).studies(); });
  EXPECT_EQ(refused, studies + ": HTTP 401 Unauthorized: the credentials given were refused");
  EXPECT_EQ(refused.find("YWxpY2U6d3Jvbmc"), std::string::npos);
  // The right ones from the environment: the series reads.
  ::setenv("TESSERA_DICOMWEB_AUTH", "Basic YWxpY2U6czNjcmV0LXB3", 1);  // alice:s3cret-pw
  const DicomWebClient client(orthanc.dicomWebRoot());
  const auto list = client.studies();
  ASSERT_EQ(list.size(), 1u);
  const Volume v =
      readVolume(orthanc.dicomWebRoot() + "/studies/" + list[0].uid + "/series/" + kSeriesUid);
  ::unsetenv("TESSERA_DICOMWEB_AUTH");
  test::expectSameVolume(v, readVolume((dir.path() / "plain").string()));
}

TEST(DicomWebUrl, SeriesUrlsAreRecognisedAndSplit) {
  EXPECT_TRUE(isDicomWebSeriesUrl("http://h:8042/dicom-web/studies/1.2/series/3.4"));
  EXPECT_TRUE(isDicomWebSeriesUrl("https://h/wado/studies/1.2/series/3.4/"));
  EXPECT_FALSE(isDicomWebSeriesUrl("http://h/dicom-web/studies/1.2"));
  EXPECT_FALSE(isDicomWebSeriesUrl("http://h/store.ome.zarr"));
  EXPECT_FALSE(isDicomWebSeriesUrl("http://h/studies/1.2/series/3.4/instances/5"));
  EXPECT_FALSE(isDicomWebSeriesUrl("/data/studies/1.2/series/3.4"));
  const DicomWebSeriesUrl u =
      parseDicomWebSeriesUrl("http://h:8042/dicom-web/studies/1.2/series/3.4/");
  EXPECT_EQ(u.root, "http://h:8042/dicom-web");
  EXPECT_EQ(u.study, "1.2");
  EXPECT_EQ(u.series, "3.4");
}

// A series of two stacks over DICOMweb: listed as `info` lists a folder's
// (the same selectors and slice counts), each chosen by `--series UID:stack`
// on the URL exactly as on the file, the largest by default with the other
// named; an unknown stack is refused listing both, another series' UID
// naming the URL's.
void expectStacksChosenByUrlLikeTheFile(const fs::path& uploaded,
                                        const std::function<std::string(const std::string&)>& url) {
  const fs::path file = uploaded / kTwoStacks / kTwoStacks;
  const auto local = listDicomSeries(file.parent_path());
  ASSERT_EQ(local.size(), 2u);
  const std::string uid = local[0].seriesInstanceUid;
  const std::string series = url(uid);
  const auto listed = listDicomWebSeries(series);
  ASSERT_EQ(listed.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(listed[i].selector(), local[i].selector());
    EXPECT_EQ(listed[i].slices, local[i].slices);
    EXPECT_EQ(listed[i].description, local[i].description);
  }
  EXPECT_EQ(listed[0].selector(), uid + ":1");
  EXPECT_EQ(listed[0].slices, 24);
  EXPECT_EQ(listed[1].selector(), uid + ":2");
  EXPECT_EQ(listed[1].slices, 20);
  for (const std::string stack : {"1", "2"}) {
    SCOPED_TRACE("stack " + stack);
    const std::string select = uid + ":" + stack;
    const Volume fromFile = readVolume(file.string(), {.dicomSeries = select});
    DicomWebTransfer transfer;
    const Volume web = readDicomWebSeries(series, &transfer, select);
    test::expectSameVolume(web, fromFile);
    EXPECT_EQ(web.indexToWorld(), fromFile.indexToWorld());
    EXPECT_EQ(web.dims().z, stack == "1" ? 24 : 20);
    // Frame z of stack "1" holds 100 + z, of "2" 200 + z: the stack asked for.
    EXPECT_EQ(web.valueAt(5, 7, 3), (stack == "1" ? 100 : 200) + 3);
    // The metadata, and the object's 44 frames in one request.
    EXPECT_EQ(transfer.requests, 2u);
    EXPECT_EQ(readVolume(series, {.dicomSeries = select}).indexToWorld(), web.indexToWorld());
  }
  // No selection: the larger stack, the other named in the description.
  const Volume largest = readVolume(series);
  EXPECT_EQ(largest.dims().z, 24);
  EXPECT_NE(largest.description().find("others: " + uid + ":2 (20 slices of "), std::string::npos)
      << largest.description();
  const std::string unknown =
      test::inputErrorMessage([&] { readVolume(series, {.dicomSeries = uid + ":7"}); });
  EXPECT_EQ(unknown.rfind(series + ": no series " + uid +
                              ":7 (Series Instance UID, or UID:stack); found: " + uid +
                              ":1 (24 slices of ",
                          0),
            0u)
      << unknown;
  EXPECT_NE(unknown.find(", " + uid + ":2 (20 slices of "), std::string::npos) << unknown;
  const std::string other =
      test::inputErrorMessage([&] { readVolume(series, {.dicomSeries = "1.2.3:1"}); });
  EXPECT_EQ(other, series + ": --series 1.2.3:1 is not the series the URL names (" + uid + ", or " +
                       uid + ":STACK for one of its stacks; `tessera info URL` lists them)");
}

}  // namespace
}  // namespace tessera
