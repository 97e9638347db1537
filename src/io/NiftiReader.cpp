// NIfTI-1 and NIfTI-2 (and ANALYZE 7.5 .hdr/.img pairs), read from the
// header bytes themselves: both headers are fixed structs (nifti1.h,
// nifti2.h; the field offsets are below), in the byte order that sizeof_hdr
// reveals. nifticlib is not used to read: it takes only paths, and it
// silently repairs headers (dim[i] <= 0 becomes 1, pixdim 0 becomes 1, a
// NIfTI-1 vox_offset float is cast to int unchecked) where Tessera names the
// problem. It remains the NIfTI writer and the test oracle for the affines.
#include "tessera/io/NiftiReader.h"
#include "io/HeaderText.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <sstream>

#include "io/ByteStream.h"
#include "io/VoxelLoader.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/NiftiGeometry.h"

namespace tessera {

namespace {

using io_detail::DiskType;

constexpr std::int64_t kMaxDim = 1 << 20;
constexpr int kNifti1HeaderSize = 348;
constexpr int kNifti2HeaderSize = 540;

// The header fields Tessera uses, in NIfTI-2 widths.
struct Header {
  int version = 0;  // 0 = ANALYZE 7.5, 1 = NIfTI-1, 2 = NIfTI-2
  bool swapped = false;
  bool singleFile = false;  // magic "n+1"/"n+2": header and voxels in one file
  std::array<std::int64_t, 8> dim{};
  int datatype = 0;
  std::array<double, 8> pixdim{};
  double voxOffset = 0.0;
  double sclSlope = 0.0;
  double sclInter = 0.0;
  NiftiGeometryFields geometry;
};

// Reads fixed-width fields of the header bytes in the file's byte order.
class Fields {
 public:
  Fields(const std::byte* bytes, bool swapped) : bytes_(bytes), swapped_(swapped) {}

  template <class T>
  T at(std::size_t offset) const {
    std::array<std::byte, sizeof(T)> b;
    std::memcpy(b.data(), bytes_ + offset, sizeof(T));
    if (swapped_) std::reverse(b.begin(), b.end());
    T v;
    std::memcpy(&v, b.data(), sizeof(T));
    return v;
  }
  const char* text(std::size_t offset) const {
    return reinterpret_cast<const char*>(bytes_ + offset);
  }

