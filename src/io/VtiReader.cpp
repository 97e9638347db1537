// VTK XML ImageData (.vti) after "VTK File Formats" (VTK User's Guide, 11th
// ed., §19.3 "XML File Formats") and the binary layout that vtkXMLWriter
// writes and vtkXMLDataParser reads: every binary array starts with a header
// of UInt32 or UInt64 words (VTKFile header_type), [byte count] for plain
// data or [#blocks, block size, last block size, compressed size of each
// block] for vtkZLibDataCompressor, each block one zlib stream.
#include "tessera/io/VtiReader.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>
#include <vector>

#include "io/Base64.h"
#include "io/ByteStream.h"
#include "io/HeaderText.h"
#include "io/Inflater.h"
#include "io/VoxelLoader.h"
#include "io/XmlPullParser.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"

namespace tessera {

namespace {

using io_detail::DiskType;
using io_detail::words;
using io_detail::XmlEvent;

// Extents beyond this cannot describe a volume we could hold, and keeping
// them below 2^53 keeps the arithmetic on them exact.
constexpr std::int64_t kMaxExtentMagnitude = std::int64_t{1} << 53;
constexpr std::int64_t kMaxDim = 1 << 20;

using Extent = std::array<std::int64_t, 6>;

struct DataArrayInfo {
  std::string name;
  std::string type;
  std::string format = "ascii";  // VTK's default when the attribute is absent
  std::int64_t components = 1;
  std::optional<std::uint64_t> offset;
  std::optional<std::int64_t> tuples;
  int line = 0;
  // Inline data: the non-blank text directly inside the element.
  bool hasText = false;
  std::uint64_t textBegin = 0;
  std::uint64_t textEnd = 0;
};

struct VtiDocument {
  bool bigEndian = false;
  std::size_t headerWordBytes = 4;  // UInt32 or UInt64
  bool zlib = false;
  bool hasImageData = false;
  Extent wholeExtent{};
  glm::dvec3 origin{0.0};
  glm::dvec3 spacing{1.0};
  // Direction's 9 values, row by row (vtkXMLImageDataWriter writes
  // vtkMatrix3x3::GetData(), which is row-major); glm is column-major.
  glm::dmat3 direction{1.0};
  bool hasDirection = false;
  int pieces = 0;
  std::optional<Extent> pieceExtent;
  std::string scalarsName;
  std::optional<DataArrayInfo> firstArray;
  std::optional<DataArrayInfo> namedArray;
  int cellArrays = 0;
  bool hasAppended = false;
  std::string appendedEncoding = "raw";
  std::uint64_t appendedStart = 0;  // file offset just after the '_'
};

using io_detail::numberString;

class AttributeReader {
 public:
  AttributeReader(const std::string& what, const XmlEvent& ev) : what_(what), ev_(ev) {}

  [[noreturn]] void fail(const std::string& msg) const {
    throw InputError(what_ + ": line " + std::to_string(ev_.line) + ": <" + ev_.name + "> " + msg);
  }

  const std::string* get(const char* name) const { return ev_.attribute(name); }

  std::int64_t integer(const std::string& s, const char* attr) const {
    return parsed<std::int64_t>(s, attr, "an integer");
  }

  double real(const std::string& s, const char* attr) const {
    return parsed<double>(s, attr, "a number");
  }

  std::vector<double> reals(const char* attr, std::size_t n) const {
    const std::string* v = get(attr);
    const auto w = words(*v);
    if (w.size() != n) {
      fail(std::string(attr) + "=\"" + *v + "\" has " + std::to_string(w.size()) +
           " values, expected " + std::to_string(n));
    }
    std::vector<double> out;
    for (const auto& s : w) out.push_back(real(s, attr));
    return out;
  }

  Extent extent(const char* attr) const {
    const std::string* v = get(attr);
    const auto w = words(*v);
    if (w.size() != 6) {
      fail(std::string(attr) + "=\"" + *v + "\" has " + std::to_string(w.size()) +
           " values, expected 6 (x0 x1 y0 y1 z0 z1)");
    }
    Extent e{};
    for (int i = 0; i < 6; ++i) {
      e[static_cast<std::size_t>(i)] = integer(w[static_cast<std::size_t>(i)], attr);
      if (std::abs(e[static_cast<std::size_t>(i)]) > kMaxExtentMagnitude) {
        fail(std::string(attr) + ": '" + w[static_cast<std::size_t>(i)] + "' is out of range");
      }
    }
    return e;
  }

