// NIfTI-1 output. nifticlib builds the header (nifti_make_new_nim, then
// nifti_convert_nim2n1hdr); the bytes are written here rather than by
// nifti_image_write, which returns nothing and ignores failed data writes
// (a full disk would leave a truncated file that looks written), into a
// temporary file renamed into place (writeAtomically).
#include "tessera/io/NiftiWriter.h"

#include <nifti2_io.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "io/OutputFile.h"
#include "io/VoxelLoader.h"
#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/io/NiftiGeometry.h"
#include "tessera/io/VolumeWriter.h"

namespace tessera {

namespace {

// NIfTI-1 stores dims as int16 (nifti1.h).
constexpr int kMaxNifti1Dim = 32767;

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

int datatypeOf(ScalarType t) {
  switch (t) {
    case ScalarType::U8:
      return DT_UINT8;
    case ScalarType::U16:
      return DT_UINT16;
    case ScalarType::I16:
      return DT_INT16;
    case ScalarType::F32:
      return DT_FLOAT32;
  }
  return DT_UNKNOWN;
}

struct NiftiImageFree {
  void operator()(nifti_image* nim) const { nifti_image_free(nim); }
};

// The header, padding and voxels into `path`, gzip-compressed when `gzip`.
// Every failure, a full disk included, is an Error: nifti_image_write would
// ignore failed data writes and leave a truncated file that looks written.
class NiftiOutput {
 public:
  NiftiOutput(const std::filesystem::path& path, bool gzip) : path_(path) {
    if (gzip) {
      gz_ = gzopen(path.c_str(), "wb6");
      if (gz_ == nullptr) fail("cannot open for writing");
    } else {
      file_ = std::make_unique<io_detail::OutputFile>(path);
    }
  }
  ~NiftiOutput() {
    if (gz_ != nullptr) gzclose(gz_);
  }
  NiftiOutput(const NiftiOutput&) = delete;
  NiftiOutput& operator=(const NiftiOutput&) = delete;

  void write(const void* data, std::size_t n) {
    if (file_) {
      file_->write(data, n);
      return;
    }
    // gzwrite takes an unsigned count: feed it in pieces.
    const auto* bytes = static_cast<const char*>(data);
    constexpr std::size_t kPiece = 1 << 30;
    for (std::size_t at = 0; at < n; at += kPiece) {
      const auto len = static_cast<unsigned>(std::min(kPiece, n - at));
      if (gzwrite(gz_, bytes + at, len) != static_cast<int>(len)) failGzip("write failed");
    }
  }

  void close() {
    if (file_) {
      file_->close();
      return;
    }
    const int rc = gzclose(gz_);
    gz_ = nullptr;
    if (rc != Z_OK) fail("write failed (gzip)");
  }

 private:
  [[noreturn]] void fail(const char* what) const {
    throw Error(path_.string() + ": " + what + ": " + std::strerror(errno));
  }
  [[noreturn]] void failGzip(const char* what) const {
    int zerr = Z_OK;
    const char* msg = gzerror(gz_, &zerr);
    throw Error(path_.string() + ": " + what + ": " +
                (zerr == Z_ERRNO ? std::strerror(errno) : msg));
  }

