// MetaImage (ITK's MetaIO) output: a .mha with the voxels after the header,
// or a .mhd header beside a .raw/.zraw data file, in ITK's field order.
#include "tessera/io/MetaImageWriter.h"

#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <string>
#include <vector>

#include "io/MetaIoOrientation.h"
#include "io/OutputFile.h"
#include "io/VoxelLoader.h"
#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"

namespace tessera {

namespace {

using io_detail::exactNumber;
using io_detail::metaOrientation;

// One zlib stream (RFC 1950), as MetaIO's MET_PerformCompression writes;
// held in memory because CompressedDataSize precedes it in the header.
std::vector<unsigned char> zlibCompress(const Volume& v, const std::filesystem::path& path) {
  z_stream zs{};
  if (deflateInit(&zs, Z_DEFAULT_COMPRESSION) != Z_OK) {
    throw Error(path.string() + ": cannot start zlib compression");
  }
  std::vector<unsigned char> out;
  std::vector<unsigned char> buf(256 * 1024);
  auto pump = [&](const std::byte* data, std::size_t n, int flush) {
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(data));
    zs.avail_in = static_cast<uInt>(n);
    int ret;
    do {
      zs.next_out = buf.data();
      zs.avail_out = static_cast<uInt>(buf.size());
      ret = deflate(&zs, flush);
      if (ret == Z_STREAM_ERROR) {
        deflateEnd(&zs);
        throw Error(path.string() + ": zlib compression failed");
      }
      out.insert(out.end(), buf.data(), buf.data() + (buf.size() - zs.avail_out));
    } while (zs.avail_out == 0 || (flush == Z_FINISH && ret != Z_STREAM_END));
  };
  io_detail::forEachLittleEndianChunk(
      v, [&](const std::byte* p, std::size_t n) { pump(p, n, Z_NO_FLUSH); });
  pump(nullptr, 0, Z_FINISH);
  deflateEnd(&zs);
  return out;
}

const char* metTypeName(ScalarType t) {
  switch (t) {
    case ScalarType::U8:
      return "MET_UCHAR";
    case ScalarType::U16:
      return "MET_USHORT";
    case ScalarType::I16:
      return "MET_SHORT";
    case ScalarType::F32:
      return "MET_FLOAT";
  }
  return "MET_UCHAR";
}

}  // namespace

void writeMetaImage(const Volume& volume, const std::filesystem::path& path, bool compressed) {
  const std::string p = path.string();
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != ".mha" && ext != ".mhd") {
    throw InputError(p +
                     ": a MetaImage file name ends in .mha (one file) or .mhd (header + data "
                     "file)");
  }
  const glm::ivec3 d = volume.dims();
  if (d.x <= 0 || d.y <= 0 || d.z <= 0 || !volume.hasData()) {
    throw InputError(p + ": cannot write an empty volume (" + io_detail::dimsString(d) + ")");
  }
  const bool local = ext == ".mha";
  const std::string dataName = path.stem().string() + (compressed ? ".zraw" : ".raw");

  std::vector<unsigned char> packed;
  if (compressed) packed = zlibCompress(volume, path);

  const glm::dvec3 s = volume.spacing();
  // LPS, as ITK writes: one unit direction per index axis (see lpsAffine).
  const glm::dmat3 toLps = lpsToRas();  // its own inverse
  const glm::dvec3 o = toLps * volume.origin();
  std::string matrix;
  for (int a = 0; a < 3; ++a) {
    const glm::dvec3 axis = toLps * volume.direction()[a];
    for (int k = 0; k < 3; ++k) {
      if (!matrix.empty()) matrix += ' ';
      matrix += exactNumber(axis[k]);
    }
  }
  // The field order of ITK's writer; ElementDataFile must come last.
  std::string header = "ObjectType = Image\nNDims = 3\nBinaryData = True\n";
  header += "BinaryDataByteOrderMSB = False\n";
  header += std::string("CompressedData = ") + (compressed ? "True" : "False") + "\n";
  if (compressed) header += "CompressedDataSize = " + std::to_string(packed.size()) + "\n";
  header += "TransformMatrix = " + matrix + "\n";
  header += "Offset = " + exactNumber(o.x) + " " + exactNumber(o.y) + " " + exactNumber(o.z) + "\n";
  header +=
      "CenterOfRotation = 0 0 0\nAnatomicalOrientation = " + metaOrientation(volume.direction()) +
      "\n";
  header += "ElementSpacing = " + exactNumber(s.x) + " " + exactNumber(s.y) + " " +
            exactNumber(s.z) + "\n";
  header += "DimSize = " + std::to_string(d.x) + " " + std::to_string(d.y) + " " +
            std::to_string(d.z) + "\n";
  header += std::string("ElementType = ") + metTypeName(volume.type()) + "\n";
  header += "ElementDataFile = " + (local ? std::string("LOCAL") : dataName) + "\n";

  auto writeData = [&](io_detail::OutputFile& out) {
    if (compressed) {
      out.write(packed.data(), packed.size());
    } else {
      io_detail::forEachLittleEndianChunk(
          volume, [&](const std::byte* b, std::size_t n) { out.write(b, n); });
    }
  };
  if (local) {
    io_detail::OutputFile out(path);
    out.write(header.data(), header.size());
    writeData(out);
    out.close();
    return;
  }
  io_detail::OutputFile data(path.parent_path() / dataName);
  writeData(data);
  data.close();
  io_detail::OutputFile out(path);
  out.write(header.data(), header.size());
  out.close();
}

}  // namespace tessera