 private:
  // The whole of `s` as a T (a leading '+' allowed, as VTK writes it), or a
  // failure saying it is not `kind`.
  template <class T>
  T parsed(const std::string& s, const char* attr, const char* kind) const {
    T v{};
    const char* b = s.data();
    const char* e = s.data() + s.size();
    if (b != e && *b == '+') ++b;
    const auto [ptr, ec] = std::from_chars(b, e, v);
    if (ec != std::errc() || ptr != e) fail(std::string(attr) + ": '" + s + "' is not " + kind);
    return v;
  }

  const std::string& what_;
  const XmlEvent& ev_;
};

void readFileAttributes(const AttributeReader& a, VtiDocument& doc) {
  const std::string* type = a.get("type");
  if (type == nullptr) a.fail("has no 'type' attribute");
  if (*type != "ImageData") {
    a.fail("type is '" + *type + "'; Tessera reads type=\"ImageData\" (.vti) only");
  }
  if (const std::string* order = a.get("byte_order")) {
    if (*order == "BigEndian") {
      doc.bigEndian = true;
    } else if (*order != "LittleEndian") {
      a.fail("byte_order is '" + *order + "', expected LittleEndian or BigEndian");
    }
  }
  if (const std::string* header = a.get("header_type")) {
    if (*header == "UInt64") {
      doc.headerWordBytes = 8;
    } else if (*header != "UInt32") {
      a.fail("header_type is '" + *header + "', expected UInt32 or UInt64");
    }
  }
  if (const std::string* compressor = a.get("compressor")) {
    if (*compressor == "vtkZLibDataCompressor") {
      doc.zlib = true;
    } else if (!compressor->empty()) {
      a.fail("compressor '" + *compressor +
             "' is not supported; expected vtkZLibDataCompressor or none");
    }
  }
}

void readImageDataAttributes(const AttributeReader& a, VtiDocument& doc) {
  doc.hasImageData = true;
  if (a.get("WholeExtent") == nullptr) a.fail("has no WholeExtent");
  doc.wholeExtent = a.extent("WholeExtent");
  if (a.get("Origin") != nullptr) {
    const auto o = a.reals("Origin", 3);
    doc.origin = {o[0], o[1], o[2]};
  }
  if (a.get("Spacing") != nullptr) {
    const auto s = a.reals("Spacing", 3);
    doc.spacing = {s[0], s[1], s[2]};
  }
  if (a.get("Direction") != nullptr) {
    const auto d = a.reals("Direction", 9);
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) {
        doc.direction[col][row] = d[static_cast<std::size_t>(row * 3 + col)];
      }
    }
    doc.hasDirection = true;
  }
}

DataArrayInfo readDataArrayAttributes(const AttributeReader& a, int line) {
  DataArrayInfo info;
  info.line = line;
  if (const std::string* v = a.get("Name")) info.name = *v;
  if (const std::string* v = a.get("type")) info.type = *v;
  if (info.type.empty()) a.fail("has no 'type' attribute");
  if (const std::string* v = a.get("format")) info.format = *v;
  if (const std::string* v = a.get("NumberOfComponents")) {
    info.components = a.integer(*v, "NumberOfComponents");
  }
  if (const std::string* v = a.get("NumberOfTuples")) {
    info.tuples = a.integer(*v, "NumberOfTuples");
  }
  if (const std::string* v = a.get("offset")) {
    const std::int64_t o = a.integer(*v, "offset");
    if (o < 0) a.fail("offset is " + *v + ", expected >= 0");
    info.offset = static_cast<std::uint64_t>(o);
  }
  return info;
}

