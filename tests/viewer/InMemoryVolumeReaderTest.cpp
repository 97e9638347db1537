#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include <zlib.h>

#include "io/GeometryFixtures.h"
#include "io/IoFixtures.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/NiftiReader.h"
#include "tessera/io/NiftiWriter.h"
#include "tessera/io/NrrdReader.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/VolumeWriter.h"
#include "tessera/viewer/InMemoryVolumeReader.h"

namespace tessera::viewer {
namespace {

std::vector<std::byte> fileBytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::vector<char> c((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::byte> b(c.size());
  std::memcpy(b.data(), c.data(), c.size());
  return b;
}

void expectSameVolume(const Volume& a, const Volume& b) {
  ASSERT_EQ(a.dims(), b.dims());
  EXPECT_EQ(a.type(), b.type());
  EXPECT_NEAR(a.spacing().x, b.spacing().x, 1e-6);
  EXPECT_NEAR(a.spacing().y, b.spacing().y, 1e-6);
  EXPECT_NEAR(a.spacing().z, b.spacing().z, 1e-6);
  ASSERT_EQ(a.byteSize(), b.byteSize());
  EXPECT_EQ(std::memcmp(a.bytes().data(), b.bytes().data(), a.byteSize()), 0);
}

Volume testVolume(ScalarType type) {
  Volume v = Volume::allocate({7, 5, 3}, type);
  v.setSpacing({0.5, 1.25, 2.0});
  for (std::size_t i = 0; i < v.voxelCount(); ++i)
    v.setValueAtIndex(i, type == ScalarType::I16 ? static_cast<double>(i) * 37 - 500
                                                 : static_cast<double>(i * 3 % 251));
  v.invalidateRange();
  return v;
}

TEST(InMemoryVolumeReader, NiftiReadsLikeTheNativeReader) {
  test::TempDir dir;
  for (ScalarType t : {ScalarType::U8, ScalarType::I16, ScalarType::U16, ScalarType::F32}) {
    std::string name = "v";
    name += scalarTypeName(t);
    name += ".nii";
    const auto path = dir / name;
    writeVolume(testVolume(t), path);
    const auto bytes = fileBytes(path);
    expectSameVolume(readVolumeFromMemory(path.filename().string(), bytes),
                     readVolume(path.string()));
  }
}

TEST(InMemoryVolumeReader, NrrdReadsLikeTheNativeReader) {
  test::TempDir dir;
  const Volume shepp = makeSheppLogan({24, 20, 16});
  writeNrrd(shepp, dir / "p.nrrd");
  expectSameVolume(readVolumeFromMemory("p.nrrd", fileBytes(dir / "p.nrrd")),
                   readNrrd(dir / "p.nrrd"));
  writeNrrd(testVolume(ScalarType::I16), dir / "s.nrrd");
  expectSameVolume(readVolumeFromMemory("s.nrrd", fileBytes(dir / "s.nrrd")),
                   readNrrd(dir / "s.nrrd"));
}

TEST(InMemoryVolumeReader, GzipNrrdPayloadIsReadOnceTheCallerInflatedIt) {
  test::TempDir dir;
  const Volume v = testVolume(ScalarType::U16);
  writeNrrd(v, dir / "g.nrrd", /*gzip=*/true);
  std::vector<std::byte> bytes = fileBytes(dir / "g.nrrd");
  const auto offset = gzipPayloadOffset(bytes);
  ASSERT_TRUE(offset.has_value());
  EXPECT_THROW(readVolumeFromMemory("g.nrrd", bytes), InputError);
  // Inflate as the page does (DecompressionStream('gzip')), here with zlib.
  std::vector<unsigned char> out(v.byteSize() + 64);
  z_stream zs{};
  ASSERT_EQ(inflateInit2(&zs, 16 + MAX_WBITS), Z_OK);
  zs.next_in = reinterpret_cast<Bytef*>(bytes.data() + *offset);
  zs.avail_in = static_cast<uInt>(bytes.size() - *offset);
  zs.next_out = out.data();
  zs.avail_out = static_cast<uInt>(out.size());
  ASSERT_EQ(inflate(&zs, Z_FINISH), Z_STREAM_END);
  out.resize(zs.total_out);
  inflateEnd(&zs);
  bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(*offset), bytes.end());
  for (unsigned char c : out) bytes.push_back(static_cast<std::byte>(c));
  expectSameVolume(readVolumeFromMemory("g.nrrd", bytes, true), readNrrd(dir / "g.nrrd"));
}

// ---- geometry: the same bytes give the native reader's affine ----

std::vector<std::byte> toBytes(const std::string& s) {
  std::vector<std::byte> b(s.size());
  std::memcpy(b.data(), s.data(), s.size());
  return b;
}

// Reads `path` both ways and compares the placement.
void expectSameGeometry(const std::filesystem::path& path) {
  SCOPED_TRACE(path.filename().string());
  const Volume native = readVolume(path.string());
  const Volume memory = readVolumeFromMemory(path.filename().string(), fileBytes(path));
  test::expectAffineNear(memory.indexToWorld(), native.indexToWorld(), 1e-12);
  EXPECT_EQ(memory.geometrySource(), native.geometrySource());
  test::expectSameVoxels(memory, native);
}

TEST(InMemoryVolumeReader, NiftiHeadersGiveTheNativeReadersAffine) {
  test::TempDir dir;
  std::vector<test::NiftiFields> cases(5);
  // sform != qform: the sform.
  cases[0].sformCode = 4;
  cases[0].srow[0][0] = -2;
  cases[0].srow[0][3] = 90.5;
  cases[0].srow[2][3] = -72;
  cases[0].qformCode = 1;
  cases[0].quatern[2] = 0.3;
  // sform_code 0: the qform, left-handed (qfac -1), rotated.
  cases[1].qformCode = 2;
  cases[1].pixdim[0] = -1;
  cases[1].pixdim[1] = 0.75;
  cases[1].quatern[0] = 0.1;
  cases[1].quatern[1] = -0.2;
  cases[1].quatern[2] = 0.4;
  cases[1].qoffset[0] = -40.5;
  // Both codes 0: the centred, x-flipped pixdim affine.
  cases[2].pixdim[1] = 2;
  cases[2].pixdim[3] = 3;
  // Big-endian header with a sform.
  cases[3] = cases[0];
  cases[3].bigEndian = true;
  // A singular sform falls back to the qform.
  cases[4] = cases[1];
  cases[4].sformCode = 2;
  for (auto& row : cases[4].srow) {
    for (double& x : row) x = 0.0;
  }
  for (std::size_t i = 0; i < cases.size(); ++i) {
    std::string name = "h";  // built piecewise: GCC 12 warns falsely on "h" + string
    name += std::to_string(i);
    name += ".nii";
    const auto path = dir / name;
    std::ofstream(path, std::ios::binary) << test::niftiHeader(cases[i]) << std::string(24, '\x09');
    expectSameGeometry(path);
  }
}

TEST(InMemoryVolumeReader, NiftiAndNrrdWrittenWithObliqueAndLasAffinesReadTheSame) {
  test::TempDir dir;
  for (const glm::dmat4& affine :
       {test::lasAffine(), test::obliqueAffine(), test::obliqueReflectedAffine()}) {
    const Volume v = test::volumeWithAffine({5, 4, 3}, ScalarType::I16, affine);
    writeNifti(v, dir / "w.nii");
    expectSameGeometry(dir / "w.nii");
    writeNrrd(v, dir / "w.nrrd");
    expectSameGeometry(dir / "w.nrrd");
  }
}

TEST(InMemoryVolumeReader, NrrdSpacesGiveTheNativeReadersAffine) {
  test::TempDir dir;
  const char* spaceLines[] = {"space: right-anterior-superior\n", "space: LPS\n",
                              "space: left-anterior-superior\n", "space: scanner-xyz\n",
                              "space dimension: 3\n"};
  for (const char* line : spaceLines) {
    // A 4-D file whose size-1 first axis has no direction, spaces inside vectors.
    std::ofstream(dir / "s.nrrd", std::ios::binary)
        << "NRRD0005\ntype: uchar\ndimension: 4\nsizes: 1 2 2 2\n"
        << line
        << "space directions: none (1.2,1.6,0) (0, 0, 3) (0.4,-0.3,0)\n"
           "space origin: (10, -20, 30)\nencoding: raw\n\n"
        << std::string(8, '\x04');
    expectSameGeometry(dir / "s.nrrd");
  }
  std::ofstream(dir / "p.nrrd", std::ios::binary)
      << "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nspacings: 0.5 2 3\n"
         "encoding: raw\n\n"
      << std::string(8, '\x04');
  expectSameGeometry(dir / "p.nrrd");
}

TEST(InMemoryVolumeReader, RefusesNrrdGeometryTheNativeReaderRefuses) {
  const std::string header =
      "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nspace: RAS\n"
      "space directions: (1,0,0) (2,0,0) (0,0,1)\nencoding: raw\n\n" +
      std::string(8, '\0');
  try {
    readVolumeFromMemory("par.nrrd", toBytes(header));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("parallel"), std::string::npos) << e.what();
  }
}

TEST(InMemoryVolumeReader, TruncatedFileIsRefusedWithTheSizes) {
  test::TempDir dir;
  writeVolume(testVolume(ScalarType::U16), dir / "t.nii");
  auto bytes = fileBytes(dir / "t.nii");
  ASSERT_GT(bytes.size(), 10u);
  bytes.erase(bytes.end() - 10, bytes.end());
  try {
    readVolumeFromMemory("t.nii", bytes);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("t.nii"), std::string::npos) << m;
    EXPECT_NE(m.find("7x5x3 uint16"), std::string::npos) << m;
  }
}

TEST(InMemoryVolumeReader, RefusesWhatItCannotRead) {
  const std::vector<std::byte> gz{std::byte{0x1f}, std::byte{0x8b}, std::byte{8}};
  EXPECT_THROW(readVolumeFromMemory("x.nii.gz", gz), InputError);
  EXPECT_TRUE(isGzip(gz));
  const std::string text = "hello";
  const std::vector<std::byte> junk(reinterpret_cast<const std::byte*>(text.data()),
                                    reinterpret_cast<const std::byte*>(text.data()) + text.size());
  EXPECT_THROW(readVolumeFromMemory("x.nii", junk), InputError);
  EXPECT_THROW(readVolumeFromMemory("x.txt", junk), InputError);
  const std::string detached = "NRRD0004\ntype: uchar\nsizes: 2 2 2\ndata file: x.raw\n\n";
  EXPECT_THROW(
      readVolumeFromMemory(
          "d.nrrd", std::vector<std::byte>(
                        reinterpret_cast<const std::byte*>(detached.data()),
                        reinterpret_cast<const std::byte*>(detached.data()) + detached.size())),
      InputError);
}

}  // namespace
}  // namespace tessera::viewer
