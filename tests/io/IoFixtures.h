#pragma once
// Fixtures for the io tests, generated on the fly: a temporary directory that
// cleans up after itself, hand-built NIfTI-1/2 headers (byte offsets from
// nifti1.h / nifti2.h), and gzip compression.
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>

#include "support/Deflate.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/Volume.h"
#include "tessera/io/NiftiReader.h"

namespace tessera::test {

inline void writeFile(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write fixture " + path.string());
}

// The whole file.
inline std::string fileBytes(const std::filesystem::path& path) {
  std::string bytes(static_cast<std::size_t>(std::filesystem::file_size(path)), '\0');
  std::ifstream in(path, std::ios::binary);
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return bytes;
}

// What randomVolume() gives its volume besides the voxels.
struct RandomVolumeOptions {
  glm::dvec3 spacing{1.0};
  glm::dvec3 origin{0.0};
  bool withNaN = false;  // f32: about one voxel in 97 is NaN
};

// dims of random voxels over the whole range of `type` (f32: uniform in
// [-1000, 1000)), for the readers' and writers' round trips.
inline Volume randomVolume(glm::ivec3 dims, ScalarType type, unsigned seed,
                           const RandomVolumeOptions& options = {}) {
  Volume v = Volume::allocate(dims, type, "test volume");
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> real(-1000.0f, 1000.0f);
  for (std::uint64_t i = 0; i < v.voxelCount(); ++i) {
    switch (type) {
      case ScalarType::U8:
        v.setValueAtIndex(i, rng() % 256);
        break;
      case ScalarType::U16:
        v.setValueAtIndex(i, rng() % 65536);
        break;
      case ScalarType::I16:
        v.setValueAtIndex(i, static_cast<int>(rng() % 65536) - 32768);
        break;
      case ScalarType::F32:
        v.setValueAtIndex(i, options.withNaN && rng() % 97 == 0 ? std::nan("") : real(rng));
        break;
    }
  }
  v.invalidateRange();
  v.setSpacing(options.spacing);
  v.setOrigin(options.origin);
  return v;
}

// Same shape, type, geometry and voxel bytes.
inline void expectSameVolume(const Volume& a, const Volume& b) {
  EXPECT_EQ(a.dims(), b.dims());
  EXPECT_EQ(a.type(), b.type());
  EXPECT_EQ(a.spacing(), b.spacing());
  EXPECT_EQ(a.origin(), b.origin());
  ASSERT_EQ(a.byteSize(), b.byteSize());
  EXPECT_EQ(std::memcmp(a.bytes().data(), b.bytes().data(), a.byteSize()), 0)
      << "voxel bytes differ";
}

// The MNI ch2 head (mricron-data): real data for the writers' round trips.
inline const std::filesystem::path kCh2 = "/usr/share/mricron/templates/ch2.nii.gz";

// Writes ch2 as each of `names` with write(volume, path) and expects
// read(path) to give it back exactly; skips the test where ch2 is not
// installed.
template <class Write, class Read>
void expectCh2RoundTrips(const std::vector<std::string>& names, Write&& write, Read&& read) {
  if (!std::filesystem::exists(kCh2)) GTEST_SKIP() << kCh2 << " is not installed (mricron-data)";
  TempDir dir;
  const Volume ch2 = readNifti(kCh2);
  for (const auto& name : names) {
    SCOPED_TRACE(name);
    write(ch2, dir / name);
    expectSameVolume(read(dir / name), ch2);
  }
}

inline std::string gzipBytes(std::string_view data) {
  return deflateBytes(data, 15 + 16, Z_BEST_SPEED);
}

// Bytes that deflate cannot shrink much, so truncating their gzip stream
// really cuts voxel data.
inline std::string noiseBytes(std::size_t n, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::string s(n, '\0');
  for (auto& c : s) c = static_cast<char>(rng() & 0xff);
  return s;
}

// Writes values at byte offsets in either byte order.
class ByteImage {
 public:
  ByteImage(std::size_t size, bool bigEndian) : bytes_(size, '\0'), big_(bigEndian) {}