// Walks the markup up to <AppendedData> (whose content is not XML) or the end
// of the document, keeping only what describes the image and its point data.
VtiDocument parseDocument(const ByteSource& file) {
  const std::string& p = file.name();
  io_detail::XmlPullParser xml(file);
  VtiDocument doc;
  std::vector<std::string> open;
  std::optional<DataArrayInfo> array;  // the point-data array being read
  bool inPointData = false;
  while (true) {
    XmlEvent ev = xml.next();
    switch (ev.kind) {
      case XmlEvent::Kind::EndOfDocument:
        return doc;
      case XmlEvent::Kind::Text:
        if (array && open.size() == 5 && !ev.blank) {
          if (array->hasText) {
            throw InputError(p + ": line " + std::to_string(ev.line) + ": the data of DataArray '" +
                             array->name + "' is split by markup; not supported");
          }
          array->hasText = true;
          array->textBegin = ev.textBegin;
          array->textEnd = ev.textEnd;
        }
        break;
      case XmlEvent::Kind::EndElement:
        if (array && open.size() == 5) {
          if (!doc.firstArray) doc.firstArray = *array;
          if (!doc.namedArray && !doc.scalarsName.empty() && array->name == doc.scalarsName) {
            doc.namedArray = *array;
          }
          array.reset();
        }
        if (open.size() == 4 && open.back() == "PointData") inPointData = false;
        open.pop_back();
        break;
      case XmlEvent::Kind::StartElement: {
        const AttributeReader a(p, ev);
        const std::string parent = open.empty() ? std::string() : open.back();
        if (open.empty()) {
          if (ev.name != "VTKFile") {
            a.fail("is the root element; a VTK XML file starts with <VTKFile>");
          }
          readFileAttributes(a, doc);
        } else if (ev.name == "AppendedData") {
          if (open.size() != 1) a.fail("must be a child of <VTKFile>");
          if (const std::string* enc = a.get("encoding")) doc.appendedEncoding = *enc;
          doc.hasAppended = true;
          doc.appendedStart = xml.offsetAfterMarker('_');
          return doc;
        } else if (open.size() == 1 && ev.name == "ImageData") {
          if (doc.hasImageData) a.fail("appears twice");
          readImageDataAttributes(a, doc);
        } else if (open.size() == 2 && parent == "ImageData" && ev.name == "Piece") {
          if (++doc.pieces > 1) {
            a.fail("appears more than once; images split into several pieces are not supported");
          }
          if (a.get("Extent") != nullptr) doc.pieceExtent = a.extent("Extent");
        } else if (open.size() == 3 && parent == "Piece" && ev.name == "PointData") {
          inPointData = true;
          if (const std::string* s = a.get("Scalars")) doc.scalarsName = *s;
        } else if (open.size() == 4 && parent == "PointData" && inPointData &&
                   ev.name == "DataArray") {
          array = readDataArrayAttributes(a, ev.line);
        } else if (open.size() == 4 && parent == "CellData" && ev.name == "DataArray") {
          ++doc.cellArrays;
        }
        open.push_back(ev.name);
        break;
      }
    }
  }
}

std::optional<DiskType> diskTypeFor(const std::string& vtkType) {
  static const std::pair<const char*, DiskType> kTypes[] = {
      {"UInt8", DiskType::U8},    {"Int8", DiskType::I8},     {"UInt16", DiskType::U16},
      {"Int16", DiskType::I16},   {"UInt32", DiskType::U32},  {"Int32", DiskType::I32},
      {"Float32", DiskType::F32}, {"Float64", DiskType::F64},
  };
  for (const auto& [name, type] : kTypes) {
    if (vtkType == name) return type;
  }
  return std::nullopt;
}

// Inflates vtkZLibDataCompressor blocks one at a time, so at most one block
// (compressed and inflated) is held besides the volume.
class ZlibBlockStream : public io_detail::ByteStream {
 public:
  ZlibBlockStream(io_detail::ByteStream& compressed, std::vector<std::uint64_t> sizes,
                  std::uint64_t blockBytes, std::uint64_t lastBlockBytes, std::string what)
      : src_(compressed),
        sizes_(std::move(sizes)),
        blockBytes_(blockBytes),
        lastBlockBytes_(lastBlockBytes),
        what_(std::move(what)) {}

