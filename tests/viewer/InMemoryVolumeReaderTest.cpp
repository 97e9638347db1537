#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include <zlib.h>

#include "support/TestSupport.h"
#include "tessera/core/Error.h"
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