  template <class T>
  void put(std::size_t offset, T value) {
    char b[sizeof(T)];
    std::memcpy(b, &value, sizeof(T));
    if (big_ != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof(T));
    std::memcpy(bytes_.data() + offset, b, sizeof(T));
  }
  void putText(std::size_t offset, std::string_view text) {
    std::memcpy(bytes_.data() + offset, text.data(), text.size());
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
  bool big_;
};

// Voxel values as they appear in a file of the given byte order.
template <class T>
std::string voxelBytes(const std::vector<T>& values, bool bigEndian) {
  ByteImage img(values.size() * sizeof(T), bigEndian);
  for (std::size_t i = 0; i < values.size(); ++i) img.put<T>(i * sizeof(T), values[i]);
  return img.bytes();
}

struct NiftiFields {
  int version = 1;  // 1 or 2
  std::int64_t dim[8] = {3, 4, 3, 2, 1, 1, 1, 1};
  int datatype = 2;  // DT_UINT8
  int bitpix = 8;
  double pixdim[8] = {1, 1, 1, 1, 1, 1, 1, 1};
  double voxOffset = -1;  // -1: right after the header (352 / 544)
  double sclSlope = 0;
  double sclInter = 0;
  int qformCode = 0;
  double quatern[3] = {0, 0, 0};  // quatern_b, c, d: 0 is the identity rotation
  double qoffset[3] = {0, 0, 0};
  int sformCode = 0;
  double srow[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};  // srow_x, srow_y, srow_z
  std::string magic;                                               // empty: "n+1" / "n+2"
  int sizeofHdr = 0;                                               // 0: 348 / 540
  bool bigEndian = false;
};

// Header plus the 4-byte extension flag, i.e. everything before vox_offset.
inline std::string niftiHeader(const NiftiFields& f) {
  if (f.version == 1) {
    ByteImage h(352, f.bigEndian);
    h.put<std::int32_t>(0, f.sizeofHdr != 0 ? f.sizeofHdr : 348);
    for (int i = 0; i < 8; ++i)
      h.put<std::int16_t>(40 + 2 * i, static_cast<std::int16_t>(f.dim[i]));
    h.put<std::int16_t>(70, static_cast<std::int16_t>(f.datatype));
    h.put<std::int16_t>(72, static_cast<std::int16_t>(f.bitpix));
    for (int i = 0; i < 8; ++i) h.put<float>(76 + 4 * i, static_cast<float>(f.pixdim[i]));
    h.put<float>(108, static_cast<float>(f.voxOffset < 0 ? 352.0 : f.voxOffset));
    h.put<float>(112, static_cast<float>(f.sclSlope));
    h.put<float>(116, static_cast<float>(f.sclInter));
    h.put<std::int16_t>(252, static_cast<std::int16_t>(f.qformCode));
    h.put<std::int16_t>(254, static_cast<std::int16_t>(f.sformCode));
    for (int i = 0; i < 3; ++i) h.put<float>(256 + 4 * i, static_cast<float>(f.quatern[i]));
    for (int i = 0; i < 3; ++i) h.put<float>(268 + 4 * i, static_cast<float>(f.qoffset[i]));
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c)
        h.put<float>(280 + 16 * r + 4 * c, static_cast<float>(f.srow[r][c]));
    }
    h.putText(344, f.magic.empty() ? std::string("n+1\0", 4) : f.magic);
    return h.bytes();
  }
  ByteImage h(544, f.bigEndian);
  h.put<std::int32_t>(0, f.sizeofHdr != 0 ? f.sizeofHdr : 540);
  h.putText(4, f.magic.empty() ? std::string("n+2\0\r\n\032\n", 8) : f.magic);
  h.put<std::int16_t>(12, static_cast<std::int16_t>(f.datatype));
  h.put<std::int16_t>(14, static_cast<std::int16_t>(f.bitpix));
  for (int i = 0; i < 8; ++i) h.put<std::int64_t>(16 + 8 * i, f.dim[i]);
  for (int i = 0; i < 8; ++i) h.put<double>(104 + 8 * i, f.pixdim[i]);
  h.put<std::int64_t>(168, static_cast<std::int64_t>(f.voxOffset < 0 ? 544.0 : f.voxOffset));
  h.put<double>(176, f.sclSlope);
  h.put<double>(184, f.sclInter);
  h.put<std::int32_t>(344, f.qformCode);
  h.put<std::int32_t>(348, f.sformCode);
  for (int i = 0; i < 3; ++i) h.put<double>(352 + 8 * i, f.quatern[i]);
  for (int i = 0; i < 3; ++i) h.put<double>(376 + 8 * i, f.qoffset[i]);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) h.put<double>(400 + 32 * r + 8 * c, f.srow[r][c]);
  }
  return h.bytes();
}

// Runs `f` and expects it to throw E (not merely some other error) quickly,
// with every one of `fragments` in the message.
template <class E, class F>
void expectRejected(F&& f, const std::vector<std::string>& fragments) {
  const auto start = std::chrono::steady_clock::now();
  try {
    f();
    ADD_FAILURE() << "expected an exception mentioning '" << fragments.front() << "'";
  } catch (const E& e) {
    const std::string msg = e.what();
    for (const auto& frag : fragments) {
      EXPECT_NE(msg.find(frag), std::string::npos) << "message: " << msg << "\nmissing: " << frag;
    }
  } catch (const std::exception& e) {
    ADD_FAILURE() << "threw the wrong exception type: " << e.what();
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 2.0) << "rejecting bad input took " << seconds << " s";
}

// Expects write(volume, path) into a folder that does not exist to throw an
// Error naming the path, and to leave nothing behind in `dir`.
template <class Write>
void expectWriteIntoMissingFolderFails(const TempDir& dir, const std::filesystem::path& path,
                                       Write&& write) {
  const Volume v = randomVolume({2, 2, 2}, ScalarType::U8, 1);
  expectRejected<Error>([&] { write(v, path); }, {path.string(), "does not exist"});
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

}  // namespace tessera::test