  std::size_t read(std::byte* dst, std::size_t n) override {
    std::size_t done = 0;
    while (done < n) {
      if (pos_ == out_.size()) {
        if (next_ == sizes_.size()) break;
        inflateNextBlock();
      }
      const std::size_t take = std::min(n - done, out_.size() - pos_);
      std::memcpy(dst + done, out_.data() + pos_, take);
      done += take;
      pos_ += take;
    }
    return done;
  }

 private:
  void inflateNextBlock() {
    const std::size_t i = next_++;
    const std::string block =
        what_ + ": zlib block " + std::to_string(i + 1) + " of " + std::to_string(sizes_.size());
    const std::uint64_t packed = sizes_[i];
    const std::uint64_t unpacked = next_ == sizes_.size() ? lastBlockBytes_ : blockBytes_;
    in_.resize(static_cast<std::size_t>(packed));
    const std::size_t got = src_.read(in_.data(), in_.size());
    if (got < packed) {
      throw InputError(block + " ends after " + std::to_string(got) + " of its " +
                       std::to_string(packed) + " compressed bytes");
    }
    // One byte more than the header gives, to see a block that holds more.
    out_.resize(static_cast<std::size_t>(unpacked) + 1);
    pos_ = 0;
    const auto inflater = io_detail::Inflater::create();
    std::size_t inPos = 0;
    std::size_t outPos = 0;
    bool ended = false;
    while (!ended) {
      const io_detail::Inflater::Step step =
          inflater->inflate(std::span<const std::byte>(in_).subspan(inPos),
                            std::span<std::byte>(out_).subspan(outPos));
      if (!step.error.empty()) {
        throw InputError(block + " is not valid zlib data (corrupt: " + step.error + ")");
      }
      inPos += step.consumed;
      outPos += step.produced;
      ended = step.ended;
      if (!ended && step.consumed == 0 && step.produced == 0) break;
    }
    if (outPos > unpacked) {
      throw InputError(block + " inflates to more than the " + std::to_string(unpacked) +
                       " bytes its header gives");
    }
    if (!ended) throw InputError(block + " is not valid zlib data (corrupt: cut short)");
    if (outPos != unpacked) {
      throw InputError(block + " inflates to " + std::to_string(outPos) +
                       " bytes, its header says " + std::to_string(unpacked));
    }
    out_.resize(outPos);
  }

  io_detail::ByteStream& src_;
  std::vector<std::uint64_t> sizes_;
  std::uint64_t blockBytes_;
  std::uint64_t lastBlockBytes_;
  std::string what_;
  std::size_t next_ = 0;
  std::vector<std::byte> in_;
  std::vector<std::byte> out_;
  std::size_t pos_ = 0;
};

struct ArrayContext {
  std::string what;  // "file: DataArray 'name'"
  io_detail::VoxelFormat format;
  std::uint64_t voxels = 0;
  std::uint64_t dataBytes = 0;  // voxels × stored type size
  std::size_t headerWordBytes = 4;
  bool zlib = false;
};

std::string sizeText(const ArrayContext& c) {
  return io_detail::dimsString(c.format.dims) + " " +
         std::string(io_detail::diskTypeName(c.format.type)) + " = " + std::to_string(c.dataBytes) +
         " bytes";
}

