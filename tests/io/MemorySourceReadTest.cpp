// The readers on memory byte sources (what the browser reads picked or
// dropped files with): the same bytes give the same Volume, affine,
// geometry source and voxels as the same files read from disk, for every
// format but DICOM; companion files are found among those opened together.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include "io/ByteStream.h"
#include "io/GeometryFixtures.h"
#include "io/IoFixtures.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/ByteSource.h"
#include "tessera/io/NiftiWriter.h"
#include "tessera/io/NrrdWriter.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/VolumeWriter.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

std::vector<std::byte> fileBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::vector<char> c((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::byte> b(c.size());
  std::memcpy(b.data(), c.data(), c.size());
  return b;
}

std::vector<std::byte> toBytes(const std::string& s) {
  std::vector<std::byte> b(s.size());
  std::memcpy(b.data(), s.data(), s.size());
  return b;
}

// Every file of `dir` in memory, by file name, as the page holds them.
MemoryFiles filesOf(const fs::path& dir) {
  MemoryFiles files;
  for (const auto& e : fs::directory_iterator(dir)) {
    files.add(e.path().filename().string(), fileBytes(e.path()));
  }
  return files;
}

Volume readFromMemory(const MemoryFiles& files, const std::string& name) {
  return readVolume(*files.open(name), files);
}

Volume readFromMemory(const std::string& name, const std::string& bytes) {
  MemoryFiles files;
  files.add(name, toBytes(bytes));
  return readFromMemory(files, name);
}

// Reads `name` of `dir` from disk and from memory and compares everything
// but the description (which names the file as given).
void expectSameFromMemory(const fs::path& dir, const std::string& name) {
  SCOPED_TRACE(name);
  const Volume disk = readVolume((dir / name).string());
  const Volume memory = readFromMemory(filesOf(dir), name);
  ASSERT_EQ(memory.dims(), disk.dims());
  EXPECT_EQ(memory.type(), disk.type());
  test::expectAffineNear(memory.indexToWorld(), disk.indexToWorld(), 0.0);
  EXPECT_EQ(memory.geometrySource(), disk.geometrySource());
  test::expectSameVoxels(memory, disk);
}

Volume testVolume(ScalarType type) {
  Volume v = test::volumeWithAffine({7, 5, 3}, type, test::obliqueReflectedAffine());
  for (std::size_t i = 0; i < v.voxelCount(); ++i) {
    v.setValueAtIndex(i, type == ScalarType::I16 ? static_cast<double>(i) * 37 - 500
                                                 : static_cast<double>(i * 3 % 251));
  }
  v.invalidateRange();
  return v;
}

TEST(MemorySource, EveryWrittenFormatReadsLikeTheFile) {
  for (ScalarType t : {ScalarType::U8, ScalarType::I16, ScalarType::U16, ScalarType::F32}) {
    SCOPED_TRACE(std::string(scalarTypeName(t)));
    test::TempDir dir;
    const Volume v = testVolume(t);
    // writeVolume compresses NRRD, MetaImage and VTI.
    for (const char* name : {"v.nii", "v.nii.gz", "v.nrrd", "v.mha", "v.vti", "v.raw"}) {
      writeVolume(v, dir / name);
    }
    writeNrrd(v, dir / "plain.nrrd", false);
    if (t == ScalarType::U8 || t == ScalarType::U16) writeVolume(v, dir / "v.pvm");
    for (const auto& e : fs::directory_iterator(dir.path())) {
      const std::string name = e.path().filename().string();
      if (name != "v.raw") expectSameFromMemory(dir.path(), name);
    }
  }
}

TEST(MemorySource, DetachedDataIsFoundAmongTheFilesOpenedTogether) {
  test::TempDir dir;
  const std::string voxels = test::noiseBytes(4 * 3 * 2 * 2);
  test::writeFile(dir / "d.raw", voxels);
  test::writeFile(dir / "d.nhdr",
                  "NRRD0004\ntype: ushort\ndimension: 3\nsizes: 4 3 2\nendian: big\n"
                  "space: LPS\nspace directions: (0,1,0) (2,0,0) (0,0,3)\n"
                  "space origin: (1,2,3)\nencoding: raw\ndata file: d.raw\n");
  test::writeFile(dir / "m.zraw", test::gzipBytes(voxels));
  test::writeFile(dir / "m.mhd",
                  "ObjectType = Image\nNDims = 3\nDimSize = 4 3 2\nElementType = MET_SHORT\n"
                  "TransformMatrix = 0 1 0 -1 0 0 0 0 1\nOffset = 5 6 7\n"
                  "CompressedData = True\nElementDataFile = m.zraw\n");
  test::NiftiFields pair;
  pair.magic = std::string("ni1\0", 4);
  pair.voxOffset = 0;
  pair.datatype = 512;  // uint16
  pair.bitpix = 16;
  pair.qformCode = 1;
  pair.quatern[1] = 0.5;
  test::writeFile(dir / "p.hdr", test::niftiHeader(pair));
  test::writeFile(dir / "p.img", voxels);
  test::writeFile(dir / "s.bin", voxels);
  test::writeFile(dir / "s.json",
                  R"({"dims": [4, 3, 2], "type": "i16", "spacing": [1, 2, 3], "file": "s.bin",)"
                  R"( "direction": [[0, 1, 0], [-1, 0, 0], [0, 0, 1]], "origin": [4, 5, 6]})");
  for (const char* name : {"d.nhdr", "m.mhd", "p.hdr", "s.json"}) {
    expectSameFromMemory(dir.path(), name);
  }
  // The page reads the header of the files picked together.
  EXPECT_EQ(volumeFileAmong({"d.raw", "d.nhdr"}), "d.nhdr");
  EXPECT_EQ(volumeFileAmong({"s.bin", "s.json"}), "s.json");
  EXPECT_EQ(volumeFileAmong({"v.raw", "v.raw.json"}), "v.raw.json");
  EXPECT_EQ(volumeFileAmong({"p.img", "p.hdr"}), "p.hdr");
  EXPECT_EQ(volumeFileAmong({"a.nii.gz", "b.nrrd"}), "a.nii.gz");
}

TEST(MemorySource, AMissingCompanionIsNamedWithTheFilesOpened) {
  const std::string nhdr =
      "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: x.raw\n";
  try {
    readFromMemory("d.nhdr", nhdr);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("d.nhdr: data file: x.raw"), std::string::npos) << m;
    EXPECT_NE(m.find("open it together"), std::string::npos) << m;
  }
  try {
    readFromMemory("v.raw", std::string(8, '\0'));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("v.raw.json"), std::string::npos) << e.what();
  }
}

