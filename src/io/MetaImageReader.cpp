// MetaImage (ITK's MetaIO): a text header of "Key = Value" lines that ends
// with ElementDataFile, then the voxels in the same file (LOCAL, .mha) or in
// a data file beside the header (.mhd). Field names and their meaning follow
// MetaIO's metaImage.cxx / metaObject.cxx; keys are case-sensitive there and
// here, and keys we do not know are ignored, as MetaIO does.
#include "tessera/io/MetaImageReader.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

#include <glm/geometric.hpp>

#include "io/ByteStream.h"
#include "io/HeaderText.h"
#include "io/MetaIoOrientation.h"
#include "io/VoxelLoader.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/PatientFrame.h"

namespace tessera {

namespace {

using io_detail::DiskType;
using io_detail::metaOrientation;
using io_detail::printable;
using io_detail::trim;
using io_detail::words;

// A header is a few hundred bytes; these limits stop us from "parsing" a
// large binary file as text.
constexpr std::size_t kMaxHeaderBytes = 1 << 20;
constexpr std::size_t kMaxLineBytes = 64 * 1024;
constexpr std::int64_t kMaxDim = 1 << 20;

struct MetaHeader {
  std::optional<std::string> objectType;
  std::optional<std::int64_t> nDims;
  std::vector<std::int64_t> dimSize;
  std::vector<double> elementSpacing;
  std::vector<double> elementSize;
  std::vector<double> offset;
  std::string offsetKey = "Offset";
  std::vector<double> transform;  // TransformMatrix, row i = index axis i (LPS)
  std::string transformKey = "TransformMatrix";
  std::string anatomicalOrientation;
  std::optional<std::string> elementType;
  std::int64_t channels = 1;
  bool binaryData = true;
  bool msb = false;
  bool compressed = false;
  std::optional<std::uint64_t> compressedDataSize;
  std::int64_t headerSize = 0;
  std::optional<std::string> dataFile;
  std::uint64_t headerEnd = 0;  // offset of the first byte after the header
};

using io_detail::numberString;

class LineParser {
 public:
  LineParser(const std::string& path, int line) : path_(path), line_(line) {}

  [[noreturn]] void fail(const std::string& msg) const {
    throw InputError(path_ + ": line " + std::to_string(line_) + ": " + msg);
  }

  std::int64_t integer(const std::string& s, const std::string& key) const {
    std::int64_t v = 0;
    const char* b = s.data();
    const char* e = s.data() + s.size();
    if (b != e && *b == '+') ++b;
    const auto [ptr, ec] = std::from_chars(b, e, v);
    if (ec != std::errc() || ptr != e) fail(key + ": '" + s + "' is not an integer");
    return v;
  }

  std::vector<std::int64_t> integers(const std::string& value, const std::string& key) const {
    std::vector<std::int64_t> out;
    for (const auto& w : words(value)) out.push_back(integer(w, key));
    if (out.empty()) fail(key + " has no values");
    return out;
  }

  std::vector<double> reals(const std::string& value, const std::string& key) const {
    std::vector<double> out;
    for (const auto& w : words(value)) {
      double v = 0.0;
      const char* b = w.data();
      const char* e = w.data() + w.size();
      if (b != e && *b == '+') ++b;
      const auto [ptr, ec] = std::from_chars(b, e, v);
      if (ec != std::errc() || ptr != e) fail(key + ": '" + w + "' is not a number");
      out.push_back(v);
    }
    if (out.empty()) fail(key + " has no values");
    return out;
  }

