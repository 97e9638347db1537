// The format registry: every writer round-trips through readVolume, the
// sniffers find each format under a misleading name, contradicting or
// impossible names give errors that name the file, and the DICOM decoder
// is chosen by transfer syntax and by where the files are.
#include "tessera/io/FormatRegistry.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "io/HeaderText.h"
#include "io/IoFixtures.h"
#include "tessera/core/Error.h"
#include "tessera/io/DicomDecoder.h"
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/VolumeWriter.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

constexpr const char* kJpegBaseline = "1.2.840.10008.1.2.4.50";
constexpr const char* kJpegLs = "1.2.840.10008.1.2.4.80";
constexpr const char* kJpeg2000 = "1.2.840.10008.1.2.4.90";
constexpr const char* kExplicitLe = "1.2.840.10008.1.2.1";
constexpr const char* kRle = "1.2.840.10008.1.2.5";

std::string readBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

// A u8 volume with geometry every format keeps (spacing; an origin of 0 and
// no rotation, which PVM drops).
Volume phantom() {
  Volume v = makeSheppLogan({11, 9, 7});
  v.setSpacing({0.5, 0.75, 1.25});
  return v;
}

void expectSameVoxels(const Volume& got, const Volume& want, const std::string& what) {
  ASSERT_EQ(got.dims(), want.dims()) << what;
  ASSERT_EQ(got.type(), want.type()) << what;
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(got.spacing()[a], want.spacing()[a], 1e-6) << what;
  EXPECT_TRUE(std::equal(got.bytes().begin(), got.bytes().end(), want.bytes().begin())) << what;
}

TEST(FormatRegistry, EveryWriterRoundTripsThroughReadVolume) {
  test::TempDir dir;
  const Volume v = phantom();
  int written = 0;
  for (const VolumeFormat& f : volumeFormats()) {
    if (!f.write) continue;
    for (const std::string& e : f.writeExtensions) {
      const fs::path out =
          e == "/" ? fs::path((dir / (f.id + "-folder")).string() + "/") : dir / (f.id + e);
      ASSERT_EQ(formatForWriteName(out), &f) << out;
      writeVolume(v, out);
      expectSameVoxels(readVolume(out.string()), v, out.string());
      ++written;
    }
  }
  // NIfTI x2, NRRD, MetaImage, VTI, PVM, raw, DICOM x2, OME-Zarr x2.
  EXPECT_EQ(written, 11);
}

TEST(FormatRegistry, SnifferOpensEachFormatUnderAMisleadingName) {
  test::TempDir dir;
  const Volume v = phantom();
  int sniffed = 0;
  for (const VolumeFormat& f : volumeFormats()) {
    if (!f.sniff || !f.write) continue;
    for (const std::string& e : f.writeExtensions) {
      if (e == ".dcm.d") continue;  // the same DICOM files as "/"
      const fs::path sub = dir / (f.id + std::to_string(sniffed));
      fs::create_directories(sub);
      const fs::path out = e == "/" ? fs::path((sub / "series").string() + "/") : sub / ("v" + e);
      writeVolume(v, out);
      fs::path misleading = sub / "scan.dat";
      if (e == "/") {
        // Every slice renamed to .dat: the series is found by content.
        int i = 0;
        for (const auto& entry : fs::directory_iterator(out)) {
          fs::rename(entry.path(), sub / ("slice" + std::to_string(i++) + ".dat"));
        }
        misleading = sub / "slice0.dat";
      } else {
        fs::rename(out, misleading);
      }
      EXPECT_EQ(&chooseReadFormat(FileSource(misleading)), &f) << f.id << " " << e;
      expectSameVoxels(readVolume(misleading.string()), v, f.id + " as " + misleading.string());
      ++sniffed;
    }
  }
  // NIfTI (.nii.gz inside gzip, .nii), NRRD, MetaImage, VTI, PVM, DICOM.
  EXPECT_EQ(sniffed, 7);
}

TEST(FormatRegistry, ContentWinsOverAContradictingExtension) {
  test::TempDir dir;
  const Volume v = phantom();
  writeVolume(v, dir / "real.nii");
  fs::rename(dir / "real.nii", dir / "actually-nifti.nrrd");
  expectSameVoxels(readVolume((dir / "actually-nifti.nrrd").string()), v, "NIfTI named .nrrd");
  // The same through a byte source held in memory (the browser's path).
  MemoryFiles files;
  const std::string bytes = readBytes(dir / "actually-nifti.nrrd");
  files.add("scan.nrrd", std::vector<std::byte>(
                             reinterpret_cast<const std::byte*>(bytes.data()),
                             reinterpret_cast<const std::byte*>(bytes.data()) + bytes.size()));
  const auto source = files.open("scan.nrrd");
  expectSameVoxels(readVolume(*source, files), v, "NIfTI named .nrrd in memory");
}

