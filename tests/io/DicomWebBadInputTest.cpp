// DICOMweb answers no archive should give, from a server with canned answers
// (tests/io/DicomWebCannedServer.py): each is one InputError (or, for a
// server that keeps failing or is gone, one Error) naming the URL at fault,
// and the good answer beside them reads. Also the multipart parser and the
// DICOM JSON reading on their own.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <memory>

#include <nlohmann/json.hpp>

#include "io/DicomToolkit.h"
#include "io/DicomWebFrame.h"
#include "io/DicomWebParts.h"
#include "io/ZarrTestSupport.h"
#include "support/ExpectError.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/DicomWeb.h"
#include "tessera/io/VolumeReader.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

const fs::path kServer = fs::path(TESSERA_TEST_DATA_DIR) / ".." / "io" / "DicomWebCannedServer.py";
const std::string kSeries = "/dw/studies/1.2/series/3.4";
const std::string kOctet = "application/octet-stream; transfer-syntax=1.2.840.10008.1.2.1";

std::string hex(const std::string& bytes) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (unsigned char c : bytes) {
    out += digits[c >> 4];
    out += digits[c & 15];
  }
  return out;
}

// Metadata of a 4x4 u16 series `uid` of `slices` axial slices, 1 mm apart.
std::string metadata(int slices, const std::string& uid = "3.4") {
  nlohmann::json a = nlohmann::json::array();
  for (int k = 0; k < slices; ++k) {
    auto v = [](nlohmann::json value, const char* vr) {
      return nlohmann::json{{"vr", vr}, {"Value", value}};
    };
    a.push_back({{"00080018", v({"9." + std::to_string(k + 1)}, "UI")},
                 {"0020000E", v({uid}, "UI")},
                 {"00080060", v({"CT"}, "CS")},
                 {"00200013", v({k + 1}, "IS")},
                 {"00200032", v({-1.5, 2.25, k * 1.0}, "DS")},
                 {"00200037", v({1, 0, 0, 0, 1, 0}, "DS")},
                 {"00280030", v({0.5, 0.5}, "DS")},
                 {"00280010", v({4}, "US")},
                 {"00280011", v({4}, "US")},
                 {"00280100", v({16}, "US")},
                 {"00280101", v({16}, "US")},
                 {"00280102", v({15}, "US")},
                 {"00280103", v({0}, "US")},
                 {"00280002", v({1}, "US")},
                 {"00280004", v({"MONOCHROME2"}, "CS")},
                 {"7FE00010", {{"vr", "OW"}, {"BulkDataURI", "http://x/bulk"}}}});
  }
  return a.dump();
}

// A one-part multipart body holding `frame`.
std::string multipart(const std::string& boundary, const std::string& partType,
                      const std::string& frame) {
  return "--" + boundary + "\r\nContent-Type: " + partType +
         "\r\nContent-Length: " + std::to_string(frame.size()) + "\r\n\r\n" + frame + "\r\n--" +
         boundary + "--\r\n";
}

std::string pixels(int first) {
  std::string p;
  for (int i = 0; i < 16; ++i) {
    const int v = first + i;
    p += static_cast<char>(v & 0xff);
    p += static_cast<char>(v >> 8);
  }
  return p;
}

using Route = std::tuple<int, std::string, std::string>;  // status, content type, body

// The good series' routes under `series` (its UID the path's last part),
// `changes` (paths relative to the series) replacing some.
void addSeries(std::map<std::string, Route>& routes, const std::string& series,
               const std::map<std::string, Route>& changes) {
  routes[series + "/metadata"] = {200, "application/dicom+json",
                                  metadata(2, series.substr(series.rfind('/') + 1))};
  for (int k = 1; k <= 2; ++k) {
    routes[series + "/instances/9." + std::to_string(k) + "/frames/1"] = {
        200, "multipart/related; type=\"application/octet-stream\"; boundary=XyZ",
        multipart("XyZ", kOctet, pixels(100 * k))};
  }
  for (const auto& [path, route] : changes) routes[series + path] = route;
}