// Binary data (raw or decoded base64) from the array's header on.
// `available` bounds the bytes `src` can deliver.
Volume readBinaryArray(io_detail::ByteStream& src, std::uint64_t available, const ArrayContext& c) {
  const std::uint64_t w = c.headerWordBytes;
  auto word = [&](const char* what) {
    unsigned char b[8] = {};
    const std::size_t got = src.read(reinterpret_cast<std::byte*>(b), w);
    if (got < w) {
      throw InputError(c.what + ": data ends inside its header (reading " + what + ")");
    }
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < w; ++i) {
      const std::size_t k = c.format.bigEndian ? i : w - 1 - i;
      v = (v << 8) | b[k];
    }
    return v;
  };
  if (!c.zlib) {
    if (available < w) throw InputError(c.what + ": data ends before its header");
    const std::uint64_t n = word("the byte count");
    if (n != c.dataBytes) {
      throw InputError(c.what + ": header says " + std::to_string(n) +
                       " bytes of data, the extent " + "and type need " + sizeText(c));
    }
    if (n > available - w) {
      throw InputError(c.what + ": needs " + std::to_string(n) + " bytes of data (" + sizeText(c) +
                       "), the file holds at most " + std::to_string(available - w) + " (" +
                       formatBytes(available - w) + ")");
    }
    return io_detail::decodeVoxels(src, c.format, c.what);
  }

  if (available < 3 * w) throw InputError(c.what + ": data ends before its compression header");
  const std::uint64_t blocks = word("the number of blocks");
  const std::uint64_t blockBytes = word("the block size");
  const std::uint64_t lastPartial = word("the last block size");
  const std::uint64_t room = available - 3 * w;
  if (blocks > room / w) {
    throw InputError(c.what + ": compression header says " + std::to_string(blocks) +
                     " blocks, but the file holds at most " + std::to_string(room) +
                     " bytes after it");
  }
  // vtkXMLWriter: every block holds `blockBytes` but the last, which holds
  // `lastPartial` when that is non-zero.
  const std::uint64_t last = lastPartial == 0 ? blockBytes : lastPartial;
  const auto mismatch = [&]() {
    return InputError(c.what + ": compression header says " + std::to_string(blocks) +
                      " blocks of " + std::to_string(blockBytes) + " bytes (last " +
                      std::to_string(last) + "), but the extent and type need " + sizeText(c));
  };
  if (blocks == 0 || blockBytes == 0 || lastPartial > blockBytes || last > c.dataBytes ||
      blocks - 1 > (c.dataBytes - last) / blockBytes ||
      (blocks - 1) * blockBytes + last != c.dataBytes) {
    throw mismatch();
  }
  std::vector<std::uint64_t> sizes(static_cast<std::size_t>(blocks));
  std::uint64_t total = 0;
  std::uint64_t largest = 0;
  for (std::uint64_t i = 0; i < blocks; ++i) {
    const std::uint64_t s = word("the compressed block sizes");
    const std::uint64_t unpacked = i + 1 == blocks ? last : blockBytes;
    if (s == 0 || s > room || unpacked / io_detail::kMaxDeflateRatio > s) {
      throw InputError(
          c.what + ": zlib block " + std::to_string(i + 1) + " of " + std::to_string(blocks) +
          " is said to be " + std::to_string(s) + " compressed bytes holding " +
          std::to_string(unpacked) +
          (s == 0 || s > room ? " (the file cannot hold it)" : " (deflate's limit is 1032:1)"));
    }
    sizes[static_cast<std::size_t>(i)] = s;
    total += s;
    if (total > room - blocks * w) {
      throw InputError(c.what + ": the " + std::to_string(blocks) +
                       " zlib blocks add up to more compressed bytes than the file holds (" +
                       std::to_string(room - blocks * w) + ")");
    }
    largest = std::max(largest, s);
  }
  // One compressed and one inflated block are held beside the volume.
  HostBudget::global().check(
      largest + std::min(blockBytes, c.dataBytes) +
          c.voxels * bytesPerVoxel(io_detail::volumeTypeFor(c.format)),
      c.what + " (" + io_detail::dimsString(c.format.dims) + ", zlib blocks plus volume)");
  ZlibBlockStream inflated(src, std::move(sizes), blockBytes, last, c.what);
  return io_detail::decodeVoxels(inflated, c.format, c.what);
}

template <class Int>
bool parseInteger(const std::string& token, std::int64_t lo, std::int64_t hi, Int& out) {
  std::int64_t v = 0;
  const char* b = token.data();
  const char* e = token.data() + token.size();
  if (b != e && *b == '+') ++b;
  const auto [ptr, ec] = std::from_chars(b, e, v);
  if (ec != std::errc() || ptr != e || v < lo || v > hi) return false;
  out = static_cast<Int>(v);
  return true;
}

template <class Real>
bool parseReal(const std::string& token, Real& out) {
  const char* b = token.data();
  const char* e = token.data() + token.size();
  if (b != e && *b == '+') ++b;
  const auto [ptr, ec] = std::from_chars(b, e, out);
  return ec == std::errc() && ptr == e;
}