 private:
  const std::byte* bytes_;
  bool swapped_;
};

std::string quoteMagic(const char* m, std::size_t n) {
  std::string s;
  for (std::size_t i = 0; i < n && m[i] != '\0'; ++i) {
    const unsigned char c = static_cast<unsigned char>(m[i]);
    if (c >= 32 && c < 127) {
      s += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      s += buf;
    }
  }
  return "'" + s + "'";
}

using io_detail::numberString;

bool endsWith(const std::string& name, const std::string& suffix) {
  return name.size() >= suffix.size() &&
         name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// ANALYZE 7.5 headers (no NIfTI magic) are only plausible as the .hdr of a
// .hdr/.img pair; a .nii without magic is a broken file.
bool isAnalyzePairName(const std::string& name) {
  return endsWith(name, ".hdr") || endsWith(name, ".hdr.gz") || endsWith(name, ".HDR");
}

// Where a header version keeps the fields read here. The fields that follow
// one another (scl_slope/scl_inter, qform_code/sform_code, quatern_b/c/d
// then qoffset_x/y/z, the srow_* rows) are adjacent in both versions.
struct FieldOffsets {
  std::size_t dim, pixdim, datatype, voxOffset, sclSlope, qformCode, quatern, srow;
};
constexpr FieldOffsets kNifti1Offsets{40, 76, 70, 108, 112, 252, 256, 280};   // nifti_1_header
constexpr FieldOffsets kNifti2Offsets{16, 104, 12, 168, 176, 344, 352, 400};  // nifti_2_header

// Decodes the fields at `o` in the widths of a header version: Int for dim,
// Real for pixdim, the scaling and the geometry, Code for qform_code and
// sform_code, VoxOffset for vox_offset (a float in NIfTI-1).
template <class Int, class Real, class Code, class VoxOffset>
Header decodeFields(const Fields& f, const FieldOffsets& o) {
  Header h;
  for (std::size_t i = 0; i < 8; ++i) {
    h.dim[i] = f.at<Int>(o.dim + sizeof(Int) * i);
    h.pixdim[i] = f.at<Real>(o.pixdim + sizeof(Real) * i);
  }
  h.datatype = f.at<std::int16_t>(o.datatype);
  h.voxOffset = static_cast<double>(f.at<VoxOffset>(o.voxOffset));
  h.sclSlope = f.at<Real>(o.sclSlope);
  h.sclInter = f.at<Real>(o.sclSlope + sizeof(Real));
  NiftiGeometryFields& g = h.geometry;
  g.qformCode = f.at<Code>(o.qformCode);
  g.sformCode = f.at<Code>(o.qformCode + sizeof(Code));
  const auto real = [&](std::size_t base, std::size_t k) {
    return f.at<Real>(base + sizeof(Real) * k);
  };
  g.quaternB = real(o.quatern, 0);
  g.quaternC = real(o.quatern, 1);
  g.quaternD = real(o.quatern, 2);
  g.qoffset = glm::dvec3(real(o.quatern, 3), real(o.quatern, 4), real(o.quatern, 5));
  for (std::size_t row = 0; row < 3; ++row) {
    for (std::size_t col = 0; col < 4; ++col) g.srow[row][col] = real(o.srow, 4 * row + col);
  }
  return h;
}

// Reads the first 540 bytes (inflated if gzip) and decodes sizeof_hdr,
// magic and the fields above.
Header readHeader(const ByteSource& file) {
  const std::string& p = file.name();
  std::array<std::byte, kNifti2HeaderSize> buf{};
  std::size_t got = 0;
  if (io_detail::startsWithGzipMagic(file)) {
    io_detail::InflateStream gz(file, 0);
    got = gz.read(buf.data(), buf.size());
  } else {
    got = file.read(0, buf.data(), buf.size());
  }
  if (got < 4) {
    throw InputError(p + ": has only " + std::to_string(got) +
                     " bytes, too short for a NIfTI header (348 bytes for NIfTI-1)");
  }
  std::int32_t sizeofHdr;
  std::memcpy(&sizeofHdr, buf.data(), 4);
  const std::int32_t swappedSize =
      static_cast<std::int32_t>(__builtin_bswap32(static_cast<std::uint32_t>(sizeofHdr)));
  int version = 0;
  bool swapped = false;
  if (sizeofHdr == kNifti1HeaderSize || sizeofHdr == kNifti2HeaderSize) {
    version = sizeofHdr == kNifti1HeaderSize ? 1 : 2;
  } else if (swappedSize == kNifti1HeaderSize || swappedSize == kNifti2HeaderSize) {
    version = swappedSize == kNifti1HeaderSize ? 1 : 2;
    swapped = true;
  } else {
    throw InputError(p + ": not a NIfTI file: sizeof_hdr is " + std::to_string(sizeofHdr) +
                     ", expected 348 (NIfTI-1) or 540 (NIfTI-2)");
  }
  const std::size_t need = version == 1 ? kNifti1HeaderSize : kNifti2HeaderSize;
  if (got < need) {
    throw InputError(p + ": file ends after " + std::to_string(got) + " of the " +
                     std::to_string(need) + " bytes of its NIfTI-" + std::to_string(version) +
                     " header");
  }
  const Fields f(buf.data(), swapped);
  Header h =
      version == 1
          ? decodeFields<std::int16_t, float, std::int16_t, float>(f, kNifti1Offsets)
          : decodeFields<std::int64_t, double, std::int32_t, std::int64_t>(f, kNifti2Offsets);
  h.version = version;
  h.swapped = swapped;
  if (version == 1) {
    const char* magic = f.text(344);
    if (std::memcmp(magic, "n+1", 4) == 0) {
      h.singleFile = true;
    } else if (std::memcmp(magic, "ni1", 4) != 0) {
      if (!isAnalyzePairName(p)) {
        throw InputError(p + ": NIfTI-1 magic is " + quoteMagic(magic, 4) +
                         ", expected 'n+1' (a .nii file) or 'ni1' (a .hdr/.img pair)");
      }
      // ANALYZE 7.5: no qform/sform (those bytes hold other fields); SPM
      // keeps an origin voxel in hist.originator, 3 int16 from byte 253.
      h.version = 0;
      h.geometry = NiftiGeometryFields{};
      for (std::size_t a = 0; a < 3; ++a) h.geometry.spmOrigin[a] = f.at<std::int16_t>(253 + 2 * a);
    }
  } else {
    const char* magic = f.text(4);
    if (std::memcmp(magic, "n+2", 4) == 0) {
      h.singleFile = true;
    } else if (std::memcmp(magic, "ni2", 4) != 0) {
      throw InputError(p + ": NIfTI-2 magic is " + quoteMagic(magic, 4) +
                       ", expected 'n+2' or 'ni2'");
    }
  }
  NiftiGeometryFields& g = h.geometry;
  g.version = h.version;
  for (std::size_t a = 0; a < 3; ++a) g.dim[a] = h.dim[a + 1];
  for (std::size_t a = 0; a < 4; ++a) g.pixdim[a] = h.pixdim[a];
  return h;
}

// nifti1.h's names of the datatype codes.
std::string datatypeName(int datatype) {
  static const std::pair<int, const char*> kNames[] = {
      {1, "BINARY"},    {2, "UINT8"},       {4, "INT16"},         {8, "INT32"},
      {16, "FLOAT32"},  {32, "COMPLEX64"},  {64, "FLOAT64"},      {128, "RGB24"},
      {256, "INT8"},    {512, "UINT16"},    {768, "UINT32"},      {1024, "INT64"},
      {1280, "UINT64"}, {1536, "FLOAT128"}, {1792, "COMPLEX128"}, {2048, "COMPLEX256"},
      {2304, "RGBA32"},
  };
  for (const auto& [code, name] : kNames) {
    if (code == datatype) return name;
  }
  return "not a NIfTI datatype";
}

DiskType diskTypeOf(int datatype, const std::string& p) {
  switch (datatype) {
    case 2:
      return DiskType::U8;
    case 256:
      return DiskType::I8;
    case 512:
      return DiskType::U16;
    case 4:
      return DiskType::I16;
    case 768:
      return DiskType::U32;
    case 8:
      return DiskType::I32;
    case 16:
      return DiskType::F32;
    case 64:
      return DiskType::F64;
    default:
      break;
  }
  throw InputError(p + ": NIfTI datatype " + std::to_string(datatype) + " (" +
                   datatypeName(datatype) +
                   ") is not supported; expected uint8, int8, uint16, int16, uint32, int32, "
                   "float32 or float64");
}

// Every message names the field and its value.
void validate(const Header& h, const std::string& p) {
  const std::int64_t ndim = h.dim[0];
  if (ndim < 3 || ndim > 7) {
    throw InputError(p + ": dim[0] is " + std::to_string(ndim) +
                     (ndim == 1 || ndim == 2 ? " (a " + std::to_string(ndim) + "-D image)" : "") +
                     "; Tessera reads 3-D volumes and 4-D time series (dim[0] = 3 or 4)");
  }
  for (int a = 1; a <= 3; ++a) {
    if (h.dim[a] <= 0 || h.dim[a] > kMaxDim) {
      throw InputError(p + ": dim[" + std::to_string(a) + "] is " + std::to_string(h.dim[a]) +
                       ", expected 1.." + std::to_string(kMaxDim));
    }
  }
  // dim[4] is time (NIfTI-1 §dim): any number of time points, one read at
  // a time. dim[5..7] (vector components, further axes) must be 1.
  if (ndim >= 4 && (h.dim[4] <= 0 || h.dim[4] > kMaxDim)) {
    throw InputError(p + ": dim[4] (time points) is " + std::to_string(h.dim[4]) +
                     ", expected 1.." + std::to_string(kMaxDim));
  }
  for (int a = 5; a <= ndim; ++a) {
    if (h.dim[a] != 1) {
      throw InputError(p + ": dim[" + std::to_string(a) + "] is " + std::to_string(h.dim[a]) +
                       " (dim[0] = " + std::to_string(ndim) +
                       "); vector or 5-D images are not supported, expected 1");
    }
  }
  for (int a = 1; a <= 3; ++a) {
    // The sign of pixdim carries no meaning for spacing (qfac lives in
    // pixdim[0]; some writers negate pixdim[1..3] as well), so only |pixdim|
    // is checked and used.
    if (!std::isfinite(h.pixdim[a]) || h.pixdim[a] == 0.0) {
      throw InputError(p + ": voxel size pixdim[" + std::to_string(a) + "] is " +
                       numberString(h.pixdim[a]) + ", expected a finite non-zero value");
    }
  }
  if (!std::isfinite(h.voxOffset) || h.voxOffset < 0.0) {
    throw InputError(p + ": vox_offset is " + numberString(h.voxOffset) +
                     ", expected a finite value >= 0");
  }
  diskTypeOf(h.datatype, p);
}

int timePointsOf(const Header& h) {
  return h.dim[0] >= 4 ? static_cast<int>(h.dim[4]) : 1;
}

// The .img of a .hdr (or of a .nii with magic "ni1"/"ni2"), as nifticlib's
// nifti_findimgname looks for it: the name without .gz and its extension,
// plus .img, then .img.gz (upper case for an upper-case header name).
std::unique_ptr<ByteSource> openImageFile(const ByteSource& header, const FileSet& files) {
  const std::string& p = header.name();
  std::string base = std::filesystem::path(p).filename().string();
  if (endsWith(base, ".gz")) base.resize(base.size() - 3);
  const bool upper = endsWith(base, ".HDR") || endsWith(base, ".NII");
  base = std::filesystem::path(base).replace_extension().string();
  const std::string img = upper ? ".IMG" : ".img";
  for (const std::string& candidate : {base + img, base + img + ".gz"}) {
    const std::string resolved = files.resolve(header, candidate);
    if (files.contains(resolved)) return files.open(resolved);
  }
  throw InputError(p + ": cannot find the image file for this header (expected " + base + img +
                   " or " + base + img + ".gz beside it)");
}

}  // namespace

Volume readNifti(const std::filesystem::path& path, int time) {
  return readNifti(FileSource(path), FolderFiles(), time);
}

int niftiTimePoints(const ByteSource& file) {
  const Header h = readHeader(file);
  validate(h, file.name());
  return timePointsOf(h);
}

Volume readNifti(const ByteSource& file, const FileSet& files, int time) {
  const std::string& p = file.name();
  const Header h = readHeader(file);
  validate(h, p);
  const int timePoints = timePointsOf(h);
  if (time < 0 || time >= timePoints) {
    throw InputError(p + ": time point " + std::to_string(time) +
                     " asked for, but the file holds " +
                     (timePoints == 1 ? std::string("one volume (time point 0)")
                                      : std::to_string(timePoints) + " (time points 0.." +
                                            std::to_string(timePoints - 1) + ")"));
  }

  io_detail::VoxelFormat format;
  format.dims = glm::ivec3(static_cast<int>(h.dim[1]), static_cast<int>(h.dim[2]),
                           static_cast<int>(h.dim[3]));
  format.type = diskTypeOf(h.datatype, p);
  // sizeof_hdr read byte-swapped means the file's byte order is not ours.
  format.bigEndian = h.swapped != (std::endian::native == std::endian::big);
  // NIfTI-1 §scl_slope: slope 0 means "no scaling"; (1, 0) is the identity.
  // ANALYZE headers have no scaling fields (nifticlib ignores them too).
  const double slope = h.sclSlope;
  const double inter = h.sclInter;
  if (h.version > 0 && std::isfinite(slope) && slope != 0.0 && !(slope == 1.0 && inter == 0.0)) {
    if (!std::isfinite(inter)) {
      throw InputError(p + ": scl_inter is " + numberString(inter) + " with scl_slope " +
                       numberString(slope) + ", expected a finite intercept");
    }
    format.scaled = true;
    format.slope = slope;
    format.intercept = inter;
  }

  // Where the voxels are: after the header in this file, from vox_offset
  // but never inside the header (as nifticlib reads them); or in the .img
  // of a pair, from vox_offset.
  std::unique_ptr<ByteSource> image;
  if (!h.singleFile) image = openImageFile(file, files);
  const ByteSource& data = image ? *image : file;
  const bool gzipped = io_detail::startsWithGzipMagic(data);
  const std::uint64_t limit = gzipped ? data.size() * io_detail::kMaxDeflateRatio : data.size();
  if (h.voxOffset > static_cast<double>(limit)) {
    throw InputError(
        p + ": vox_offset " + numberString(h.voxOffset) + " lies beyond the end of " +
        (image ? data.name() : std::string("the file")) + " (" + formatBytes(data.size()) +
        (gzipped ? " of gzip data, at most " + formatBytes(limit) + " inflated)" : ")"));
  }
  std::uint64_t offset = static_cast<std::uint64_t>(h.voxOffset);
  if (h.singleFile) {
    offset = std::max<std::uint64_t>(
        offset, static_cast<std::uint64_t>(h.version == 2 ? kNifti2HeaderSize : kNifti1HeaderSize));
  }
  // Time point t follows t whole volumes (NIfTI stores i fastest, then j,
  // k, t). Each factor is at most kMaxDim, so the products fit 64 bits; the
  // loader checks the end against what the file holds. A series shorter
  // than its header is refused whichever time point is asked for (as
  // nibabel does), where the file size tells without inflating it.
  const std::uint64_t volumeBytes =
      static_cast<std::uint64_t>(format.dims.x) * static_cast<std::uint64_t>(format.dims.y) *
      static_cast<std::uint64_t>(format.dims.z) * io_detail::diskTypeSize(format.type);
  if (timePoints > 1 && !gzipped &&
      offset + static_cast<std::uint64_t>(timePoints) * volumeBytes > data.size()) {
    const std::uint64_t whole = data.size() > offset ? (data.size() - offset) / volumeBytes : 0;
    throw InputError(p + ": header says " + std::to_string(timePoints) + " time points of " +
                     formatBytes(volumeBytes) + " from offset " + std::to_string(offset) +
                     ", but " + (image ? data.name() : std::string("the file")) + " (" +
                     formatBytes(data.size()) + ") holds " + std::to_string(whole) +
                     " complete ones: truncated");
  }
  offset += static_cast<std::uint64_t>(time) * volumeBytes;

  io_detail::VoxelSource source;
  source.file = &data;
  source.gzip = gzipped;
  if (source.gzip) {
    source.inflatedSkip = offset;
  } else {
    source.fileOffset = offset;
  }
  Volume v = io_detail::loadVoxels(source, format, p);

  const NiftiGeometry geometry = niftiGeometry(h.geometry);
  v.setIndexToWorld(geometry.indexToWorld);
  v.setGeometrySource(geometry.source);

  std::string description =
      (h.version == 0 ? "ANALYZE 7.5 " : "NIfTI-" + std::to_string(h.version) + " ") + p + " (" +
      io_detail::dimsString(format.dims) + " " + std::string(io_detail::diskTypeName(format.type));
  if (format.scaled) {
    description += ", scaled by scl_slope " + numberString(slope) + " and scl_inter " +
                   numberString(inter) + " to f32";
  } else if (io_detail::isConvertedToF32(format.type)) {
    description += ", converted to f32";
  } else if (format.type == DiskType::I8) {
    description += ", widened to i16";
  }
  if (timePoints > 1) {
    description += ", time point " + std::to_string(time) + " of " + std::to_string(timePoints);
  }
  v.setDescription(description + ")");
  return v;
}

}  // namespace tessera