// The canned server, serving `routes` (plus the good series and an empty
// study list).
class Canned {
 public:
  Canned(const test::TempDir& dir, std::map<std::string, Route> routes, int dieAfter = -1) {
    addSeries(routes, kSeries, {});
    routes.emplace("/dw/studies", Route{200, "application/dicom+json", "[]"});
    nlohmann::json spec = {{"routes", nlohmann::json::object()}};
    for (const auto& [path, r] : routes) {
      spec["routes"][path] = {std::get<0>(r), std::get<1>(r), hex(std::get<2>(r))};
    }
    if (dieAfter >= 0) spec["die_after"] = dieAfter;
    const fs::path file = dir.path() / ("spec" + std::to_string(counter_++) + ".json");
    std::ofstream(file) << spec.dump();
    process_ = std::make_unique<test::ChildProcess>(
        std::vector<std::string>{"/usr/bin/python3", kServer.string(), file.string()});
    const std::string port = process_->readLine();
    if (port.empty() || !test::waitForPort(std::stoi(port), 10.0)) {
      throw std::runtime_error("the canned server did not start");
    }
    root_ = "http://127.0.0.1:" + port + "/dw";
  }
  std::string url(const std::string& path = kSeries) const {
    return root_.substr(0, root_.size() - 3) + path;
  }
  const std::string& root() const { return root_; }

 private:
  static inline int counter_ = 0;
  std::unique_ptr<test::ChildProcess> process_;
  std::string root_;
};

std::string frameUrl(const Canned& c, int k) {
  return c.url(kSeries + "/instances/9." + std::to_string(k) + "/frames/1");
}

std::string errorOf(const std::string& url) {
  try {
    readVolume(url);
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an error";
  return "";
}

class DicomWebBadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    ::setenv("TESSERA_HTTP_ATTEMPTS", "2", 1);  // the retries of a 500 are quick
    ::unsetenv("TESSERA_DICOMWEB_AUTH");
  }
  void TearDown() override { ::unsetenv("TESSERA_HTTP_ATTEMPTS"); }
  test::TempDir dir_;
};

TEST_F(DicomWebBadInput, TheGoodSeriesReadsWithItsGeometry) {
  const Canned c(dir_, {});
  const Volume v = readVolume(c.url());
  EXPECT_EQ(v.dims(), glm::ivec3(4, 4, 2));
  EXPECT_EQ(v.valueAtIndex(0), 100.0);
  EXPECT_EQ(v.valueAtIndex(16 + 15), 215.0);
  EXPECT_EQ(v.spacing(), glm::dvec3(0.5, 0.5, 1.0));
  // LPS (-1.5, 2.25, 0) is RAS (1.5, -2.25, 0).
  EXPECT_EQ(v.origin(), glm::dvec3(1.5, -2.25, 0.0));
}