const std::string kPng = std::string("\x89PNG\r\n\x1a\n", 8) + std::string(64, '\0');

TEST(FormatRegistry, ImpossibleNamesAreClearErrorsNamingTheFile) {
  test::TempDir dir;
  test::writeFile(dir / "text.nii.gz", "hello, this is not a volume\n");
  test::expectRejected<InputError>(
      [&] { readVolume((dir / "text.nii.gz").string()); },
      {"text.nii.gz", "named .nii.gz", "not gzip", "text starting 'hello, this is not a volume'"});
  test::writeFile(dir / "picture.nii.gz", kPng);
  test::expectRejected<InputError>([&] { readVolume((dir / "picture.nii.gz").string()); },
                                   {"picture.nii.gz", "not gzip", "a PNG image"});
  test::writeFile(dir / "picture.nrrd", kPng);
  test::expectRejected<InputError>(
      [&] { readVolume((dir / "picture.nrrd").string()); },
      {"picture.nrrd", "not a NRRD file", "a PNG image (starts 89 50 4e 47 0d 0a 1a 0a)"});
  // gzip holding a PNG, named as a NIfTI.
  test::writeFile(dir / "zipped.nii.gz", test::gzipBytes(kPng));
  test::expectRejected<InputError>(
      [&] { readVolume((dir / "zipped.nii.gz").string()); },
      {"zipped.nii.gz", "not a NIfTI file", "gzip data holding a PNG"});
  // Unknown name, unknown bytes: the supported list and what the bytes are.
  test::writeFile(dir / "blob.bin", std::string("\x01\x02\x03\x04", 4));
  test::expectRejected<InputError>([&] { readVolume((dir / "blob.bin").string()); },
                                   {"blob.bin", "unknown volume format", ".nii.gz", ".nrrd",
                                    "binary data starting 01 02 03 04"});
}

TEST(FormatRegistry, UncompressedNiftiNamedNiiGzStillOpens) {
  test::TempDir dir;
  const Volume v = phantom();
  writeVolume(v, dir / "plain.nii");
  fs::rename(dir / "plain.nii", dir / "plain.nii.gz");
  expectSameVoxels(readVolume((dir / "plain.nii.gz").string()), v, ".nii.gz without gzip");
}

TEST(FormatRegistry, ExtensionsAreUniqueAndLowerCase) {
  std::set<std::string> read;
  std::set<std::string> ids;
  for (const VolumeFormat& f : volumeFormats()) {
    EXPECT_TRUE(ids.insert(f.id).second) << f.id;
    EXPECT_FALSE(f.extensions.empty()) << f.id;
    for (const std::string& e : f.extensions) {
      EXPECT_TRUE(read.insert(e).second) << e << " is claimed twice";
      EXPECT_EQ(e, io_detail::lower(e)) << e;
    }
    std::set<std::string> written;
    for (const std::string& e : f.writeExtensions) {
      EXPECT_TRUE(written.insert(e).second) << e;
    }
  }
  // Longest match first: ".nii.gz" is NIfTI, ".ome.zarr" OME-Zarr.
  EXPECT_EQ(formatForReadName("A.NII.GZ")->id, "nifti");
  EXPECT_EQ(formatForReadName("x.raw")->id, "raw");
  EXPECT_EQ(formatForReadName("x.img"), nullptr) << "a companion is never read on its own";
  EXPECT_EQ(formatForWriteName("out.ome.zarr/")->id, "ome-zarr");
  EXPECT_EQ(formatForWriteName("series/")->id, "dicom");
  EXPECT_EQ(formatForWriteName("series.dcm.d")->id, "dicom");
  EXPECT_EQ(formatForWriteName("x.xyz"), nullptr);
}

TEST(FormatRegistry, BrowserAcceptListHasEveryBrowserReadableFile) {
  const std::string accept = browserAcceptList();
  for (const char* e : {".gz", ".nii", ".hdr", ".img", ".nrrd", ".nhdr", ".mha", ".mhd", ".raw",
                        ".zraw", ".vti", ".pvm", ".json", ".dcm", "application/gzip"}) {
    EXPECT_NE(("," + accept + ",").find(std::string(",") + e + ","), std::string::npos)
        << e << " missing from " << accept;
  }
  EXPECT_EQ(accept.find(".zarr"), std::string::npos) << "stores are opened by URL, not picked";
}