// DICOM from memory goes to the reader without DCMTK (DicomBasicReaderTest
// reads whole series this way); a Part-10 marker without file meta
// information is refused naming the file.
TEST(MemorySource, DicomWithoutFileMetaIsRefusedWithAReason) {
  std::string part10(200, '\0');
  std::memcpy(part10.data() + 128, "DICM", 4);
  for (const char* name : {"slice.dcm", "IM0001"}) {
    try {
      readFromMemory(name, part10);
      FAIL() << "no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string(name) + ": the file meta information has "
                                                               "no Transfer Syntax UID"),
                std::string::npos)
          << e.what();
    }
  }
}

// ---- geometry: the same header bytes give the native reader's affine ----

void expectSameGeometry(const fs::path& path) {
  expectSameFromMemory(path.parent_path(), path.filename().string());
}

TEST(MemorySource, NiftiHeadersGiveTheFileReadersAffine) {
  test::TempDir dir;
  std::vector<test::NiftiFields> cases(6);
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
  // NIfTI-2, big endian, with a sform.
  cases[5] = cases[3];
  cases[5].version = 2;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    std::string name = "h";  // built piecewise: GCC 12 warns falsely on "h" + string
    name += std::to_string(i);
    name += ".nii";
    std::ofstream(dir / name, std::ios::binary)
        << test::niftiHeader(cases[i]) << std::string(24, '\x09');
    expectSameGeometry(dir / name);
  }
}