TEST_F(DicomWebBadInput, EachBadAnswerIsOneLineNamingTheUrl) {
  const std::string frame2 = "/instances/9.2/frames/1";
  const std::string meta = "/metadata";
  const std::string multi = "multipart/related; type=\"application/octet-stream\"; boundary=XyZ";
  struct Case {
    std::string name;
    std::map<std::string, Route> changes;
    std::string at;  // the path the error names, under the series
    std::string message;
  };
  const std::vector<Case> cases = {
      {"metadata not JSON",
       {{meta, {200, "text/html", "<html>busy</html>"}}},
       meta,
       ": not JSON (17 bytes starting '<html>busy</html>'; parse error at byte 1)"},
      {"metadata a JSON object",
       {{meta, {200, "application/dicom+json", "{\"a\": 1}"}}},
       meta,
       ": JSON object, expected an array of DICOM JSON datasets"},
      {"metadata nested 5000 deep",
       {{meta, {200, "application/dicom+json", std::string(5000, '[') + std::string(5000, ']')}}},
       meta,
       ": JSON nested deeper than 194 levels; not DICOM JSON"},
      {"metadata item not an object",
       {{meta, {200, "application/dicom+json", "[1]"}}},
       meta,
       ": JSON array item 0 is number, expected a DICOM JSON dataset (object)"},
      {"403",
       {{meta, {403, "text/plain", "no"}}},
       meta,
       ": HTTP 403 Forbidden: the credentials given do not allow this"},
      {"500 every time",
       {{meta, {500, "text/plain", "oops"}}},
       meta,
       ": HTTP 500 (gave up after 2 attempts)"},
      {"wrong boundary",
       {{frame2, {200, multi, multipart("AbC", kOctet, pixels(0))}}},
       frame2,
       ": multipart body: the boundary 'XyZ' of its Content-Type never occurs (body starts "
       "'--AbC..Content-Type: application/octet-s...')"},
      {"no boundary parameter",
       {{frame2, {200, "multipart/related", multipart("XyZ", kOctet, pixels(0))}}},
       frame2,
       ": multipart body: Content-Type 'multipart/related' has no valid boundary parameter"},
      {"not multipart",
       {{frame2, {200, "application/octet-stream", pixels(0)}}},
       frame2,
       ": multipart body: Content-Type is 'application/octet-stream', expected "
       "multipart/related"},
      {"truncated: no close delimiter",
       {{frame2, {200, multi, "--XyZ\r\nContent-Type: " + kOctet + "\r\n\r\n" + pixels(0)}}},
       frame2,
       ": multipart body: part 1 never ends: no boundary after it (truncated?)"},
      {"part length lies",
       {{frame2,
         {200, multi, "--XyZ\r\nContent-Length: 100\r\n\r\n" + pixels(0) + "\r\n--XyZ--\r\n"}}},
       frame2,
       ": multipart body: part 1 declares Content-Length 100 but holds 32 bytes"},
      {"two parts for one frame",
       {{frame2,
         {200, multi,
          "--XyZ\r\n\r\n" + pixels(0) + "\r\n--XyZ\r\n\r\n" + pixels(0) + "\r\n--XyZ--\r\n"}}},
       frame2,
       ": multipart body: more than the 1 parts expected"},
      {"frame shorter than declared",
       {{frame2, {200, multi, multipart("XyZ", kOctet, pixels(0).substr(0, 20))}}},
       frame2,
       ": the frame decodes to 20 bytes, but 4x4 pixels x 2 bytes = 32 bytes"},
      {"corrupt JPEG 2000 frame",
       {{frame2,
         {200, multi,
          multipart("XyZ", "image/jp2; transfer-syntax=1.2.840.10008.1.2.4.90",
                    "\xff\x4f\xff\x51garbage")}}},
       frame2,
       ": "},
      {"corrupt JPEG lossless frame",
       {{frame2,
         {200, multi,
          multipart("XyZ", "image/jpeg; transfer-syntax=1.2.840.10008.1.2.4.70",
                    "\xff\xd8\xff\xc3garbage")}}},
       frame2,
       ": the JPEG Lossless"},
      {"unknown transfer syntax",
       {{frame2,
         {200, multi,
          multipart("XyZ", "application/octet-stream; transfer-syntax=1.2.3", pixels(0))}}},
       frame2,
       ": the frame's transfer syntax '1.2.3' is not one this build decodes (uncompressed, JPEG "
       "baseline/extended/lossless, JPEG-LS, RLE, JPEG 2000 and HTJ2K)"},
      {"frame larger than any 4x4 frame",
       {{frame2, {200, multi, std::string(70000, 'x')}}},
       frame2,
       ": more than 65600 bytes, more than any valid content of this key can have"},
      {"404 for a frame",
       {{frame2, {404, "text/plain", ""}}},
       frame2,
       ": HTTP 404 Not Found: no such study, series or instance, or not a DICOMweb service root"},
  };
  // One server, each case its own series (3.4.N); the HTTP failure memory
  // is per URL, so the cases do not see each other's errors.
  std::map<std::string, Route> routes;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    addSeries(routes, kSeries + "." + std::to_string(i), cases[i].changes);
  }
  const Canned c(dir_, routes);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Case& k = cases[i];
    SCOPED_TRACE(k.name);
    const std::string series = kSeries + "." + std::to_string(i);
    const std::string m = errorOf(c.url(series));
    EXPECT_EQ(m.rfind(c.url(series + k.at) + k.message, 0), 0u) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    std::printf("[bad input] %-30s %s\n", k.name.c_str(), m.c_str());
  }
}

