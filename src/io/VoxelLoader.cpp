#include "io/VoxelLoader.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <vector>

#include "io/ByteStream.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"

namespace tessera::io_detail {

namespace {

constexpr std::int64_t kMaxDim = 1 << 20;  // the same limit Volume::allocate applies
constexpr std::size_t kDecodeChunk = 1 << 20;

void swapBytesInPlace(std::byte* p, std::size_t count, std::size_t size) {
  switch (size) {
    case 2:
      for (std::size_t i = 0; i < count; ++i) {
        std::uint16_t v;
        std::memcpy(&v, p + 2 * i, 2);
        v = __builtin_bswap16(v);
        std::memcpy(p + 2 * i, &v, 2);
      }
      break;
    case 4:
      for (std::size_t i = 0; i < count; ++i) {
        std::uint32_t v;
        std::memcpy(&v, p + 4 * i, 4);
        v = __builtin_bswap32(v);
        std::memcpy(p + 4 * i, &v, 4);
      }
      break;
    case 8:
      for (std::size_t i = 0; i < count; ++i) {
        std::uint64_t v;
        std::memcpy(&v, p + 8 * i, 8);
        v = __builtin_bswap64(v);
        std::memcpy(p + 8 * i, &v, 8);
      }
      break;
    default:
      break;
  }
}

template <class In, class Out>
void convert(const std::byte* src, std::size_t count, Out* dst, const VoxelFormat& f) {
  for (std::size_t i = 0; i < count; ++i) {
    In v;
    std::memcpy(&v, src + i * sizeof(In), sizeof(In));
    if (f.scaled) {
      dst[i] = static_cast<Out>(static_cast<double>(v) * f.slope + f.intercept);
    } else {
      dst[i] = static_cast<Out>(v);
    }
  }
}

template <class Out>
void convertFrom(DiskType type, const std::byte* src, std::size_t count, Out* dst,
                 const VoxelFormat& f) {
  switch (type) {
    case DiskType::U8:
      convert<std::uint8_t>(src, count, dst, f);
      break;
    case DiskType::I8:
      convert<std::int8_t>(src, count, dst, f);
      break;
    case DiskType::U16:
      convert<std::uint16_t>(src, count, dst, f);
      break;
    case DiskType::I16:
      convert<std::int16_t>(src, count, dst, f);
      break;
    case DiskType::U32:
      convert<std::uint32_t>(src, count, dst, f);
      break;
    case DiskType::I32:
      convert<std::int32_t>(src, count, dst, f);
      break;
    case DiskType::F32:
      convert<float>(src, count, dst, f);
      break;
    case DiskType::F64:
      convert<double>(src, count, dst, f);
      break;
  }
}

bool needsSwap(const VoxelFormat& f) {
  const bool hostBig = std::endian::native == std::endian::big;
  return diskTypeSize(f.type) > 1 && f.bigEndian != hostBig;
}

// Reads every voxel from `src` into `out`; returns the bytes consumed, which
// is less than dims × size only if the source ended early.
std::uint64_t decode(ByteStream& src, const VoxelFormat& f, Volume& out) {
  const std::size_t inSize = diskTypeSize(f.type);
  const std::uint64_t count = out.voxelCount();
  const bool sameLayout = !f.scaled && bytesPerVoxel(out.type()) == inSize &&
                          !isConvertedToF32(f.type) && f.type != DiskType::I8;
  if (sameLayout) {
    // Straight into the volume; swapping, if any, happens in place.
    std::byte* dst = out.bytes().data();
    const std::uint64_t total = count * inSize;
    std::uint64_t done = 0;
    while (done < total) {
      const std::size_t want =
          static_cast<std::size_t>(std::min<std::uint64_t>(total - done, 64u << 20));
      const std::size_t got = src.read(dst + done, want);
      done += got;
      if (got < want) break;
    }
    if (needsSwap(f)) swapBytesInPlace(dst, static_cast<std::size_t>(done / inSize), inSize);
    out.invalidateRange();
    return done;
  }
  std::vector<std::byte> chunk(kDecodeChunk);
  const std::size_t perChunk = kDecodeChunk / inSize;
  std::uint64_t voxel = 0;
  while (voxel < count) {
    const std::size_t n =
        static_cast<std::size_t>(std::min<std::uint64_t>(count - voxel, perChunk));
    const std::size_t got = src.read(chunk.data(), n * inSize);
    const std::size_t whole = got / inSize;
    if (needsSwap(f)) swapBytesInPlace(chunk.data(), whole, inSize);
    switch (out.type()) {
      case ScalarType::U8:
        convertFrom(f.type, chunk.data(), whole, out.dataAs<std::uint8_t>() + voxel, f);
        break;
      case ScalarType::U16:
        convertFrom(f.type, chunk.data(), whole, out.dataAs<std::uint16_t>() + voxel, f);
        break;
      case ScalarType::I16:
        convertFrom(f.type, chunk.data(), whole, out.dataAs<std::int16_t>() + voxel, f);
        break;
      case ScalarType::F32:
        convertFrom(f.type, chunk.data(), whole, out.dataAs<float>() + voxel, f);
        break;
    }
    voxel += whole;
    if (got < n * inSize) {
      out.invalidateRange();
      return voxel * inSize + (got - whole * inSize);
    }
  }
  out.invalidateRange();
  return count * inSize;
}

std::string bytesWithUnit(std::uint64_t bytes) {
  return std::to_string(bytes) + " bytes (" + formatBytes(bytes) + ")";
}

}  // namespace

std::size_t diskTypeSize(DiskType t) {
  switch (t) {
    case DiskType::U8:
    case DiskType::I8:
      return 1;
    case DiskType::U16:
    case DiskType::I16:
      return 2;
    case DiskType::U32:
    case DiskType::I32:
    case DiskType::F32:
      return 4;
    case DiskType::F64:
      return 8;
  }
  return 1;
}

std::string_view diskTypeName(DiskType t) {
  switch (t) {
    case DiskType::U8:
      return "u8";
    case DiskType::I8:
      return "i8";
    case DiskType::U16:
      return "u16";
    case DiskType::I16:
      return "i16";
    case DiskType::U32:
      return "u32";
    case DiskType::I32:
      return "i32";
    case DiskType::F32:
      return "f32";
    case DiskType::F64:
      return "f64";
  }
  return "?";
}

bool isConvertedToF32(DiskType t) {
  return t == DiskType::U32 || t == DiskType::I32 || t == DiskType::F64;
}

ScalarType volumeTypeFor(const VoxelFormat& format) {
  if (format.scaled) return ScalarType::F32;
  switch (format.type) {
    case DiskType::U8:
      return ScalarType::U8;
    case DiskType::I8:
    case DiskType::I16:
      return ScalarType::I16;
    case DiskType::U16:
      return ScalarType::U16;
    case DiskType::U32:
    case DiskType::I32:
    case DiskType::F32:
    case DiskType::F64:
      return ScalarType::F32;
  }
  return ScalarType::F32;
}

std::string dimsString(glm::ivec3 dims) {
  return std::to_string(dims.x) + "x" + std::to_string(dims.y) + "x" + std::to_string(dims.z);
}

Volume loadVoxels(const VoxelSource& source, const VoxelFormat& format, const std::string& what) {
  for (int a = 0; a < 3; ++a) {
    if (format.dims[a] <= 0 || format.dims[a] > kMaxDim) {
      throw InputError(what + ": size along axis " + std::to_string(a) + " is " +
                       std::to_string(format.dims[a]) + ", expected 1.." + std::to_string(kMaxDim));
    }
  }
  // At most 2^60 voxels × 8 bytes: fits in 64 bits, so no overflow below.
  const std::uint64_t voxels = static_cast<std::uint64_t>(format.dims.x) *
                               static_cast<std::uint64_t>(format.dims.y) *
                               static_cast<std::uint64_t>(format.dims.z);
  const std::uint64_t diskBytes = voxels * diskTypeSize(format.type);
  const ScalarType outType = volumeTypeFor(format);
  const std::string declared = what + ": header says " + dimsString(format.dims) + " " +
                               std::string(diskTypeName(format.type)) + " = " +
                               formatBytes(diskBytes) + " of voxel data";
  const ByteSource& file = *source.file;
  const std::string inFile = file.name() == what ? std::string() : " in " + file.name();
  const std::uint64_t fileSize = file.size();

  if (!source.gzip) {
    std::uint64_t offset = source.fileOffset;
    if (source.atEndOfFile) {
      if (fileSize < diskBytes) {
        throw InputError(declared + " at the end of" + (inFile.empty() ? " the file" : inFile) +
                         ", file has " + bytesWithUnit(fileSize));
      }
      offset = fileSize - diskBytes;
    }
    if (offset > fileSize || fileSize - offset < diskBytes) {
      throw InputError(declared + " at offset " + std::to_string(offset) + inFile + ", file has " +
                       formatBytes(fileSize) + " (needs " + std::to_string(offset + diskBytes) +
                       " bytes, has " + std::to_string(fileSize) + ")");
    }
    Volume v = Volume::allocate(format.dims, outType, what);
    SourceStream src(file, offset);
    const std::uint64_t got = decode(src, format, v);
    if (got < diskBytes) {  // the file shrank while we read it
      throw InputError(what + ": file ends after " + std::to_string(got) + " of " +
                       std::to_string(diskBytes) + " bytes of voxel data");
    }
    return v;
  }

  // Gzip: the inflated chunks and the volume coexist for a moment.
  HostBudget::global().check(diskBytes + voxels * bytesPerVoxel(outType),
                             what + " (" + dimsString(format.dims) + " " +
                                 std::string(diskTypeName(format.type)) +
                                 ", inflated data plus volume)");
  if (source.fileOffset > fileSize) {
    throw InputError(what + ": compressed data should start at byte " +
                     std::to_string(source.fileOffset) + inFile + ", file has " +
                     bytesWithUnit(fileSize));
  }
  const std::uint64_t compressed = fileSize - source.fileOffset;
  const std::uint64_t mostInflated = compressed * kMaxDeflateRatio;
  if (source.inflatedSkip + diskBytes > mostInflated) {
    throw InputError(declared + " at inflated offset " + std::to_string(source.inflatedSkip) +
                     ", but " + bytesWithUnit(compressed) + " of gzip data" + inFile +
                     " can inflate to at most " + formatBytes(mostInflated) +
                     " (deflate's limit is 1032:1)");
  }
  if (!startsWithGzipMagic(file, source.fileOffset)) {
    throw InputError(what + ": data is said to be gzip-compressed, but the bytes at offset " +
                     std::to_string(source.fileOffset) + inFile +
                     " do not start with the gzip magic 1f 8b");
  }
  InflateStream gz(file, source.fileOffset);
  const std::uint64_t skipped = gz.skip(source.inflatedSkip);
  if (skipped < source.inflatedSkip) {
    throw InputError(what + ": gzip data ends after " + std::to_string(skipped) +
                     " bytes, before the voxel data at inflated offset " +
                     std::to_string(source.inflatedSkip));
  }
  ChunkedBuffer inflated = ChunkedBuffer::readUpTo(gz, diskBytes);
  if (inflated.size() < diskBytes) {
    throw InputError(what + ": gzip data ends after " + std::to_string(inflated.size()) + " of " +
                     std::to_string(diskBytes) + " bytes of voxel data (" +
                     dimsString(format.dims) + " " + std::string(diskTypeName(format.type)) +
                     " = " + formatBytes(diskBytes) + ")");
  }
  Volume v = Volume::allocate(format.dims, outType, what);
  decode(inflated, format, v);
  return v;
}

Volume decodeVoxels(ByteStream& bytes, const VoxelFormat& format, const std::string& what) {
  for (int a = 0; a < 3; ++a) {
    if (format.dims[a] <= 0 || format.dims[a] > kMaxDim) {
      throw InputError(what + ": size along axis " + std::to_string(a) + " is " +
                       std::to_string(format.dims[a]) + ", expected 1.." + std::to_string(kMaxDim));
    }
  }
  Volume v = Volume::allocate(format.dims, volumeTypeFor(format), what);
  const std::uint64_t want = v.voxelCount() * diskTypeSize(format.type);
  const std::uint64_t got = decode(bytes, format, v);
  if (got < want) {
    throw InputError(what + ": voxel data ends after " + std::to_string(got) + " of " +
                     std::to_string(want) + " bytes (" + dimsString(format.dims) + " " +
                     std::string(diskTypeName(format.type)) + ")");
  }
  return v;
}

}  // namespace tessera::io_detail
