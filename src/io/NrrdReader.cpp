// NRRD reading after the format definition of Teem 1.9+
// (teem.sourceforge.net/nrrd/format.html); section numbers below refer to it.
#include "tessera/io/NrrdReader.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <optional>
#include <vector>

#include "io/ByteStream.h"
#include "io/HeaderText.h"
#include "io/VoxelLoader.h"
#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/io/NrrdGeometry.h"

namespace tessera {

namespace {

using io_detail::DiskType;
using io_detail::lower;
using io_detail::trim;
using io_detail::words;

// A header is a few hundred bytes; these limits stop us from "parsing" a
// large binary file as text when the magic happens to match.
constexpr std::size_t kMaxHeaderBytes = 1 << 20;
constexpr std::size_t kMaxLineBytes = 64 * 1024;

struct NrrdHeader {
  int dimension = 0;
  std::vector<std::int64_t> sizes;
  std::optional<DiskType> type;
  std::string typeName;
  std::string encoding;  // "raw" or "gzip" once validated
  std::optional<bool> bigEndian;
  std::vector<double> spacings;
  bool hasSpaceDirections = false;
  std::vector<std::optional<std::vector<double>>> spaceDirections;  // nullopt = "none"
  std::optional<std::vector<double>> spaceOrigin;
  std::string space;
  int spaceDimension = 0;
  std::int64_t byteSkip = 0;
  std::int64_t lineSkip = 0;
  std::optional<std::string> dataFile;
  std::string content;
  std::uint64_t headerEnd = 0;  // offset of the first byte after the header
};

class HeaderParser {
 public:
  explicit HeaderParser(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& msg) const {
    throw InputError(path_ + ": line " + std::to_string(line_) + ": " + msg);
  }

  void setLine(int line) { line_ = line; }

  std::int64_t integer(const std::string& s, const std::string& field) const {
    std::int64_t v = 0;
    const char* end = s.data() + s.size();
    const auto [ptr, ec] = std::from_chars(s.data(), end, v);
    if (ec != std::errc() || ptr != end) {
      fail(field + ": '" + s + "' is not an integer");
    }
    return v;
  }

  // Accepts "nan"/"inf" (§2: NaN marks an unknown per-axis value).
  double real(const std::string& s, const std::string& field) const {
    double v = 0.0;
    const char* end = s.data() + s.size();
    const char* begin = s.data();
    if (begin != end && *begin == '+') ++begin;
    const auto [ptr, ec] = std::from_chars(begin, end, v);
    if (ec != std::errc() || ptr != end) fail(field + ": '" + s + "' is not a number");
    return v;
  }

  // "(1.5,0, 0)" → {1.5, 0, 0}
  std::vector<double> vector(const std::string& s, const std::string& field) const {
    const std::string t = trim(s);
    if (t.size() < 2 || t.front() != '(' || t.back() != ')') {
      fail(field + ": '" + s + "' is not a vector like (1,0,0)");
    }
    std::vector<double> v;
    std::size_t b = 1;
    while (b < t.size()) {
      std::size_t e = t.find(',', b);
      if (e == std::string::npos) e = t.size() - 1;
      v.push_back(real(trim(t.substr(b, e - b)), field));
      b = e + 1;
    }
    return v;
  }

  // Splits "(1,0,0) none (0,1,0)" into vector tokens and words.
  std::vector<std::string> vectorTokens(const std::string& s) const {
    std::vector<std::string> out;
    std::size_t i = 0;
    while (i < s.size()) {
      while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
      if (i >= s.size()) break;
      std::size_t e;
      if (s[i] == '(') {
        e = s.find(')', i);
        if (e == std::string::npos) fail("unclosed '(' in '" + s + "'");
        ++e;
      } else {
        e = i;
        while (e < s.size() && !std::isspace(static_cast<unsigned char>(s[e]))) ++e;
      }
      out.push_back(s.substr(i, e - i));
      i = e;
    }
    return out;
  }