bool storeAsciiValue(const std::string& token, DiskType type, Volume& v, std::size_t i) {
  switch (type) {
    case DiskType::U8:
      return parseInteger(token, 0, 255, v.dataAs<std::uint8_t>()[i]);
    case DiskType::I8:
      return parseInteger(token, -128, 127, v.dataAs<std::int16_t>()[i]);
    case DiskType::U16:
      return parseInteger(token, 0, 65535, v.dataAs<std::uint16_t>()[i]);
    case DiskType::I16:
      return parseInteger(token, -32768, 32767, v.dataAs<std::int16_t>()[i]);
    case DiskType::U32: {
      std::uint32_t x = 0;
      if (!parseInteger(token, 0, std::numeric_limits<std::uint32_t>::max(), x)) return false;
      v.dataAs<float>()[i] = static_cast<float>(x);
      return true;
    }
    case DiskType::I32: {
      std::int32_t x = 0;
      if (!parseInteger(token, std::numeric_limits<std::int32_t>::min(),
                        std::numeric_limits<std::int32_t>::max(), x)) {
        return false;
      }
      v.dataAs<float>()[i] = static_cast<float>(x);
      return true;
    }
    case DiskType::F32:
      return parseReal(token, v.dataAs<float>()[i]);
    case DiskType::F64: {
      double x = 0.0;
      if (!parseReal(token, x)) return false;
      v.dataAs<float>()[i] = static_cast<float>(x);
      return true;
    }
  }
  return false;
}

Volume readAsciiArray(const ByteSource& file, std::uint64_t begin, std::uint64_t end,
                      const ArrayContext& c, const std::string& typeName) {
  const std::uint64_t chars = end - begin;
  // Each value takes a character and a separator: refuse before allocating.
  if (c.voxels > (chars + 1) / 2) {
    throw InputError(c.what + ": its ascii text of " + std::to_string(chars) +
                     " characters holds at most " + std::to_string((chars + 1) / 2) +
                     " values, the extent needs " + std::to_string(c.voxels) + " (" +
                     io_detail::dimsString(c.format.dims) + ")");
  }
  Volume v = Volume::allocate(c.format.dims, io_detail::volumeTypeFor(c.format), c.what);
  io_detail::SourceStream text(file, begin);
  std::vector<char> buf(64 * 1024);
  std::uint64_t left = chars;
  std::uint64_t count = 0;
  std::string token;
  const auto flush = [&]() {
    if (token.empty()) return;
    if (count >= c.voxels) {
      throw InputError(c.what + ": ascii data has more than the " + std::to_string(c.voxels) +
                       " values the extent needs (" + io_detail::dimsString(c.format.dims) + ")");
    }
    if (!storeAsciiValue(token, c.format.type, v, static_cast<std::size_t>(count))) {
      throw InputError(c.what + ": ascii value " + std::to_string(count + 1) + " '" + token +
                       "' is not a valid " + typeName);
    }
    ++count;
    token.clear();
  };
  while (left > 0) {
    const std::size_t want = static_cast<std::size_t>(std::min<std::uint64_t>(left, buf.size()));
    const std::size_t got = text.read(reinterpret_cast<std::byte*>(buf.data()), want);
    if (got == 0) break;
    left -= got;
    for (std::size_t i = 0; i < got; ++i) {
      const char ch = buf[i];
      if (ch == ' ' || ch == '\n' || ch == '\t' || ch == '\r') {
        flush();
      } else if (token.size() >= 64) {
        throw InputError(c.what + ": ascii value " + std::to_string(count + 1) + " '" +
                         token.substr(0, 20) + "...' is not a number");
      } else {
        token += ch;
      }
    }
  }
  flush();
  if (count < c.voxels) {
    throw InputError(c.what + ": ascii data has " + std::to_string(count) + " values, the extent " +
                     "needs " + std::to_string(c.voxels) + " (" +
                     io_detail::dimsString(c.format.dims) + ")");
  }
  v.invalidateRange();
  return v;
}

std::string extentString(const Extent& e) {
  std::string s;
  // Built piecewise: GCC 12 warns falsely (-Wrestrict) on "" + string.
  for (auto v : e) {
    if (!s.empty()) s += ' ';
    s += std::to_string(v);
  }
  return s;
}

}  // namespace