TEST(MemorySource, NiftiAndNrrdWrittenWithObliqueAndLasAffinesReadTheSame) {
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

TEST(MemorySource, NrrdSpacesGiveTheFileReadersAffine) {
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

TEST(MemorySource, RefusesWhatTheFileReaderRefusesWithTheSameMessage) {
  const std::string parallel =
      "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nspace: RAS\n"
      "space directions: (1,0,0) (2,0,0) (0,0,1)\nencoding: raw\n\n" +
      std::string(8, '\0');
  test::TempDir dir;
  test::writeFile(dir / "par.nrrd", parallel);
  std::string fromFile;
  try {
    readVolume((dir / "par.nrrd").string());
  } catch (const InputError& e) {
    fromFile = e.what();
  }
  try {
    readFromMemory("par.nrrd", parallel);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("parallel"), std::string::npos) << m;
    // The same words after the file's name.
    EXPECT_EQ(m.substr(m.find(':')), fromFile.substr(fromFile.find(": ")));
  }
}

TEST(MemorySource, TruncatedAndBrokenFilesAreRefusedWithTheSizes) {
  test::TempDir dir;
  writeVolume(testVolume(ScalarType::U16), dir / "t.nii");
  auto bytes = fileBytes(dir / "t.nii");
  bytes.erase(bytes.end() - 10, bytes.end());
  MemoryFiles files;
  files.add("t.nii", bytes);
  try {
    readFromMemory(files, "t.nii");
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("t.nii: header says 7x5x3 u16", 0), 0u) << m;
    EXPECT_NE(m.find("file has"), std::string::npos) << m;
  }
  EXPECT_THROW(readFromMemory("x.nii.gz", std::string("\x1f\x8b\x08", 3)), InputError);
  EXPECT_THROW(readFromMemory("x.nii", "hello"), InputError);
  EXPECT_THROW(readFromMemory("x.txt", "hello"), InputError);
}

// ---- the inflate seam, as every compressed reader uses it ----

std::string inflatedFrom(const std::string& compressed) {
  const MemorySource source("x.gz", toBytes(compressed));
  io_detail::InflateStream in(source, 0);
  std::string out(1 << 16, '\0');
  out.resize(in.read(reinterpret_cast<std::byte*>(out.data()), out.size()));
  return out;
}

TEST(InflateStream, ReadsConcatenatedMembersAndIgnoresWhatFollows) {
  const std::string a = test::noiseBytes(3000, 1) + std::string(5000, 'a');
  const std::string b = std::string(7000, 'b') + test::noiseBytes(100, 2);
  EXPECT_EQ(inflatedFrom(test::gzipBytes(a) + test::gzipBytes(b)), a + b);
  EXPECT_EQ(inflatedFrom(test::gzipBytes(a) + "trailing garbage"), a);
}

TEST(InflateStream, ACutStreamEndsEarlyAndCorruptDataIsNamed) {
  const std::string data = test::noiseBytes(20000, 3);
  const std::string packed = test::gzipBytes(data);
  const std::string cut = inflatedFrom(packed.substr(0, packed.size() / 2));
  EXPECT_LT(cut.size(), data.size());
  EXPECT_EQ(cut, data.substr(0, cut.size()));
  std::string corrupt = packed;
  corrupt[20] = static_cast<char>(corrupt[20] ^ 0x55);
  corrupt[21] = static_cast<char>(corrupt[21] ^ 0x55);
  try {
    inflatedFrom(corrupt);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("x.gz: gzip data is corrupt after"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace tessera