TEST(DicomDecoder, ChosenByTransferSyntaxAndWhereTheFilesAre) {
  const FolderFiles disk;
  const MemoryFiles memory;
  const DicomDecoder& dcmtk = dcmtkDicomDecoder();
  const DicomDecoder& basic = basicDicomDecoder();
  ASSERT_EQ(dicomDecoders().size(), 2u);
  EXPECT_EQ(dicomDecoders().front(), &dcmtk) << "the native build prefers DCMTK";

  EXPECT_TRUE(basic.canDecode(kExplicitLe));
  EXPECT_TRUE(basic.canDecode(kRle));
  EXPECT_FALSE(basic.canDecode(kJpegBaseline));
  EXPECT_FALSE(basic.canDecode(kJpegLs));
  EXPECT_TRUE(basic.canDecode(kJpeg2000));                  // OpenJPEG
  EXPECT_TRUE(basic.canDecode("1.2.840.10008.1.2.4.201"));  // HTJ2K: OpenJPH, guarded
  EXPECT_TRUE(dcmtk.canDecode(kExplicitLe));
  EXPECT_TRUE(dcmtk.canDecode(kJpegBaseline));
  EXPECT_TRUE(dcmtk.canDecode(kJpegLs));
  EXPECT_FALSE(dcmtk.canDecode(kJpeg2000)) << "free DCMTK has no JPEG 2000 codec";
  EXPECT_FALSE(dcmtk.canDecode("1.2.3.4.not-a-syntax"));

  const auto& ranked = dicomDecoders();
  EXPECT_EQ(chooseDicomDecoder(ranked, {kExplicitLe}, disk), &dcmtk);
  EXPECT_EQ(chooseDicomDecoder(ranked, {kJpegLs, kRle}, disk), &dcmtk);
  EXPECT_EQ(chooseDicomDecoder(ranked, {kExplicitLe, kRle}, memory), &basic);
  // JPEG 2000 is the basic reader's (OpenJPEG), on disk too; with a syntax
  // nobody decodes beside it, the first that reads the files reports it.
  EXPECT_EQ(chooseDicomDecoder(ranked, {kJpeg2000}, disk), &basic);
  EXPECT_EQ(chooseDicomDecoder(ranked, {kJpeg2000, kJpegLs}, disk), &dcmtk);
  // The browser's list: only the basic reader.
  EXPECT_EQ(chooseDicomDecoder({&basic}, {kRle}, disk), &basic);
  EXPECT_EQ(chooseDicomDecoder({&dcmtk}, {kRle}, memory), nullptr);
}

TEST(DicomDecoder, ReadsTheTransferSyntaxOfWrittenFiles) {
  test::TempDir dir;
  const Volume v = phantom();
  DicomWriteOptions rle;
  rle.transferSyntax = "rle";
  writeDicomSeries(v, dir / "rle", rle);
  DicomWriteOptions jls;
  jls.transferSyntax = "jpeg-ls-lossless";
  writeDicomSeries(v, dir / "jls", jls);
  const fs::path rleSlice = *fs::directory_iterator(dir / "rle");
  const fs::path jlsSlice = *fs::directory_iterator(dir / "jls");
  EXPECT_EQ(dicomTransferSyntaxOf(FileSource(rleSlice)), kRle);
  EXPECT_EQ(dicomTransferSyntaxOf(FileSource(jlsSlice)), kJpegLs);

  // In memory, RLE goes to the basic reader; JPEG-LS is refused by it,
  // naming the file and the syntax (DCMTK reads files on disk only).
  for (const fs::path& slice : {rleSlice, jlsSlice}) {
    MemoryFiles files;
    const std::string bytes = readBytes(slice);
    files.add(
        slice.filename().string(),
        std::vector<std::byte>(reinterpret_cast<const std::byte*>(bytes.data()),
                               reinterpret_cast<const std::byte*>(bytes.data()) + bytes.size()));
    const auto source = files.open(slice.filename().string());
    if (slice == rleSlice) {
      EXPECT_EQ(readVolume(*source, files).dims(), glm::ivec3(11, 9, 1));
    } else {
      test::expectRejected<InputError>([&] { readVolume(*source, files); },
                                       {slice.filename().string(), "JPEG-LS"});
    }
  }
  // On disk both read, by DCMTK, to the same voxels.
  expectSameVoxels(readVolume((dir / "rle").string()), v, "RLE series");
  expectSameVoxels(readVolume((dir / "jls").string()), v, "JPEG-LS series");
}

}  // namespace
}  // namespace tessera