Volume readVti(const std::filesystem::path& path) {
  return readVti(FileSource(path));
}

Volume readVti(const ByteSource& file) {
  const std::string& p = file.name();
  const std::uint64_t fileSize = file.size();
  const VtiDocument doc = parseDocument(file);
  if (!doc.hasImageData) throw InputError(p + ": VTK file has no <ImageData> element");
  if (doc.pieces == 0) throw InputError(p + ": <ImageData> has no <Piece>");
  if (doc.pieceExtent && *doc.pieceExtent != doc.wholeExtent) {
    throw InputError(p + ": Piece Extent \"" + extentString(*doc.pieceExtent) +
                     "\" differs from WholeExtent \"" + extentString(doc.wholeExtent) +
                     "\"; a piece of a larger image is not supported");
  }

  io_detail::VoxelFormat format;
  const char* axes = "xyz";
  for (int a = 0; a < 3; ++a) {
    const std::int64_t lo = doc.wholeExtent[static_cast<std::size_t>(2 * a)];
    const std::int64_t hi = doc.wholeExtent[static_cast<std::size_t>(2 * a + 1)];
    const std::int64_t n = hi - lo + 1;  // |lo|, |hi| <= 2^53: exact
    if (n < 1 || n > kMaxDim) {
      throw InputError(p + ": WholeExtent \"" + extentString(doc.wholeExtent) + "\" gives " +
                       std::to_string(n) + " points along " + axes[a] + ", expected 1.." +
                       std::to_string(kMaxDim));
    }
    format.dims[a] = static_cast<int>(n);
  }
  glm::dvec3 origin = doc.origin;
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(doc.spacing[a]) || doc.spacing[a] <= 0.0) {
      throw InputError(p + ": Spacing along " + std::string(1, axes[a]) + " is " +
                       numberString(doc.spacing[a]) + ", expected a finite value > 0");
    }
    if (!std::isfinite(doc.origin[a])) {
      throw InputError(p + ": Origin along " + std::string(1, axes[a]) + " is " +
                       numberString(doc.origin[a]) + ", expected a finite value");
    }
  }
  // vtkImageData::ComputeTransforms: point (i, j, k) of the extent lies at
  // Origin + Direction * diag(Spacing) * (i, j, k), so Direction's columns
  // are the axes. VTK has no patient frame: these coordinates are taken as
  // Tessera's RAS world unchanged (and written back the same way).
  glm::dmat4 affine(1.0);
  for (int a = 0; a < 3; ++a) affine[a] = glm::dvec4(doc.direction[a] * doc.spacing[a], 0.0);
  const glm::dvec3 first(static_cast<double>(doc.wholeExtent[0]),
                         static_cast<double>(doc.wholeExtent[2]),
                         static_cast<double>(doc.wholeExtent[4]));
  // Tessera's voxel 0 is the extent's first point.
  affine[3] = glm::dvec4(origin + glm::dvec3(affine * glm::dvec4(first, 0.0)), 1.0);
  for (int a = 0; a < 3; ++a) {
    for (int r = 0; r < 3; ++r) {
      if (!std::isfinite(doc.direction[a][r])) {
        throw InputError(p + ": Direction value " + std::to_string(r * 3 + a + 1) + " is " +
                         numberString(doc.direction[a][r]) + ", expected a finite number");
      }
    }
    if (doc.direction[a] == glm::dvec3(0.0)) {
      throw InputError(p + ": Direction column " + std::to_string(a + 1) + " (axis " +
                       std::string(1, axes[a]) + ") is (0 0 0); expected a unit vector");
    }
  }

  const DataArrayInfo* array = nullptr;
  if (!doc.scalarsName.empty()) {
    if (!doc.namedArray) {
      throw InputError(p + ": PointData names Scalars=\"" + doc.scalarsName +
                       "\", but has no DataArray of that name");
    }
    array = &*doc.namedArray;
  } else if (doc.firstArray) {
    array = &*doc.firstArray;
  } else {
    throw InputError(p + ": the image has no point-data array" +
                     (doc.cellArrays > 0 ? std::string("; cell data is not supported") : ""));
  }

  ArrayContext c;
  c.what = p + ": DataArray '" + array->name + "' (line " + std::to_string(array->line) + ")";
  if (array->components != 1) {
    throw InputError(c.what + " has " + std::to_string(array->components) +
                     " components; Tessera reads scalar (1-component) arrays");
  }
  const auto type = diskTypeFor(array->type);
  if (!type) {
    throw InputError(c.what + " has type '" + array->type +
                     "', which is not supported; expected UInt8, Int8, UInt16, Int16, UInt32, "
                     "Int32, Float32 or Float64");
  }
  format.type = *type;
  format.bigEndian = doc.bigEndian;
  c.format = format;
  c.voxels = static_cast<std::uint64_t>(format.dims.x) * static_cast<std::uint64_t>(format.dims.y) *
             static_cast<std::uint64_t>(format.dims.z);
  c.dataBytes = c.voxels * io_detail::diskTypeSize(format.type);
  c.headerWordBytes = doc.headerWordBytes;
  c.zlib = doc.zlib;
  if (array->tuples && static_cast<std::uint64_t>(*array->tuples) != c.voxels) {
    throw InputError(c.what + " has NumberOfTuples=" + std::to_string(*array->tuples) +
                     ", the extent has " + std::to_string(c.voxels) + " points");
  }

  Volume v;
  std::string encoding;
  if (array->format == "ascii" || array->format == "binary") {
    if (!array->hasText) throw InputError(c.what + " has no data inside it");
    if (array->format == "ascii") {
      encoding = "ascii";
      v = readAsciiArray(file, array->textBegin, array->textEnd, c, array->type);
    } else {
      encoding = "inline base64";
      const std::uint64_t chars = array->textEnd - array->textBegin;
      io_detail::SourceStream text(file, array->textBegin);
      io_detail::Base64Stream bytes(text, chars, c.what, array->textBegin);
      v = readBinaryArray(bytes, io_detail::base64DecodedBound(chars), c);
    }
  } else if (array->format == "appended") {
    if (!doc.hasAppended) {
      throw InputError(c.what + " is appended, but the file has no <AppendedData>");
    }
    if (!array->offset) throw InputError(c.what + " is appended but has no offset attribute");
    const std::uint64_t room = fileSize - std::min(fileSize, doc.appendedStart);
    if (*array->offset >= room) {
      throw InputError(c.what + " starts at appended offset " + std::to_string(*array->offset) +
                       ", but the appended data has only " + std::to_string(room) + " bytes");
    }
    const std::uint64_t start = doc.appendedStart + *array->offset;
    io_detail::SourceStream data(file, start);
    if (doc.appendedEncoding == "raw") {
      encoding = "appended raw";
      v = readBinaryArray(data, fileSize - start, c);
    } else if (doc.appendedEncoding == "base64") {
      encoding = "appended base64";
      io_detail::Base64Stream bytes(data, fileSize - start, c.what, start);
      v = readBinaryArray(bytes, io_detail::base64DecodedBound(fileSize - start), c);
    } else {
      throw InputError(p + ": AppendedData encoding '" + doc.appendedEncoding +
                       "' is not supported; expected raw or base64");
    }
  } else {
    throw InputError(c.what + " has format '" + array->format +
                     "', expected ascii, binary or appended");
  }

  try {
    v.setIndexToWorld(affine);
  } catch (const InputError& e) {
    throw InputError(p + ": ImageData Direction: " + e.what());
  }
  v.setGeometrySource(doc.hasDirection ? "VTK ImageData Direction (no patient frame: taken as RAS)"
                                       : "VTK ImageData Origin and Spacing (no Direction: "
                                         "identity, taken as RAS)");
  std::string description = "VTK ImageData " + p + " (" + io_detail::dimsString(format.dims) + " " +
                            std::string(io_detail::diskTypeName(format.type)) + ", " + encoding +
                            (doc.zlib && array->format != "ascii" ? " zlib" : "") + ", array '" +
                            array->name + "'";
  if (io_detail::isConvertedToF32(format.type)) description += ", converted to f32";
  if (format.type == DiskType::I8) description += ", widened to i16";
  v.setDescription(description + ")");
  return v;
}

}  // namespace tessera
