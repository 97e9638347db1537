#include "tessera/io/NiftiReader.h"

#include <nifti2_io.h>
#include <zlib.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <memory>
#include <sstream>

#include "io/ByteSource.h"
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

// The header fields we check ourselves, in NIfTI-2 widths. We read them from
// the raw header because nifticlib silently repairs some of them (dim[i] <= 0
// becomes 1, pixdim 0 becomes 1) and casts a NIfTI-1 vox_offset float to int
// unchecked; Tessera wants to name such problems instead.
struct RawHeader {
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

std::string numberString(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

// ANALYZE 7.5 headers (no NIfTI magic) are only plausible as the .hdr of a
// .hdr/.img pair; a .nii without magic is a broken file.
bool isAnalyzePairName(const std::filesystem::path& path) {
  const std::string name = path.filename().string();
  auto endsWith = [&](const std::string& suffix) {
    return name.size() >= suffix.size() &&
           name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  return endsWith(".hdr") || endsWith(".hdr.gz") || endsWith(".HDR");
}

// The placement fields of either header version (already in native byte
// order); NiftiGeometry turns them into the affine.
template <class Header>
NiftiGeometryFields geometryFields(const Header& n) {
  NiftiGeometryFields g;
  g.version = sizeof(Header) == sizeof(nifti_2_header) ? 2 : 1;
  for (int a = 0; a < 3; ++a) g.dim[static_cast<std::size_t>(a)] = n.dim[a + 1];
  for (int a = 0; a < 4; ++a) g.pixdim[static_cast<std::size_t>(a)] = n.pixdim[a];
  g.qformCode = n.qform_code;
  g.sformCode = n.sform_code;
  g.quaternB = n.quatern_b;
  g.quaternC = n.quatern_c;
  g.quaternD = n.quatern_d;
  g.qoffset = glm::dvec3(n.qoffset_x, n.qoffset_y, n.qoffset_z);
  for (int c = 0; c < 4; ++c) {
    const auto i = static_cast<std::size_t>(c);
    g.srow[0][i] = n.srow_x[c];
    g.srow[1][i] = n.srow_y[c];
    g.srow[2][i] = n.srow_z[c];
  }
  return g;
}

// ANALYZE 7.5 has no qform/sform (those bytes hold other fields); SPM keeps
// an origin voxel in hist.originator, 3 int16 from byte 253 (dbh.h).
NiftiGeometryFields analyzeGeometryFields(const nifti_1_header& n, const unsigned char* raw,
                                          bool swapped) {
  NiftiGeometryFields g;
  g.version = 0;
  for (int a = 0; a < 3; ++a) g.dim[static_cast<std::size_t>(a)] = n.dim[a + 1];
  for (int a = 0; a < 4; ++a) g.pixdim[static_cast<std::size_t>(a)] = n.pixdim[a];
  for (int a = 0; a < 3; ++a) {
    std::uint16_t u;
    std::memcpy(&u, raw + 253 + 2 * a, 2);
    if (swapped) u = static_cast<std::uint16_t>((u >> 8) | (u << 8));
    g.spmOrigin[static_cast<std::size_t>(a)] = static_cast<std::int16_t>(u);
  }
  return g;
}

// Reads the first 540 bytes (inflating if gzip: zlib's gz* functions pass
// plain files through) and decodes sizeof_hdr, magic and the fields above.
RawHeader readRawHeader(const std::filesystem::path& path) {
  const std::string p = path.string();
  gzFile gz = gzopen(p.c_str(), "rb");
  if (gz == nullptr) throw InputError(p + ": cannot open");
  std::array<unsigned char, kNifti2HeaderSize> buf{};
  const int got = gzread(gz, buf.data(), static_cast<unsigned>(buf.size()));
  int zerr = Z_OK;
  const std::string zmsg = got < 0 ? gzerror(gz, &zerr) : "";
  gzclose(gz);
  if (got < 0) throw InputError(p + ": cannot read the NIfTI header: " + zmsg);
  if (got < 4) {
    throw InputError(p + ": has only " + std::to_string(got) +
                     " bytes, too short for a NIfTI header (348 bytes for NIfTI-1)");
  }

  std::int32_t sizeofHdr;
  std::memcpy(&sizeofHdr, buf.data(), 4);
  const std::int32_t swappedSize =
      static_cast<std::int32_t>(__builtin_bswap32(static_cast<std::uint32_t>(sizeofHdr)));
  RawHeader h;
  if (sizeofHdr == kNifti1HeaderSize || sizeofHdr == kNifti2HeaderSize) {
    h.version = sizeofHdr == kNifti1HeaderSize ? 1 : 2;
  } else if (swappedSize == kNifti1HeaderSize || swappedSize == kNifti2HeaderSize) {
    h.version = swappedSize == kNifti1HeaderSize ? 1 : 2;
    h.swapped = true;
  } else {
    throw InputError(p + ": not a NIfTI file: sizeof_hdr is " + std::to_string(sizeofHdr) +
                     ", expected 348 (NIfTI-1) or 540 (NIfTI-2)");
  }
  const int need = h.version == 1 ? kNifti1HeaderSize : kNifti2HeaderSize;
  if (got < need) {
    throw InputError(p + ": file ends after " + std::to_string(got) + " of the " +
                     std::to_string(need) + " bytes of its NIfTI-" + std::to_string(h.version) +
                     " header");
  }

  if (h.version == 1) {
    nifti_1_header n1;
    std::memcpy(&n1, buf.data(), sizeof n1);
    if (h.swapped) nifti_swap_as_nifti1(&n1);
    if (std::memcmp(n1.magic, "n+1", 4) == 0) {
      h.singleFile = true;
    } else if (std::memcmp(n1.magic, "ni1", 4) != 0) {
      h.version = 0;  // no NIfTI magic: an ANALYZE 7.5 header
    }
    for (int i = 0; i < 8; ++i) {
      h.dim[i] = n1.dim[i];
      h.pixdim[i] = n1.pixdim[i];
    }
    h.datatype = n1.datatype;
    h.voxOffset = n1.vox_offset;
    h.sclSlope = n1.scl_slope;
    h.sclInter = n1.scl_inter;
    h.geometry = geometryFields(n1);
    if (h.version == 0 && !isAnalyzePairName(path)) {
      throw InputError(p + ": NIfTI-1 magic is " + quoteMagic(n1.magic, 4) +
                       ", expected 'n+1' (a .nii file) or 'ni1' (a .hdr/.img pair)");
    }
    if (h.version == 0) h.geometry = analyzeGeometryFields(n1, buf.data(), h.swapped);
  } else {
    nifti_2_header n2;
    std::memcpy(&n2, buf.data(), sizeof n2);
    if (h.swapped) nifti_swap_as_nifti2(&n2);
    if (std::memcmp(n2.magic, "n+2", 4) == 0) {
      h.singleFile = true;
    } else if (std::memcmp(n2.magic, "ni2", 4) != 0) {
      throw InputError(p + ": NIfTI-2 magic is " + quoteMagic(n2.magic, 4) +
                       ", expected 'n+2' or 'ni2'");
    }
    for (int i = 0; i < 8; ++i) {
      h.dim[i] = n2.dim[i];
      h.pixdim[i] = n2.pixdim[i];
    }
    h.datatype = n2.datatype;
    h.voxOffset = static_cast<double>(n2.vox_offset);
    h.sclSlope = n2.scl_slope;
    h.sclInter = n2.scl_inter;
    h.geometry = geometryFields(n2);
  }
  return h;
}

DiskType diskTypeOf(int datatype, const std::string& p) {
  switch (datatype) {
    case DT_UINT8:
      return DiskType::U8;
    case DT_INT8:
      return DiskType::I8;
    case DT_UINT16:
      return DiskType::U16;
    case DT_INT16:
      return DiskType::I16;
    case DT_UINT32:
      return DiskType::U32;
    case DT_INT32:
      return DiskType::I32;
    case DT_FLOAT32:
      return DiskType::F32;
    case DT_FLOAT64:
      return DiskType::F64;
    default:
      break;
  }
  const std::string name = nifti_datatype_string(datatype);
  throw InputError(p + ": NIfTI datatype " + std::to_string(datatype) + " (" +
                   (name.find("ILLEGAL") != std::string::npos ? "not a NIfTI datatype" : name) +
                   ") is not supported; expected uint8, int8, uint16, int16, uint32, int32, "
                   "float32 or float64");
}

// The checks nifticlib would skip or paper over; every message names the
// field and its value.
void validate(const RawHeader& h, const std::string& p) {
  const std::int64_t ndim = h.dim[0];
  if (ndim < 3 || ndim > 7) {
    throw InputError(p + ": dim[0] is " + std::to_string(ndim) +
                     (ndim == 1 || ndim == 2 ? " (a " + std::to_string(ndim) + "-D image)" : "") +
                     "; Tessera reads 3-D volumes (dim[0] = 3, or 4 with a single time point)");
  }
  for (int a = 1; a <= 3; ++a) {
    if (h.dim[a] <= 0 || h.dim[a] > kMaxDim) {
      throw InputError(p + ": dim[" + std::to_string(a) + "] is " + std::to_string(h.dim[a]) +
                       ", expected 1.." + std::to_string(kMaxDim));
    }
  }
  for (int a = 4; a <= ndim; ++a) {
    if (h.dim[a] != 1) {
      throw InputError(p + ": dim[" + std::to_string(a) + "] is " + std::to_string(h.dim[a]) +
                       " (dim[0] = " + std::to_string(ndim) +
                       "); only a single 3-D volume is supported, expected 1");
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

struct NiftiImageFree {
  void operator()(nifti_image* nim) const { nifti_image_free(nim); }
};

}  // namespace

Volume readNifti(const std::filesystem::path& path) {
  const std::string p = path.string();
  const std::uint64_t fileSize = io_detail::regularFileSize(path);
  const RawHeader raw = readRawHeader(path);
  validate(raw, p);

  // Bound vox_offset by what the file can hold before nifticlib reads the
  // extensions that sit between the header and the voxels.
  const bool gzipped = io_detail::startsWithGzipMagic(path);
  if (raw.singleFile) {
    const std::uint64_t limit = gzipped ? fileSize * io_detail::kMaxDeflateRatio : fileSize;
    if (raw.voxOffset > static_cast<double>(limit)) {
      throw InputError(
          p + ": vox_offset " + numberString(raw.voxOffset) + " lies beyond the end of the file (" +
          formatBytes(fileSize) +
          (gzipped ? " of gzip data, at most " + formatBytes(limit) + " inflated)" : ")"));
    }
  }

  nifti_set_debug_level(0);  // we report problems ourselves, nifticlib would print to stderr
  std::unique_ptr<nifti_image, NiftiImageFree> nim(nifti_image_read(p.c_str(), 0));
  if (!nim) throw InputError(p + ": nifticlib could not read the NIfTI header");
  if (nim->iname == nullptr) {
    throw InputError(p + ": cannot find the image file for this header (expected .img or .img.gz)");
  }

  io_detail::VoxelFormat format;
  format.dims = glm::ivec3(static_cast<int>(raw.dim[1]), static_cast<int>(raw.dim[2]),
                           static_cast<int>(raw.dim[3]));
  format.type = diskTypeOf(raw.datatype, p);
  // sizeof_hdr read byte-swapped means the file's byte order is not ours.
  format.bigEndian = raw.swapped != (std::endian::native == std::endian::big);
  // NIfTI-1 §scl_slope: slope 0 means "no scaling"; (1, 0) is the identity.
  // ANALYZE headers have no scaling fields (nifticlib ignores them too).
  const double slope = raw.sclSlope;
  const double inter = raw.sclInter;
  if (raw.version > 0 && std::isfinite(slope) && slope != 0.0 && !(slope == 1.0 && inter == 0.0)) {
    if (!std::isfinite(inter)) {
      throw InputError(p + ": scl_inter is " + numberString(inter) + " with scl_slope " +
                       numberString(slope) + ", expected a finite intercept");
    }
    format.scaled = true;
    format.slope = slope;
    format.intercept = inter;
  }

  io_detail::VoxelSource source;
  source.file = nim->iname;
  // nifticlib names the .img it would read even when it does not exist; say
  // which header wanted it, not only that some .img is missing.
  if (source.file != path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(source.file, ec)) {
      throw InputError(p + ": cannot find the image file for this header (" + source.file.string() +
                       " is missing or not a regular file)");
    }
  }
  source.gzip = io_detail::startsWithGzipMagic(source.file);
  const std::uint64_t offset =
      nim->iname_offset > 0 ? static_cast<std::uint64_t>(nim->iname_offset) : 0;
  if (source.gzip) {
    source.inflatedSkip = offset;
  } else {
    source.fileOffset = offset;
  }
  Volume v = io_detail::loadVoxels(source, format, p);

  // Geometry from the raw header, not nifticlib's nim: the browser's reader
  // decodes the same fields the same way (io/NiftiGeometry).
  const NiftiGeometry geometry = niftiGeometry(raw.geometry);
  v.setIndexToWorld(geometry.indexToWorld);
  v.setGeometrySource(geometry.source);

  std::string description =
      (raw.version == 0 ? "ANALYZE 7.5 " : "NIfTI-" + std::to_string(raw.version) + " ") + p +
      " (" + io_detail::dimsString(format.dims) + " " +
      std::string(io_detail::diskTypeName(format.type));
  if (format.scaled) {
    description += ", scaled by scl_slope " + numberString(slope) + " and scl_inter " +
                   numberString(inter) + " to f32";
  } else if (io_detail::isConvertedToF32(format.type)) {
    description += ", converted to f32";
  } else if (format.type == DiskType::I8) {
    description += ", widened to i16";
  }
  v.setDescription(description + ")");
  return v;
}

}  // namespace tessera