  std::filesystem::path path_;
  std::unique_ptr<io_detail::OutputFile> file_;
  gzFile gz_ = nullptr;
};

}  // namespace

void writeNifti(const Volume& volume, const std::filesystem::path& path) {
  const std::string p = path.string();
  const std::string name = path.filename().string();
  const bool gzip = endsWith(name, ".nii.gz");
  if (!gzip && !endsWith(name, ".nii")) {
    throw InputError(p + ": a NIfTI file name must end in .nii or .nii.gz");
  }
  if (!volume.hasData()) throw InputError(p + ": cannot write a volume without voxels");
  const glm::ivec3 d = volume.dims();
  if (d.x > kMaxNifti1Dim || d.y > kMaxNifti1Dim || d.z > kMaxNifti1Dim) {
    throw InputError(p + ": " + io_detail::dimsString(d) + " exceeds NIfTI-1's limit of " +
                     std::to_string(kMaxNifti1Dim) + " voxels per axis");
  }

  nifti_set_debug_level(0);  // errors are ours to report, not nifticlib's to print
  const std::int64_t dims[8] = {3, d.x, d.y, d.z, 1, 1, 1, 1};
  std::unique_ptr<nifti_image, NiftiImageFree> nim(
      nifti_make_new_nim(dims, datatypeOf(volume.type()), 0));
  if (!nim) throw Error(p + ": nifticlib could not create a NIfTI header");
  nim->nifti_type = NIFTI_FTYPE_NIFTI1_1;  // one .nii file, magic "n+1"
  const glm::dvec3 s = volume.spacing();
  nim->dx = nim->pixdim[1] = s.x;
  nim->dy = nim->pixdim[2] = s.y;
  nim->dz = nim->pixdim[3] = s.z;
  nim->xyz_units = NIFTI_UNITS_MM;
  // No scaling: scl_slope 0 means "none" (nifti1.h).
  nim->scl_slope = 0.0;
  nim->scl_inter = 0.0;
  // Both forms, as nibabel writes them: the sform holds the affine exactly
  // (also a sheared one), the qform its nearest rotation (a quaternion,
  // qfac = -1 for a reflection such as LAS) for readers that only know the
  // qform. The code keeps the meaning of a NIfTI source ("MNI_152" stays
  // MNI_152), else 1 (NIFTI_XFORM_SCANNER_ANAT).
  const int code = niftiXformCodeFor(volume.geometrySource());
  const glm::dmat4 affine = volume.indexToWorld();
  nim->sform_code = code;
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) nim->sto_xyz.m[row][col] = affine[col][row];
  }
  const glm::dmat3 rotation = nearestOrthonormal(volume.direction());
  nifti_dmat44 q;
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) {
      q.m[row][col] = col < 3 && row < 3 ? rotation[col][row] * s[col] : affine[col][row];
    }
  }
  // nifticlib's polar decomposition gives b, c, d, qoffset and qfac; the
  // pixdim it derives is ours again (the columns of q have our spacings).
  double qdx = 0.0, qdy = 0.0, qdz = 0.0;
  nim->qform_code = code;
  nifti_dmat44_to_quatern(q, &nim->quatern_b, &nim->quatern_c, &nim->quatern_d, &nim->qoffset_x,
                          &nim->qoffset_y, &nim->qoffset_z, &qdx, &qdy, &qdz, &nim->qfac);
  nim->pixdim[0] = nim->qfac;
  nim->qto_xyz =
      nifti_quatern_to_dmat44(nim->quatern_b, nim->quatern_c, nim->quatern_d, nim->qoffset_x,
                              nim->qoffset_y, nim->qoffset_z, s.x, s.y, s.z, nim->qfac);
  std::snprintf(nim->descrip, sizeof nim->descrip, "written by Tessera");
  nifti_set_iname_offset(nim.get(), 1);

  nifti_1_header header;
  if (nifti_convert_nim2n1hdr(nim.get(), &header) != 0) {
    throw Error(p + ": nifticlib could not build a NIfTI-1 header for " + io_detail::dimsString(d) +
                " " + std::string(scalarTypeName(volume.type())));
  }
  const std::uint64_t voxOffset = static_cast<std::uint64_t>(header.vox_offset);
  if (voxOffset < sizeof header + 4) {
    throw Error(p + ": nifticlib set vox_offset " + std::to_string(voxOffset) +
                ", inside the header");
  }

  writeAtomically(path, [&](const std::filesystem::path& temp) {
    NiftiOutput out(temp, gzip);
    out.write(&header, sizeof header);
    // The 4 bytes after the header say whether extensions follow (none),
    // then padding up to vox_offset (352 with no extensions).
    const std::string gap(static_cast<std::size_t>(voxOffset - sizeof header), '\0');
    out.write(gap.data(), gap.size());
    // Native byte order: sizeof_hdr tells readers which one that is.
    out.write(volume.bytes().data(), volume.bytes().size());
    out.close();
  });
}

}  // namespace tessera