TEST_F(DicomWebBadInput, QidoAnswerThatIsNotJsonNamesTheUrl) {
  const Canned c(dir_, {{"/dw/studies", {200, "text/plain", "Service Unavailable, try later"}}});
  const std::string m =
      test::inputErrorMessage([&] { DicomWebClient(c.root(), DicomWebOptions{}).studies(); });
  EXPECT_EQ(m.rfind(c.root() + "/studies?includefield=", 0), 0u) << m;
  EXPECT_NE(m.find(": not JSON (30 bytes starting 'Service Unavailable, try later'"),
            std::string::npos)
      << m;
}

TEST_F(DicomWebBadInput, ArchiveStoppedMidSeriesIsOneErrorNamingAFrameUrl) {
  // The archive answers the metadata and the first frame, then is gone.
  ::setenv("TESSERA_HTTP_CONNECTIONS", "1", 1);
  const Canned c(dir_, {}, 2);
  const std::string m = errorOf(c.url());
  ::unsetenv("TESSERA_HTTP_CONNECTIONS");
  EXPECT_EQ(m.rfind(frameUrl(c, 2) + ": ", 0), 0u) << m;
  EXPECT_NE(m.find("(gave up after 2 attempts)"), std::string::npos) << m;
  std::printf("[bad input] %-30s %s\n", "archive stopped mid-series", m.c_str());
}

TEST(DicomWebParts, MultipartSplitsPartsAndKeepsTheirBytes) {
  const std::string body =
      "preamble\r\n--b1\r\nContent-Type: image/jp2\r\n\r\nAB\r\nC"
      "\r\n--b1\r\n\r\n\r\n--b1--\r\nepilogue";
  const auto parts = io_detail::parseMultipart(
      "multipart/related; type=\"image/jp2\"; boundary=\"b1\"",
      {reinterpret_cast<const std::byte*>(body.data()), body.size()}, "u", 4);
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[0].contentType, "image/jp2");
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(parts[0].body.data()), parts[0].body.size()),
            "AB\r\nC");
  EXPECT_EQ(parts[1].body.size(), 0u);
  EXPECT_EQ(io_detail::frameTransferSyntax("image/jp2"), "1.2.840.10008.1.2.4.90");
  EXPECT_EQ(io_detail::frameTransferSyntax("image/jp2; transfer-syntax=1.2.840.10008.1.2.4.91"),
            "1.2.840.10008.1.2.4.91");
  EXPECT_EQ(*io_detail::mediaParameter(
                "multipart/related; type=\"image/jp2; transfer-syntax=1.2\"; boundary=x", "type"),
            "image/jp2; transfer-syntax=1.2");
}

// Found by fuzz_functional_groups: a number no double holds made
// nlohmann::json throw out_of_range, which escaped as no InputError.
TEST(DicomWebParts, DicomJsonWithANumberTooLargeIsOneLine) {
  const std::string text = R"([{"00280008": {"vr": "IS", "Value": [1e999]}}])";
  const std::string m = test::inputErrorMessage([&] {
    io_detail::parseDicomJson(
        std::span(reinterpret_cast<const std::byte*>(text.data()), text.size()), "meta");
  });
  EXPECT_EQ(m.rfind("meta: not DICOM JSON (46 bytes starting", 0), 0u) << m;
  EXPECT_NE(m.find("): a number too large for a double"), std::string::npos) << m;
}