 private:
  std::string path_;
  int line_ = 0;
};

std::optional<DiskType> typeFromName(const std::string& name) {
  // §5 "type": every spelling the format allows for the types we read.
  static const std::pair<const char*, DiskType> kNames[] = {
      {"signed char", DiskType::I8},
      {"int8", DiskType::I8},
      {"int8_t", DiskType::I8},
      {"uchar", DiskType::U8},
      {"unsigned char", DiskType::U8},
      {"uint8", DiskType::U8},
      {"uint8_t", DiskType::U8},
      {"short", DiskType::I16},
      {"short int", DiskType::I16},
      {"signed short", DiskType::I16},
      {"signed short int", DiskType::I16},
      {"int16", DiskType::I16},
      {"int16_t", DiskType::I16},
      {"ushort", DiskType::U16},
      {"unsigned short", DiskType::U16},
      {"unsigned short int", DiskType::U16},
      {"uint16", DiskType::U16},
      {"uint16_t", DiskType::U16},
      {"int", DiskType::I32},
      {"signed int", DiskType::I32},
      {"int32", DiskType::I32},
      {"int32_t", DiskType::I32},
      {"uint", DiskType::U32},
      {"unsigned int", DiskType::U32},
      {"uint32", DiskType::U32},
      {"uint32_t", DiskType::U32},
      {"float", DiskType::F32},
      {"double", DiskType::F64},
  };
  const std::string n = lower(trim(name));
  for (const auto& [alias, type] : kNames) {
    if (n == alias) return type;
  }
  return std::nullopt;
}

// "data file: LIST" and "data file: <format> <min> <max> <step> [<subdim>]"
// (§3) spread the data over several files.
bool namesSeveralFiles(const std::string& value) {
  const auto w = words(value);
  if (!w.empty() && w[0] == "LIST") return true;
  if (w.size() >= 4 && w[0].find('%') != std::string::npos) {
    auto isInt = [](const std::string& s) {
      std::int64_t v;
      const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      return ec == std::errc() && ptr == s.data() + s.size();
    };
    return isInt(w[1]) && isInt(w[2]) && isInt(w[3]);
  }
  return false;
}

// Reads the header line by line up to the blank line that ends it (or the
// end of a detached header file).
NrrdHeader parseHeader(const ByteSource& file) {
  const std::string& p = file.name();
  io_detail::LineReader lines(file, kMaxLineBytes,
                              " (is the blank line that ends a NRRD header missing?)");
  auto nextLine = [&](std::string& line) { return lines.next(line); };
  std::string line;
  nextLine(line);
  // §1.1: "NRRD000X", X = 1..5 for the versions defined so far.
  if (line.rfind("NRRD", 0) != 0) {
    std::string shown;
    for (char c : line.substr(0, 8)) {
      shown += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
    }
    throw InputError(p + ": not a NRRD file: starts with '" + shown +
                     "', expected the magic 'NRRD000X'");
  }
  if (line.size() != 8 || line.compare(0, 7, "NRRD000") != 0 || line[7] < '1' || line[7] > '5') {
    throw InputError(p + ": unsupported NRRD magic '" + line.substr(0, 16) +
                     "', expected NRRD0001 .. NRRD0005");
  }

  HeaderParser parse(p);
  NrrdHeader h;
  int lineNo = 1;
  while (true) {
    if (!nextLine(line)) break;  // end of file ends a detached header
    ++lineNo;
    parse.setLine(lineNo);
    if (lines.consumed() > kMaxHeaderBytes) {
      throw InputError(p + ": NRRD header longer than " + std::to_string(kMaxHeaderBytes) +
                       " bytes; is the blank line that ends it missing?");
    }
    if (line.empty()) break;  // §1.2: a blank line separates header and data
    if (line[0] == '#') continue;
    const std::size_t kv = line.find(":=");
    const std::size_t colon = line.find(": ");
    if (kv != std::string::npos && (colon == std::string::npos || kv < colon)) continue;
    if (colon == std::string::npos) {
      parse.fail("'" + line + "' is not a 'field: value' line");
    }
    const std::string field = lower(trim(line.substr(0, colon)));
    const std::string value = trim(line.substr(colon + 2));

    if (field == "dimension") {
      const std::int64_t d = parse.integer(value, field);
      if (d < 1 || d > 16) parse.fail("dimension is " + value + ", expected 1..16");
      h.dimension = static_cast<int>(d);
    } else if (field == "type") {
      h.typeName = value;
      h.type = typeFromName(value);
      if (!h.type) {
        parse.fail("type '" + value +
                   "' is not supported; expected uchar, signed char, ushort, short, uint, int, "
                   "float or double (or an alias)");
      }
    } else if (field == "sizes") {
      h.sizes.clear();
      for (const auto& w : words(value)) h.sizes.push_back(parse.integer(w, field));
    } else if (field == "encoding") {
      const std::string e = lower(value);
      if (e == "raw") {
        h.encoding = "raw";
      } else if (e == "gzip" || e == "gz") {
        h.encoding = "gzip";
      } else {
        parse.fail("encoding '" + value + "' is not supported; expected raw or gzip");
      }
    } else if (field == "endian") {
      const std::string e = lower(value);
      if (e != "little" && e != "big")
        parse.fail("endian is '" + value + "', expected little or big");
      h.bigEndian = e == "big";
    } else if (field == "spacings") {
      h.spacings.clear();
      for (const auto& w : words(value)) h.spacings.push_back(parse.real(w, field));
    } else if (field == "space directions") {
      h.hasSpaceDirections = true;
      h.spaceDirections.clear();
      for (const auto& t : parse.vectorTokens(value)) {
        if (lower(t) == "none") {
          h.spaceDirections.emplace_back(std::nullopt);
        } else {
          h.spaceDirections.emplace_back(parse.vector(t, field));
        }
      }
    } else if (field == "space origin") {
      h.spaceOrigin = parse.vector(value, field);
    } else if (field == "space") {
      h.space = value;
    } else if (field == "space dimension") {
      const std::int64_t d = parse.integer(value, field);
      if (d < 1 || d > 8) parse.fail("space dimension is " + value + ", expected 1..8");
      h.spaceDimension = static_cast<int>(d);
    } else if (field == "byte skip") {
      h.byteSkip = parse.integer(value, field);
      if (h.byteSkip < -1) parse.fail("byte skip is " + value + ", expected -1 or >= 0");
    } else if (field == "line skip") {
      h.lineSkip = parse.integer(value, field);
      if (h.lineSkip < 0) parse.fail("line skip is " + value + ", expected >= 0");
    } else if (field == "data file" || field == "datafile") {
      // Checked here: with "LIST" the file names follow as header lines.
      if (namesSeveralFiles(value)) {
        parse.fail("'data file: " + value +
                   "' spreads the data over several files; not supported (use one data file)");
      }
      h.dataFile = value;
    } else if (field == "content") {
      h.content = value;
    } else if (field == "block size" || field == "blocksize") {
      // only meaningful for type "block", which typeFromName rejects
    }
    // Other fields (kinds, centers, labels, units, thicknesses, min, max,
    // measurement frame, ...) change neither the voxels nor their placement.
  }
  // For an attached header without its blank line this is the end of the
  // file, and the size check reports the missing data.
  h.headerEnd = lines.consumed();
  return h;
}

// Byte offset just past `lines` newlines counted from `offset` (§5 "line
// skip"); InputError if the file has fewer lines.
std::uint64_t skipLines(const ByteSource& file, std::uint64_t offset, std::int64_t lines,
                        const std::string& what) {
  if (lines == 0) return offset;
  io_detail::SourceStream src(file, offset);
  std::vector<std::byte> buf(64 * 1024);
  std::int64_t seen = 0;
  std::uint64_t pos = offset;
  while (seen < lines) {
    const std::size_t got = src.read(buf.data(), buf.size());
    if (got == 0) {
      throw InputError(what + ": line skip is " + std::to_string(lines) + ", but " + file.name() +
                       " ends after " + std::to_string(seen) + " lines");
    }
    for (std::size_t i = 0; i < got; ++i) {
      if (buf[i] == std::byte{'\n'} && ++seen == lines) return pos + i + 1;
    }
    pos += got;
  }
  return pos;
}

}  // namespace

Volume readNrrd(const std::filesystem::path& path) {
  return readNrrd(FileSource(path), FolderFiles());
}

Volume readNrrd(const ByteSource& file, const FileSet& files) {
  const std::string& p = file.name();
  NrrdHeader h = parseHeader(file);

  io_detail::requireField(h.dimension > 0, p, "NRRD", "dimension");
  io_detail::requireField(!h.sizes.empty(), p, "NRRD", "sizes");
  io_detail::requireField(h.type.has_value(), p, "NRRD", "type");
  io_detail::requireField(!h.encoding.empty(), p, "NRRD", "encoding");
  if (h.sizes.size() != static_cast<std::size_t>(h.dimension)) {
    throw InputError(p + ": 'sizes' has " + std::to_string(h.sizes.size()) +
                     " values, but dimension is " + std::to_string(h.dimension));
  }
  auto checkPerAxis = [&](std::size_t n, const std::string& field) {
    if (n != 0 && n != static_cast<std::size_t>(h.dimension)) {
      throw InputError(p + ": '" + field + "' has " + std::to_string(n) +
                       " values, but dimension is " + std::to_string(h.dimension));
    }
  };
  checkPerAxis(h.spacings.size(), "spacings");
  checkPerAxis(h.spaceDirections.size(), "space directions");
  // An empty "space directions:" line still means "space directions give the
  // spacing", so it must have one entry per axis like any other.
  if (h.hasSpaceDirections && h.spaceDirections.empty()) {
    throw InputError(p + ": 'space directions' has no values, but dimension is " +
                     std::to_string(h.dimension));
  }
  for (std::size_t a = 0; a < h.sizes.size(); ++a) {
    if (h.sizes[a] <= 0) {
      throw InputError(p + ": size of axis " + std::to_string(a) + " is " +
                       std::to_string(h.sizes[a]) + ", expected >= 1");
    }
  }

  // Keep the three spatial axes: a 4-D file qualifies when its extra axis
  // (first, as for a 1-component vector, or last) has size 1.
  std::size_t first = 0;
  if (h.dimension == 4 && h.sizes[0] == 1) {
    first = 1;
  } else if (h.dimension == 4 && h.sizes[3] == 1) {
    first = 0;
  } else if (h.dimension != 3) {
    std::string sizes;
    for (auto s : h.sizes) {
      if (!sizes.empty()) sizes += ' ';
      sizes += std::to_string(s);
    }
    throw InputError(p + ": dimension is " + std::to_string(h.dimension) + " (sizes " + sizes +
                     "); Tessera reads 3-D volumes, or 4-D with a size-1 first or last axis");
  }

  io_detail::VoxelFormat format;
  for (int a = 0; a < 3; ++a) {
    const std::int64_t s = h.sizes[first + a];
    if (s > (1 << 20)) {
      throw InputError(p + ": size of axis " + std::to_string(first + a) + " is " +
                       std::to_string(s) + ", expected at most " + std::to_string(1 << 20));
    }
    format.dims[a] = static_cast<int>(s);
  }
  format.type = *h.type;
  if (io_detail::diskTypeSize(format.type) > 1) {
    if (!h.bigEndian) {
      throw InputError(p + ": NRRD header has no 'endian' field, which type '" + h.typeName +
                       "' needs");
    }
    format.bigEndian = *h.bigEndian;
  }

  // Placement (io/NrrdGeometry), checked before the voxels are read.
  NrrdGeometryFields g;
  g.space = h.space;
  g.spaceDimension = h.spaceDimension;
  g.hasSpaceDirections = h.hasSpaceDirections;
  g.spaceOrigin = h.spaceOrigin;
  g.firstAxis = static_cast<int>(first);
  for (int a = 0; a < 3; ++a) {
    const std::size_t axis = first + static_cast<std::size_t>(a);
    if (h.hasSpaceDirections) g.spaceDirections.push_back(h.spaceDirections[axis]);
    if (!h.spacings.empty()) g.spacings[a] = h.spacings[axis];
  }
  const NrrdGeometry geometry = nrrdGeometry(g, p);

  io_detail::VoxelSource source;
  std::uint64_t start = h.headerEnd;
  source.file = &file;
  std::unique_ptr<ByteSource> dataFile;
  if (h.dataFile) {
    // §3: a relative data file name is relative to the header's directory.
    try {
      dataFile = files.open(files.resolve(file, *h.dataFile));
    } catch (const InputError& e) {
      // The user named the header; say which header wants the missing file.
      throw InputError(p + ": data file: " + e.what());
    }
    source.file = dataFile.get();
    start = 0;
  }
  start = skipLines(*source.file, start, h.lineSkip, p);
  if (h.encoding == "gzip") {
    if (h.byteSkip < 0) {
      throw InputError(p +
                       ": byte skip -1 (data at the end of the file) is only valid with raw "
                       "encoding, this file is gzip");
    }
    source.gzip = true;
    source.fileOffset = start;
    // Teem applies byte skip to the decompressed stream for gzip.
    source.inflatedSkip = static_cast<std::uint64_t>(h.byteSkip);
  } else if (h.byteSkip == -1) {
    source.atEndOfFile = true;
  } else {
    source.fileOffset = start + static_cast<std::uint64_t>(h.byteSkip);
  }

  Volume v = io_detail::loadVoxels(source, format, p);
  v.setIndexToWorld(geometry.indexToWorld);
  v.setGeometrySource(geometry.source);
  std::string description = "NRRD " + p + " (" + io_detail::dimsString(format.dims) + " " +
                            std::string(io_detail::diskTypeName(format.type)) + ", " + h.encoding;
  if (io_detail::isConvertedToF32(format.type)) description += ", converted to f32";
  if (format.type == DiskType::I8) description += ", widened to i16";
  if (!h.content.empty()) description += ", content: " + h.content;
  v.setDescription(description + ")");
  return v;
}

}  // namespace tessera
