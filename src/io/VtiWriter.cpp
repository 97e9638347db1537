// VTK XML ImageData (.vti) output: appended raw data with UInt64 headers,
// optionally in vtkZLibDataCompressor's blocks, as ParaView writes.
#include "tessera/io/VtiWriter.h"

#include <zlib.h>

#include <algorithm>
#include <string>
#include <vector>

#include "io/OutputFile.h"
#include "io/VoxelLoader.h"
#include "tessera/core/Error.h"

namespace tessera {

namespace {

using io_detail::exactNumber;

// vtkXMLWriter's default BlockSize: what VTK and ParaView expect.
constexpr std::size_t kWriteBlockBytes = 32768;

void writeWord(io_detail::OutputFile& out, std::uint64_t v) {  // UInt64, little endian
  unsigned char b[8];
  for (int i = 0; i < 8; ++i) b[i] = static_cast<unsigned char>(v >> (8 * i));
  out.write(b, 8);
}

const char* vtkTypeName(ScalarType t) {
  switch (t) {
    case ScalarType::U8:
      return "UInt8";
    case ScalarType::U16:
      return "UInt16";
    case ScalarType::I16:
      return "Int16";
    case ScalarType::F32:
      return "Float32";
  }
  return "UInt8";
}

}  // namespace

void writeVti(const Volume& volume, const std::filesystem::path& path, bool compressed) {
  const glm::ivec3 d = volume.dims();
  if (d.x <= 0 || d.y <= 0 || d.z <= 0 || !volume.hasData()) {
    throw InputError(path.string() + ": cannot write an empty volume (" + io_detail::dimsString(d) +
                     ")");
  }
  const glm::dvec3 s = volume.spacing();
  const glm::dvec3 o = volume.origin();
  const glm::dmat3& dir = volume.direction();
  std::string direction;  // row by row, as vtkXMLImageDataWriter writes it
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) {
      if (!direction.empty()) direction += ' ';
      direction += exactNumber(dir[col][row]);
    }
  }
  const ValueRange range = volume.valueRange();
  const std::string extent = "0 " + std::to_string(d.x - 1) + " 0 " + std::to_string(d.y - 1) +
                             " 0 " + std::to_string(d.z - 1);
  // Appended raw data with UInt64 headers, as ParaView writes by default.
  std::string xml = "<?xml version=\"1.0\"?>\n";
  xml +=
      "<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\"";
  if (compressed) xml += " compressor=\"vtkZLibDataCompressor\"";
  xml += ">\n";
  xml += "  <ImageData WholeExtent=\"" + extent + "\" Origin=\"" + exactNumber(o.x) + " " +
         exactNumber(o.y) + " " + exactNumber(o.z) + "\" Spacing=\"" + exactNumber(s.x) + " " +
         exactNumber(s.y) + " " + exactNumber(s.z) + "\" Direction=\"" + direction + "\">\n";
  xml += "    <Piece Extent=\"" + extent + "\">\n";
  xml += "      <PointData Scalars=\"scalars\">\n";
  xml += std::string("        <DataArray type=\"") + vtkTypeName(volume.type()) +
         "\" Name=\"scalars\" format=\"appended\" RangeMin=\"" + exactNumber(range.min) +
         "\" RangeMax=\"" + exactNumber(range.max) + "\" offset=\"0\"/>\n";
  xml += "      </PointData>\n      <CellData>\n      </CellData>\n    </Piece>\n";
  xml += "  </ImageData>\n  <AppendedData encoding=\"raw\">\n   _";

  io_detail::OutputFile out(path);
  out.write(xml);
  const std::size_t total = volume.bytes().size();
  if (!compressed) {
    writeWord(out, total);
    io_detail::forEachLittleEndianChunk(
        volume, [&](const std::byte* chunk, std::size_t n) { out.write(chunk, n); });
  } else {
    const std::size_t blocks = (total + kWriteBlockBytes - 1) / kWriteBlockBytes;
    // The header holds the compressed sizes: reserve it, write the blocks,
    // then come back and fill it in.
    const std::streampos header = out.position();
    for (std::size_t i = 0; i < 3 + blocks; ++i) writeWord(out, 0);
    std::vector<std::uint64_t> sizes;
    sizes.reserve(blocks);
    std::vector<unsigned char> packed(compressBound(kWriteBlockBytes));
    // Chunks are whole multiples of the block size, but the last.
    io_detail::forEachLittleEndianChunk(volume, [&](const std::byte* chunk, std::size_t n) {
      for (std::size_t at = 0; at < n; at += kWriteBlockBytes) {
        const std::size_t len = std::min(kWriteBlockBytes, n - at);
        uLongf packedLen = static_cast<uLongf>(packed.size());
        if (compress2(packed.data(), &packedLen, reinterpret_cast<const Bytef*>(chunk + at),
                      static_cast<uLong>(len), Z_DEFAULT_COMPRESSION) != Z_OK) {
          throw Error(path.string() + ": zlib compression failed");
        }
        out.write(packed.data(), packedLen);
        sizes.push_back(packedLen);
      }
    });
    const std::streampos end = out.position();
    out.seek(header);
    writeWord(out, blocks);
    writeWord(out, kWriteBlockBytes);
    writeWord(out, total % kWriteBlockBytes);
    for (std::uint64_t sz : sizes) writeWord(out, sz);
    out.seek(end);
  }
  out.write(std::string("\n  </AppendedData>\n</VTKFile>\n"));
  out.close();
}

}  // namespace tessera