// Found by fuzz_dicomweb (a > 5 s timeout): DCMTK 3.6.7's JPEG decoder
// looks for the frame header's precision first and loops for ever on a TEM
// marker (FF01) before it. The frame is refused in one line instead.
TEST(DicomWebFrame, JpegFrameWithATemMarkerBeforeItsHeaderIsRefused) {
  io_detail::Slice slice;
  slice.rows = 64;
  slice.columns = 64;
  slice.bitsAllocated = 16;
  slice.bitsStored = 16;
  slice.highBit = 15;
  slice.isSigned = true;
  slice.photometric = "MONOCHROME2";
  // SOI, a 16-byte JFIF APP0, then TEM where the SOF3 header was (the
  // fuzzer's input, shortened), then a lossless frame header and noise.
  std::vector<std::uint8_t> frame = {0xFF, 0xD8, 0xFF, 0xE0, 0x00, 0x10, 'J',  'F',  'I',  'F',
                                     0x00, 0x01, 0x01, 0x00, 0x00, 0x01, 0x00, 0x01, 0x00, 0x00,
                                     0xFF, 0x01, 0x0B, 0x00, 0x10, 0x00, 0x40, 0x00, 0x40, 0x01,
                                     0xFF, 0xC3, 0x00, 0x0B, 0x10, 0x00, 0x40, 0x00, 0x40, 0x01};
  for (int i = 0; i < 200; ++i) frame.push_back(static_cast<std::uint8_t>(i * 37 + 11));
  const auto decode = [&](const std::string& syntax) {
    return test::inputErrorMessage([&] {
      io_detail::decodeWebFrame(
          slice, syntax, {reinterpret_cast<const std::byte*>(frame.data()), frame.size()}, "f.jpg");
    });
  };
  for (const char* syntax : {"1.2.840.10008.1.2.4.70", "1.2.840.10008.1.2.4.57",
                             "1.2.840.10008.1.2.4.50", "1.2.840.10008.1.2.4.51"}) {
    EXPECT_EQ(decode(syntax),
              "f.jpg: the JPEG frame has a TEM marker (FF01) at byte 20 before its frame header, "
              "which DCMTK's JPEG decoder cannot pass (corrupt frame?)")
        << syntax;
  }
  // JPEG-LS has its own header reading: the check is the JPEG 1992 one only.
  const std::span<const std::uint8_t> bytes(frame);
  EXPECT_NO_THROW(io_detail::checkJpegFragment(EXS_JPEGLSLossless, bytes, "f.jls"));
  // With the marker after the frame header the precision scan ends first.
  frame[20] = 0xFF;
  frame[21] = 0xC3;
  frame[30] = 0xFF;
  frame[31] = 0x01;
  EXPECT_NO_THROW(io_detail::checkJpegFragment(EXS_JPEGProcess14, bytes, "f.jpg"));
}

TEST(DicomWebParts, DicomJsonGivesTheTextsTheFolderReaderReads) {
  const auto j = nlohmann::json::parse(
      R"([{"00200032": {"vr": "DS", "Value": [-83.9063, 0.1, 1e-7]},
           "00100010": {"vr": "PN", "Value": [{"Alphabetic": "DOE^JANE"}]},
           "00280010": {"vr": "US", "Value": [512]},
           "00080050": {"vr": "SH"},
           "00280030": {"vr": "DS", "Value": ["0.5", "0.25"]}}])");
  const io_detail::DicomJsonAttributes a(j[0]);
  EXPECT_EQ(*a.text({0x0020, 0x0032}), "-83.9063\\0.1\\1e-07");
  EXPECT_EQ(*a.text({0x0010, 0x0010}), "DOE^JANE");
  EXPECT_EQ(*a.uint16({0x0028, 0x0010}), 512);
  EXPECT_EQ(*a.text({0x0008, 0x0050}), "");
  EXPECT_EQ(*a.text({0x0028, 0x0030}), "0.5\\0.25");
  EXPECT_FALSE(a.text({0x0028, 0x0011}).has_value());
}

}  // namespace
}  // namespace tessera