  // MetaIO reads True/False (any case) and 1/0.
  bool boolean(const std::string& value, const std::string& key) const {
    std::string v = value;
    std::transform(v.begin(), v.end(), v.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (v == "true" || v == "1") return true;
    if (v == "false" || v == "0") return false;
    fail(key + " is '" + value + "', expected True or False");
  }

 private:
  const std::string& path_;
  int line_;
};

// Reads "Key = Value" lines up to and including ElementDataFile, which
// MetaIO requires to be the last field of the header.
MetaHeader parseHeader(const ByteSource& file) {
  const std::string& p = file.name();
  io_detail::LineReader lines(file, kMaxLineBytes,
                              "; is this a MetaImage file, and does its header end with "
                              "ElementDataFile?");
  auto nextLine = [&](std::string& line) { return lines.next(line); };

  MetaHeader h;
  std::string line;
  int lineNo = 0;
  bool sawField = false;
  while (nextLine(line)) {
    ++lineNo;
    const LineParser parse(p, lineNo);
    if (lines.consumed() > kMaxHeaderBytes) {
      parse.fail("MetaImage header longer than " + std::to_string(kMaxHeaderBytes) +
                 " bytes; does it end with ElementDataFile?");
    }
    for (char c : line) {
      if (static_cast<unsigned char>(c) < 0x20 && c != '\t') {
        if (!sawField) {
          throw InputError(p + ": not a MetaImage file: starts with '" + printable(line, 16) +
                           "', expected 'Key = Value' lines such as 'ObjectType = Image'");
        }
        parse.fail("binary data inside the header; the header must end with ElementDataFile");
      }
    }
    if (trim(line).empty()) continue;
    const std::size_t eq = line.find('=');
    if (eq == std::string::npos) {
      if (!sawField) {
        throw InputError(p + ": not a MetaImage file: starts with '" + printable(line, 16) +
                         "', expected 'Key = Value' lines such as 'ObjectType = Image'");
      }
      parse.fail("'" + printable(line, 60) + "' is not a 'Key = Value' line");
    }
    sawField = true;
    const std::string key = trim(line.substr(0, eq));
    const std::string value = trim(line.substr(eq + 1));

    if (key == "ObjectType") {
      h.objectType = value;
    } else if (key == "NDims") {
      h.nDims = parse.integer(value, key);
    } else if (key == "DimSize") {
      h.dimSize = parse.integers(value, key);
    } else if (key == "ElementSpacing") {
      h.elementSpacing = parse.reals(value, key);
    } else if (key == "ElementSize") {
      h.elementSize = parse.reals(value, key);
    } else if (key == "Offset" || key == "Origin" || key == "Position") {
      h.offset = parse.reals(value, key);
      h.offsetKey = key;
    } else if (key == "TransformMatrix" || key == "Rotation" || key == "Orientation") {
      // MetaIO's metaObject.cxx reads all three names into one matrix.
      h.transform = parse.reals(value, key);
      h.transformKey = key;
    } else if (key == "AnatomicalOrientation") {
      h.anatomicalOrientation = value;
    } else if (key == "ElementType") {
      h.elementType = value;
    } else if (key == "ElementNumberOfChannels") {
      h.channels = parse.integer(value, key);
    } else if (key == "BinaryData") {
      h.binaryData = parse.boolean(value, key);
    } else if (key == "BinaryDataByteOrderMSB" || key == "ElementByteOrderMSB") {
      h.msb = parse.boolean(value, key);
    } else if (key == "CompressedData") {
      h.compressed = parse.boolean(value, key);
    } else if (key == "CompressedDataSize") {
      const std::int64_t n = parse.integer(value, key);
      if (n < 0) parse.fail("CompressedDataSize is " + value + ", expected >= 0");
      // MetaIO writes 0 for "unknown": the data then runs to the end of the file.
      if (n > 0) h.compressedDataSize = static_cast<std::uint64_t>(n);
    } else if (key == "HeaderSize") {
      h.headerSize = parse.integer(value, key);
      if (h.headerSize < -1) parse.fail("HeaderSize is " + value + ", expected -1 or >= 0");
    } else if (key == "ElementDataFile") {
      if (value.empty()) parse.fail("ElementDataFile is empty");
      h.dataFile = value;
      break;
    }
    // CenterOfRotation (ITK ignores it for images), Comment, Modality,
    // ElementMin/Max and others change neither the voxels nor their place.
  }
  if (!sawField) throw InputError(p + ": not a MetaImage file: it has no 'Key = Value' lines");
  h.headerEnd = lines.consumed();
  return h;
}

std::optional<DiskType> diskTypeFor(const std::string& name) {
  // MET_LONG/MET_ULONG are 4 bytes in MetaIO (MET_ValueTypeSize); ITK writes
  // 64-bit longs as MET_LONG_LONG.
  static const std::pair<const char*, DiskType> kTypes[] = {
      {"MET_UCHAR", DiskType::U8},   {"MET_CHAR", DiskType::I8},  {"MET_USHORT", DiskType::U16},
      {"MET_SHORT", DiskType::I16},  {"MET_UINT", DiskType::U32}, {"MET_INT", DiskType::I32},
      {"MET_ULONG", DiskType::U32},  {"MET_LONG", DiskType::I32}, {"MET_FLOAT", DiskType::F32},
      {"MET_DOUBLE", DiskType::F64},
  };
  for (const auto& [metName, type] : kTypes) {
    if (name == metName) return type;
  }
  return std::nullopt;
}

bool startsZlibOrGzip(const ByteSource& file, std::uint64_t offset) {
  unsigned char b[2] = {0, 0};
  if (file.read(offset, reinterpret_cast<std::byte*>(b), 2) < 2) return false;
  if (b[0] == 0x1f && b[1] == 0x8b) return true;
  // RFC 1950 §2.2: CM = 8 (deflate) and CMF*256 + FLG a multiple of 31.
  return (b[0] & 0x0f) == 8 && (b[0] * 256 + b[1]) % 31 == 0;
}

// ITK's compressed MetaImage data is one zlib stream. The checks come first,
// none of them allocating: host budget, the size the header gives against the
// file, deflate's ratio bound; then the stream is inflated into chunks as
// bytes arrive, and only a complete stream gets a Volume.
Volume loadCompressed(const MetaHeader& h, const ByteSource& file,
                      const io_detail::VoxelFormat& format, const std::string& p,
                      std::uint64_t start) {
  const std::uint64_t voxels = static_cast<std::uint64_t>(format.dims.x) *
                               static_cast<std::uint64_t>(format.dims.y) *
                               static_cast<std::uint64_t>(format.dims.z);
  const std::uint64_t diskBytes = voxels * io_detail::diskTypeSize(format.type);
  const std::string inFile = file.name() == p ? std::string() : " in " + file.name();
  const std::uint64_t fileSize = file.size();
  if (h.headerSize == -1) {
    if (!h.compressedDataSize) {
      throw InputError(p +
                       ": HeaderSize = -1 (data at the end of the file) with compressed data "
                       "needs CompressedDataSize");
    }
    if (*h.compressedDataSize > fileSize) {
      throw InputError(p + ": CompressedDataSize = " + std::to_string(*h.compressedDataSize) +
                       ", but" + (inFile.empty() ? " the file" : inFile) + " has only " +
                       std::to_string(fileSize) + " bytes");
    }
    start = fileSize - *h.compressedDataSize;
  }
  if (start >= fileSize) {
    throw InputError(p + ": compressed data should start at byte " + std::to_string(start) +
                     inFile + ", but the file has " + std::to_string(fileSize) + " bytes");
  }
  const std::uint64_t available = fileSize - start;
  std::uint64_t compressed = available;
  if (h.compressedDataSize) {
    if (*h.compressedDataSize > available) {
      throw InputError(p + ": CompressedDataSize = " + std::to_string(*h.compressedDataSize) +
                       ", but" + (inFile.empty() ? " the file" : inFile) + " has only " +
                       std::to_string(available) + " bytes of data after byte " +
                       std::to_string(start) + " (truncated?)");
    }
    compressed = *h.compressedDataSize;
  }
  HostBudget::global().check(diskBytes + voxels * bytesPerVoxel(io_detail::volumeTypeFor(format)),
                             p + " (" + io_detail::dimsString(format.dims) + " " +
                                 std::string(io_detail::diskTypeName(format.type)) +
                                 ", inflated data plus volume)");
  const std::uint64_t mostInflated = compressed * io_detail::kMaxDeflateRatio;
  if (diskBytes > mostInflated) {
    throw InputError(p + ": header says " + io_detail::dimsString(format.dims) + " " +
                     std::string(io_detail::diskTypeName(format.type)) + " = " +
                     formatBytes(diskBytes) + " of voxel data, but " + std::to_string(compressed) +
                     " bytes of zlib data" + inFile + " can inflate to at most " +
                     formatBytes(mostInflated) + " (deflate's limit is 1032:1)");
  }
  if (!startsZlibOrGzip(file, start)) {
    throw InputError(p + ": CompressedData = True, but the bytes at offset " +
                     std::to_string(start) + inFile + " do not start a zlib stream");
  }
  io_detail::InflateStream zlib(file, start);
  io_detail::ChunkedBuffer inflated = io_detail::ChunkedBuffer::readUpTo(zlib, diskBytes);
  if (inflated.size() < diskBytes) {
    throw InputError(p + ": zlib data ends after " + std::to_string(inflated.size()) + " of " +
                     std::to_string(diskBytes) + " bytes of voxel data (" +
                     io_detail::dimsString(format.dims) + " " +
                     std::string(io_detail::diskTypeName(format.type)) + " = " +
                     formatBytes(diskBytes) + ")");
  }
  return io_detail::decodeVoxels(inflated, format, p);
}

// MetaImage coordinates are ITK's LPS+. ITK's MetaImageIO reads
// TransformMatrix value ii * NDims + jj as component jj of the direction of
// index axis ii (MetaImageIO::ReadImageInformation, "Read direction cosines":
// directionAxis[jj] = transformMatrix[ii * N + jj]; SetDirection(ii, ...);
// InsightSoftwareConsortium/ITK Modules/IO/Meta/src/itkMetaImageIO.cxx, and
// Write() fills it the same way from GetDirection(ii)). So the values list
// the axes' directions one after another: "1 0 0 0 1 0 0 0 1" is identity,
// "-1 0 0 0 1 0 0 0 1" has index x growing towards patient right. Physical
// point = Offset + TransformMatrix-as-columns * diag(ElementSpacing) * index.
glm::dmat4 lpsAffine(const MetaHeader& h, std::int64_t n, glm::dvec3 spacing, glm::dvec3 origin,
                     const std::string& p) {
  glm::dmat4 a(1.0);
  for (int c = 0; c < 3; ++c) a[c][c] = spacing[c];
  a[3] = glm::dvec4(origin, 1.0);
  if (h.transform.empty()) return a;
  // NDims x NDims values; for NDims 4 (a size-1 4th axis) the spatial 3 x 3
  // alone is accepted too.
  const auto nn = static_cast<std::size_t>(n);
  const std::size_t un = h.transform.size() == 9 ? 3 : nn;
  if (h.transform.size() != un * un) {
    throw InputError(p + ": " + h.transformKey + " has " + std::to_string(h.transform.size()) +
                     " values, but NDims " + std::to_string(n) + " needs " +
                     std::to_string(nn * nn));
  }
  for (std::size_t axis = 0; axis < 3; ++axis) {
    glm::dvec3 d;
    for (std::size_t k = 0; k < 3; ++k) {
      const double v = h.transform[axis * un + k];
      if (!std::isfinite(v)) {
        throw InputError(p + ": " + h.transformKey + " value " + std::to_string(axis * un + k + 1) +
                         " is " + numberString(v) + ", expected a finite number");
      }
      d[static_cast<int>(k)] = v;
    }
    if (glm::length(d) == 0.0) {
      throw InputError(p + ": " + h.transformKey + " gives index axis " + std::to_string(axis) +
                       " the direction (0 0 0); expected a unit vector");
    }
    a[static_cast<int>(axis)] = glm::dvec4(d * spacing[static_cast<int>(axis)], 0.0);
  }
  return a;
}

}  // namespace

Volume readMetaImage(const std::filesystem::path& path) {
  return readMetaImage(FileSource(path), FolderFiles());
}

Volume readMetaImage(const ByteSource& header, const FileSet& files) {
  const std::string& p = header.name();
  const MetaHeader h = parseHeader(header);

  io_detail::requireField(h.nDims.has_value(), p, "MetaImage", "NDims");
  io_detail::requireField(!h.dimSize.empty(), p, "MetaImage", "DimSize");
  io_detail::requireField(h.elementType.has_value(), p, "MetaImage", "ElementType");
  io_detail::requireField(h.dataFile.has_value(), p, "MetaImage", "ElementDataFile");
  if (h.objectType && *h.objectType != "Image") {
    throw InputError(p + ": ObjectType is '" + *h.objectType + "'; Tessera reads Image objects");
  }
  const std::int64_t n = *h.nDims;
  if (h.dimSize.size() != static_cast<std::size_t>(std::max<std::int64_t>(n, 0))) {
    throw InputError(p + ": DimSize has " + std::to_string(h.dimSize.size()) +
                     " values, but NDims is " + std::to_string(n));
  }
  if (!(n == 3 || (n == 4 && h.dimSize[3] == 1))) {
    throw InputError(p + ": NDims is " + std::to_string(n) +
                     "; Tessera reads 3-D images (or 4-D with DimSize 1 along the last axis)");
  }
  io_detail::VoxelFormat format;
  for (std::size_t a = 0; a < 3; ++a) {
    const std::int64_t s = h.dimSize[a];
    if (s < 1 || s > kMaxDim) {
      throw InputError(p + ": DimSize along axis " + std::to_string(a) + " is " +
                       std::to_string(s) + ", expected 1.." + std::to_string(kMaxDim));
    }
    format.dims[static_cast<int>(a)] = static_cast<int>(s);
  }
  if (h.channels != 1) {
    throw InputError(p + ": ElementNumberOfChannels is " + std::to_string(h.channels) +
                     "; Tessera reads scalar (1-channel) images");
  }
  if (!h.binaryData) {
    throw InputError(p + ": BinaryData = False (voxels as text) is not supported");
  }
  const auto type = diskTypeFor(*h.elementType);
  if (!type) {
    throw InputError(p + ": ElementType '" + *h.elementType +
                     "' is not supported; expected MET_UCHAR, MET_CHAR, MET_USHORT, MET_SHORT, "
                     "MET_UINT, MET_INT, MET_FLOAT or MET_DOUBLE");
  }
  format.type = *type;
  format.bigEndian = h.msb;

  // MetaIO: ElementSpacing, or ElementSize when only that is given.
  const bool fromSize = h.elementSpacing.empty() && !h.elementSize.empty();
  const std::vector<double>& sp = fromSize ? h.elementSize : h.elementSpacing;
  const char* spacingKey = fromSize ? "ElementSize" : "ElementSpacing";
  glm::dvec3 spacing(1.0);
  if (!sp.empty()) {
    if (sp.size() != static_cast<std::size_t>(n)) {
      throw InputError(p + ": " + spacingKey + " has " + std::to_string(sp.size()) +
                       " values, but NDims is " + std::to_string(n));
    }
    for (std::size_t a = 0; a < 3; ++a) {
      if (!std::isfinite(sp[a]) || sp[a] <= 0.0) {
        throw InputError(p + ": " + spacingKey + " along axis " + std::to_string(a) + " is " +
                         numberString(sp[a]) + ", expected a finite value > 0");
      }
      spacing[static_cast<int>(a)] = sp[a];
    }
  }
  glm::dvec3 origin(0.0);
  if (!h.offset.empty()) {
    if (h.offset.size() != static_cast<std::size_t>(n)) {
      throw InputError(p + ": " + h.offsetKey + " has " + std::to_string(h.offset.size()) +
                       " values, but NDims is " + std::to_string(n));
    }
    for (std::size_t a = 0; a < 3; ++a) {
      if (!std::isfinite(h.offset[a])) {
        throw InputError(p + ": " + h.offsetKey + " along axis " + std::to_string(a) + " is " +
                         numberString(h.offset[a]) + ", expected a finite value");
      }
      origin[static_cast<int>(a)] = h.offset[a];
    }
  }

  // Where the voxels are. MetaIO spreads them over several files for
  // "LIST" and for a printf pattern ("slice%03d.raw 1 40 1").
  const std::string& name = *h.dataFile;
  std::unique_ptr<ByteSource> dataFile;
  std::uint64_t start = h.headerEnd;
  if (name == "LOCAL" || name == "Local" || name == "local") {
    // data follows the header in this file
  } else if (name.rfind("LIST", 0) == 0 || name.find('%') != std::string::npos) {
    throw InputError(p + ": ElementDataFile = " + name +
                     " spreads the data over several files; not supported (use one data file)");
  } else {
    // Relative to the header's folder.
    try {
      dataFile = files.open(files.resolve(header, name));
    } catch (const InputError& e) {
      throw InputError(p + ": ElementDataFile " + name + ": " + e.what());
    }
    start = 0;
  }
  const ByteSource& file = dataFile ? *dataFile : header;
  // MetaIO seeks to HeaderSize from the start of the data file (for LOCAL
  // data, of this file); -1 means the voxels are the file's last bytes.
  if (h.headerSize > 0) start = static_cast<std::uint64_t>(h.headerSize);

  Volume v;
  if (h.compressed) {
    v = loadCompressed(h, file, format, p, start);
  } else {
    io_detail::VoxelSource source;
    source.file = &file;
    source.fileOffset = start;
    source.atEndOfFile = h.headerSize == -1;
    v = io_detail::loadVoxels(source, format, p);
  }
  // ITK's reader ignores AnatomicalOrientation, and so do we; only a
  // disagreement with TransformMatrix is worth saying.
  const glm::dmat4 ras = glm::dmat4(lpsToRas()) * lpsAffine(h, n, spacing, origin, p);
  try {
    v.setIndexToWorld(ras);
  } catch (const InputError& e) {
    throw InputError(p + ": " + h.transformKey + ": " + e.what());
  }
  std::string source = h.transform.empty()
                           ? "MetaImage without TransformMatrix (identity in LPS)"
                           : "MetaImage " + h.transformKey + " (LPS, converted to RAS)";
  if (!h.anatomicalOrientation.empty() &&
      h.anatomicalOrientation.substr(0, 3) != metaOrientation(v.direction())) {
    source += "; AnatomicalOrientation " + h.anatomicalOrientation + " disagrees (" +
              metaOrientation(v.direction()) + " by the matrix), ignored as ITK does";
  }
  v.setGeometrySource(source);
  std::string description = "MetaImage " + p + " (" + io_detail::dimsString(format.dims) + " " +
                            std::string(io_detail::diskTypeName(format.type)) + ", " +
                            (h.compressed ? "zlib" : "raw");
  if (dataFile)
    description += ", data in " + std::filesystem::path(file.name()).filename().string();
  if (io_detail::isConvertedToF32(format.type)) description += ", converted to f32";
  if (format.type == DiskType::I8) description += ", widened to i16";
  v.setDescription(description + ")");
  return v;
}

}  // namespace tessera
