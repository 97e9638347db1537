// NRRD writing after the format definition of Teem 1.9+
// (teem.sourceforge.net/nrrd/format.html); section numbers refer to it.
#include "tessera/io/NrrdWriter.h"

#include <zlib.h>

#include <cstdio>
#include <optional>
#include <vector>

#include "io/OutputFile.h"
#include "io/VoxelLoader.h"
#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"

namespace tessera {

namespace {

using io_detail::exactNumber;

class GzipWriter {
 public:
  explicit GzipWriter(io_detail::OutputFile& out) : out_(out), buf_(256 * 1024) {
    // 15 + 16: gzip wrapper, which is what "encoding: gzip" means (§5).
    if (deflateInit2(&zs_, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) !=
        Z_OK) {
      throw Error(out_.path().string() + ": cannot start zlib compression");
    }
  }
  ~GzipWriter() { deflateEnd(&zs_); }
  GzipWriter(const GzipWriter&) = delete;
  GzipWriter& operator=(const GzipWriter&) = delete;

  void write(const std::byte* data, std::size_t n) { pump(data, n, Z_NO_FLUSH); }
  void finish() { pump(nullptr, 0, Z_FINISH); }

 private:
  void pump(const std::byte* data, std::size_t n, int flush) {
    zs_.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(data));
    zs_.avail_in = static_cast<uInt>(n);
    int ret;
    do {
      zs_.next_out = buf_.data();
      zs_.avail_out = static_cast<uInt>(buf_.size());
      ret = deflate(&zs_, flush);
      if (ret == Z_STREAM_ERROR) throw Error(out_.path().string() + ": zlib compression failed");
      out_.write(buf_.data(), buf_.size() - zs_.avail_out);
    } while (zs_.avail_out == 0 || (flush == Z_FINISH && ret != Z_STREAM_END));
  }

  io_detail::OutputFile& out_;
  z_stream zs_{};
  std::vector<unsigned char> buf_;
};

}  // namespace

void writeNrrd(const Volume& volume, const std::filesystem::path& path, bool gzip) {
  const glm::ivec3 d = volume.dims();
  if (d.x <= 0 || d.y <= 0 || d.z <= 0) {
    throw InputError(path.string() + ": cannot write an empty volume (" + io_detail::dimsString(d) +
                     ")");
  }
  const char* type = "uchar";
  switch (volume.type()) {
    case ScalarType::U8:
      type = "uchar";
      break;
    case ScalarType::U16:
      type = "ushort";
      break;
    case ScalarType::I16:
      type = "short";
      break;
    case ScalarType::F32:
      type = "float";
      break;
  }
  // Written in LPS, the space ITK and Slicer write (§4 "space"): each
  // axis' space direction is its unit direction times its spacing (§5).
  const glm::dmat3 toLps = lpsToRas();  // its own inverse
  const glm::dmat4 affine = volume.indexToWorld();
  auto vec = [](const glm::dvec3& v) {
    // Built piecewise: GCC 12 warns falsely (-Wrestrict) on "(" + string.
    std::string s(1, '(');
    s += exactNumber(v.x);
    s += ',';
    s += exactNumber(v.y);
    s += ',';
    s += exactNumber(v.z);
    s += ')';
    return s;
  };
  std::string header = "NRRD0004\n# written by Tessera\n";
  header += std::string("type: ") + type + "\n";
  header += "dimension: 3\n";
  header += "space: left-posterior-superior\n";
  header += "sizes: " + std::to_string(d.x) + " " + std::to_string(d.y) + " " +
            std::to_string(d.z) + "\n";
  header += "space directions: " + vec(toLps * glm::dvec3(affine[0])) + " " +
            vec(toLps * glm::dvec3(affine[1])) + " " + vec(toLps * glm::dvec3(affine[2])) + "\n";
  header += "kinds: domain domain domain\n";
  header += "endian: little\n";
  header += std::string("encoding: ") + (gzip ? "gzip" : "raw") + "\n";
  header += "space origin: " + vec(toLps * glm::dvec3(affine[3])) + "\n\n";

  io_detail::OutputFile out(path);
  out.write(header.data(), header.size());

  std::optional<GzipWriter> gz;
  if (gzip) gz.emplace(out);
  io_detail::forEachLittleEndianChunk(volume, [&](const std::byte* chunk, std::size_t n) {
    if (gz) {
      gz->write(chunk, n);
    } else {
      out.write(chunk, n);
    }
  });
  if (gz) gz->finish();
  out.close();
}

}  // namespace tessera
