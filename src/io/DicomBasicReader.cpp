// The DICOM reader that needs no DCMTK (see DicomBasicReader.h): a Part-10
// parser (PS3.10 7.1; data elements PS3.5 7.1, sequences 7.5, encapsulated
// pixel data A.4), an RLE Lossless decoder (PS3.5 Annex G) and, natively,
// JPEG 2000 frames through OpenJPEG (io/Jpeg2000Frame.h), in front of the series code the DCMTK
// reader uses (io/DicomSeries.cpp).
#include "tessera/io/DicomBasicReader.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "io/DicomSeries.h"
#include "io/DicomWebInstance.h"
#ifndef __EMSCRIPTEN__
#include "io/Jpeg2000Frame.h"
#endif
#include "tessera/core/Error.h"
#include "tessera/io/DicomDecoder.h"

namespace tessera {

namespace fs = std::filesystem;
using io_detail::DicomTag;
using io_detail::FolderScan;
using io_detail::Slice;
using io_detail::StoredRange;

namespace {

constexpr std::uint32_t kUndefinedLength = 0xffffffffu;
// PackBits never expands more than 64:1: a two-byte replicate run gives at
// most 128 bytes (PS3.5 G.3.1). It bounds what an RLE frame can hold.
constexpr std::uint64_t kMaxRleRatio = 64;
// What a JPEG 2000 or HTJ2K frame is taken to expand to at most, so that a
// small file cannot declare a huge image: lossy CT and MR stay under 1:200,
// but a nearly uniform test image reaches 1:2100 (pydicom's JPEG2000.dcm:
// 512 KiB of pixels in a 250-byte codestream); 4096 leaves room for both.
constexpr std::uint64_t kMaxJpeg2000Ratio = 4096;
// No attribute read here is longer (LT holds 10240 characters).
constexpr std::uint32_t kLongestAttribute = 64 * 1024;

constexpr std::uint32_t tagKey(std::uint16_t group, std::uint16_t element) {
  return (static_cast<std::uint32_t>(group) << 16) | element;
}
constexpr std::uint32_t kItem = tagKey(0xfffe, 0xe000);
constexpr std::uint32_t kItemEnd = tagKey(0xfffe, 0xe00d);
constexpr std::uint32_t kSequenceEnd = tagKey(0xfffe, 0xe0dd);
constexpr std::uint32_t kPixelData = tagKey(0x7fe0, 0x0010);
constexpr std::uint32_t kTransferSyntaxUid = tagKey(0x0002, 0x0010);

std::string tagText(std::uint32_t key) {
  return DicomTag{static_cast<std::uint16_t>(key >> 16), static_cast<std::uint16_t>(key)}.text();
}

// How a syntax's pixel data is stored.
enum class Codec { None, Rle, Jpeg2000, Htj2k };

#ifdef __EMSCRIPTEN__
// The page has no OpenJPEG or OpenJPH (their WebAssembly builds are not
// loaded yet): JPEG 2000 and HTJ2K are refused there with the reason.
constexpr bool kJpeg2000Codecs = false;
#else
constexpr bool kJpeg2000Codecs = true;
#endif

struct TransferSyntax {
  const char* uid;
  const char* name;  // DCMTK's names, so both readers describe a file alike
  bool readable;
  bool implicitVr;
  Codec codec;
};

// The syntaxes read here, and the usual others, named in the refusal.
constexpr TransferSyntax kSyntaxes[] = {
    {"1.2.840.10008.1.2", "Little Endian Implicit", true, true, Codec::None},
    {"1.2.840.10008.1.2.1", "Little Endian Explicit", true, false, Codec::None},
    {"1.2.840.10008.1.2.5", "RLE Lossless", true, false, Codec::Rle},
    {"1.2.840.10008.1.2.2", "Big Endian Explicit", false, false, Codec::None},
    {"1.2.840.10008.1.2.1.99", "Deflated Explicit VR Little Endian", false, false, Codec::None},
    {"1.2.840.10008.1.2.4.50", "JPEG Baseline", false, false, Codec::None},
    {"1.2.840.10008.1.2.4.51", "JPEG Extended", false, false, Codec::None},
    {"1.2.840.10008.1.2.4.57", "JPEG Lossless, Non-hierarchical", false, false, Codec::None},
    {"1.2.840.10008.1.2.4.70", "JPEG Lossless, Non-hierarchical, First-Order Prediction", false,
     false, Codec::None},
    {"1.2.840.10008.1.2.4.80", "JPEG-LS Lossless", false, false, Codec::None},
    {"1.2.840.10008.1.2.4.81", "JPEG-LS Lossy (Near-lossless)", false, false, Codec::None},
    {"1.2.840.10008.1.2.4.90", "JPEG 2000 (Lossless only)", kJpeg2000Codecs, false,
     Codec::Jpeg2000},
    {"1.2.840.10008.1.2.4.91", "JPEG 2000", kJpeg2000Codecs, false, Codec::Jpeg2000},
    // HTJ2K (Part 15): an HTJ2K codestream (one with a CAP marker) goes to
    // OpenJPH behind Htj2kFrame.h's checks, whatever the file declares.
    {"1.2.840.10008.1.2.4.201", "HTJ2K (Lossless only)", kJpeg2000Codecs, false, Codec::Htj2k},
    {"1.2.840.10008.1.2.4.202", "HTJ2K with RPCL Options (Lossless only)", kJpeg2000Codecs, false,
     Codec::Htj2k},
    {"1.2.840.10008.1.2.4.203", "HTJ2K", kJpeg2000Codecs, false, Codec::Htj2k},
};

// What this build reads, for messages and the decoder table.
constexpr const char* kReadsText =
    kJpeg2000Codecs ? "implicit and explicit VR little endian, RLE Lossless, JPEG 2000 and HTJ2K"
                    : "implicit and explicit VR little endian and RLE Lossless";

bool isLongVr(std::string_view vr) {
  static constexpr std::array<std::string_view, 13> kLong = {
      "OB", "OD", "OF", "OL", "OV", "OW", "SQ", "UC", "UN", "UR", "UT", "SV", "UV"};
  return std::find(kLong.begin(), kLong.end(), vr) != kLong.end();
}

bool isKnownVr(std::string_view vr) {
  static constexpr std::array<std::string_view, 21> kShort = {
      "AE", "AS", "AT", "CS", "DA", "DS", "DT", "FL", "FD", "IS", "LO",
      "LT", "PN", "SH", "SL", "SS", "ST", "TM", "UI", "UL", "US"};
  return isLongVr(vr) || std::find(kShort.begin(), kShort.end(), vr) != kShort.end();
}

// Printable text for a message, however odd the bytes.
std::string printable(std::string_view s) {
  std::string out;
  for (char c : s.substr(0, 80)) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7f) {
      out += c;
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", u);
      out += buf;
    }
  }
  return s.size() > 80 ? out + "..." : out;
}

std::string trimmed(std::string_view s) {
  const auto b = s.find_first_not_of(std::string_view(" \0", 2));
  const auto e = s.find_last_not_of(std::string_view(" \0", 2));
  return b == std::string_view::npos ? std::string() : std::string(s.substr(b, e - b + 1));
}

struct Element {
  std::uint64_t offset = 0;  // of the value
  std::uint32_t length = 0;
  std::array<char, 2> vr{};  // {0, 0} in implicit VR
};

// One item of a sequence that is read (the functional groups of
// multi-frame objects): its elements and the items of its sequences.
struct ItemNode {
  std::map<std::uint32_t, Element> elements;
  std::map<std::uint32_t, std::vector<ItemNode>> sequences;
};

// The top-level sequences whose items are kept; every other sequence is
// skipped (its items walked only as far as their lengths need).
bool keepsItems(std::uint32_t tag) {
  using namespace io_detail;
  for (DicomTag t : {kTagSharedFunctionalGroups, kTagPerFrameFunctionalGroups,
                     kTagDetectorInformationSequence}) {
    if (tag == tagKey(t.group, t.element)) return true;
  }
  return false;
}

// An element's value as the shared series code reads it (see
// DicomAttributes in io/DicomSeries.h).
std::optional<std::string> elementText(const Element* e, const std::uint8_t* bytes) {
  if (e == nullptr || e->length > kLongestAttribute) return std::nullopt;
  return trimmed(std::string_view(reinterpret_cast<const char*>(bytes + e->offset), e->length));
}

std::optional<int> elementUint16(const Element* e, const std::uint8_t* bytes) {
  if (e == nullptr) return std::nullopt;
  const std::string_view vr(e->vr.data(), 2);
  // US may hold several values (the first is read); implicit VR and UN
  // (PS3.5 6.2.2) must be one value.
  const bool us = vr == "US" && e->length >= 2 && e->length % 2 == 0;
  if (!us && !(vr != "US" && (e->vr[0] == 0 || vr == "UN") && e->length == 2)) {
    return std::nullopt;
  }
  return bytes[e->offset] | (bytes[e->offset + 1] << 8);
}

std::optional<std::uint32_t> elementUint32(const Element* e, const std::uint8_t* bytes) {
  if (e == nullptr) return std::nullopt;
  const std::string_view vr(e->vr.data(), 2);
  const bool ul = vr == "UL" && e->length >= 4 && e->length % 4 == 0;
  if (!ul && !(vr != "UL" && (e->vr[0] == 0 || vr == "UN") && e->length == 4)) {
    return std::nullopt;
  }
  const std::uint8_t* p = bytes + e->offset;
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

const Element* findIn(const std::map<std::uint32_t, Element>& elements, DicomTag tag) {
  const auto it = elements.find(tagKey(tag.group, tag.element));
  return it == elements.end() ? nullptr : &it->second;
}

// A kept item as attributes; the file's bytes outlive it.
class ItemAttributes final : public io_detail::DicomAttributes {
 public:
  ItemAttributes(const ItemNode& node, const std::uint8_t* bytes) : node_(node), bytes_(bytes) {}
  std::optional<std::string> text(DicomTag tag) const override {
    return elementText(findIn(node_.elements, tag), bytes_);
  }
  std::optional<int> uint16(DicomTag tag) const override {
    return elementUint16(findIn(node_.elements, tag), bytes_);
  }
  std::optional<std::uint32_t> uint32(DicomTag tag) const override {
    return elementUint32(findIn(node_.elements, tag), bytes_);
  }
  std::vector<std::unique_ptr<io_detail::DicomAttributes>> items(DicomTag tag) const override {
    return itemsOf(node_.sequences, tag, bytes_);
  }

  static std::vector<std::unique_ptr<io_detail::DicomAttributes>> itemsOf(
      const std::map<std::uint32_t, std::vector<ItemNode>>& sequences, DicomTag tag,
      const std::uint8_t* bytes) {
    std::vector<std::unique_ptr<io_detail::DicomAttributes>> out;
    const auto it = sequences.find(tagKey(tag.group, tag.element));
    if (it == sequences.end()) return out;
    for (const ItemNode& n : it->second) out.push_back(std::make_unique<ItemAttributes>(n, bytes));
    return out;
  }

 private:
  const ItemNode& node_;
  const std::uint8_t* bytes_;
};

// One Part-10 file, parsed from its bytes (read whole: the file's size is
// what justifies the allocation). Keeps the top-level elements found before
// a failure, so that an unreadable file still tells its series and position.
class Part10File final : public io_detail::DicomAttributes {
 public:
  explicit Part10File(const ByteSource& source) : name_(source.name()) {
    bytes_.resize(static_cast<std::size_t>(source.size()));
    const std::size_t got =
        source.read(0, reinterpret_cast<std::byte*>(bytes_.data()), bytes_.size());
    bytes_.resize(got);
  }

  // PS3.10 7.1: a 128-byte preamble, then "DICM".
  bool isPart10() const {
    return bytes_.size() >= 132 && std::memcmp(bytes_.data() + 128, "DICM", 4) == 0;
  }

  // Parses the file meta information and the dataset up to Pixel Data;
  // InputError naming the file for anything malformed or unsupported.
  void parse() {
    parseMeta();
    const TransferSyntax* ts = syntax_;
    if (ts == nullptr || !ts->readable) {
      // JPEG and friends keep an explicit little-endian dataset: read it for
      // the series and position before refusing the pixels.
      if (ts != nullptr && std::string_view(ts->uid).starts_with("1.2.840.10008.1.2.4.")) {
        encapsulated_ = true;
        try {
          parseDataset(false);
        } catch (const InputError&) {
          // the syntax is the reason given
        }
      }
      throw InputError(unsupportedSyntaxMessage());
    }
    encapsulated_ = ts->codec != Codec::None;
    parseDataset(ts->implicitVr);
  }

  // For one frame's bytes only (io/DicomWebInstance.h): every syntax whose
  // dataset is little endian, whatever this build's codecs decode.
  void parseAnyLittleEndian() {
    parseMeta();
    const TransferSyntax* ts = syntax_;
    const bool compressed =
        ts != nullptr && std::string_view(ts->uid).starts_with("1.2.840.10008.1.2.4.");
    if (ts == nullptr || (!ts->readable && !compressed))
      throw InputError(unsupportedSyntaxMessage());
    encapsulated_ = compressed || ts->codec != Codec::None;
    parseDataset(ts->implicitVr);
  }
  const std::string& syntaxUid() const { return syntaxUid_; }

  const std::string& name() const { return name_; }
  std::string syntaxText() const {
    return std::string(syntax_ != nullptr ? syntax_->name : "unknown") + " (" + syntaxUid_ + ")";
  }
  bool encapsulated() const { return encapsulated_; }
  Codec codec() const { return syntax_ != nullptr ? syntax_->codec : Codec::None; }
  bool hasPixelData() const { return pixelData_.has_value() || !fragments_.empty(); }
  const std::optional<Element>& pixelData() const { return pixelData_; }
  const std::vector<Element>& fragments() const { return fragments_; }
  const std::uint8_t* at(std::uint64_t offset) const { return bytes_.data() + offset; }

  std::optional<std::string> text(DicomTag tag) const override {
    return elementText(find(tag), bytes_.data());
  }
  std::optional<int> uint16(DicomTag tag) const override {
    return elementUint16(find(tag), bytes_.data());
  }
  std::optional<std::uint32_t> uint32(DicomTag tag) const override {
    return elementUint32(find(tag), bytes_.data());
  }
  std::vector<std::unique_ptr<io_detail::DicomAttributes>> items(DicomTag tag) const override {
    return ItemAttributes::itemsOf(sequences_, tag, bytes_.data());
  }
  // Fragments' item offsets from the first fragment's item, as the Basic
  // Offset Table counts them (PS3.5 A.4), and the table itself.
  const std::vector<std::uint32_t>& offsetTable() const { return offsetTable_; }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw InputError(name_ + ": " + what); }

  const Element* find(DicomTag tag) const { return findIn(elements_, tag); }

  std::uint16_t u16(std::uint64_t at) const {
    return static_cast<std::uint16_t>(bytes_[at] | (bytes_[at + 1] << 8));
  }
  std::uint32_t u32(std::uint64_t at) const {
    return static_cast<std::uint32_t>(bytes_[at]) |
           (static_cast<std::uint32_t>(bytes_[at + 1]) << 8) |
           (static_cast<std::uint32_t>(bytes_[at + 2]) << 16) |
           (static_cast<std::uint32_t>(bytes_[at + 3]) << 24);
  }

  std::uint64_t size() const { return bytes_.size(); }

  void need(std::uint64_t pos, std::uint64_t n, const std::string& what) const {
    if (pos + n > size()) {
      fail(what + " at offset " + std::to_string(pos) + " needs " + std::to_string(n) +
           " bytes, but the file ends at " + std::to_string(size()) + " (truncated)");
    }
  }

  struct Header {
    std::uint32_t tag = 0;
    std::array<char, 2> vr{};
    std::uint32_t length = 0;
    std::uint64_t valueOffset = 0;
  };

  // An element's tag, VR and length at `pos` (PS3.5 7.1.1-7.1.3); items and
  // delimiters (group FFFE) never have a VR.
  Header header(std::uint64_t pos, bool implicitVr) const {
    need(pos, 8, "an element");
    Header h;
    h.tag = tagKey(u16(pos), u16(pos + 2));
    if (implicitVr || (h.tag >> 16) == 0xfffe) {
      h.length = u32(pos + 4);
      h.valueOffset = pos + 8;
      return h;
    }
    h.vr = {static_cast<char>(bytes_[pos + 4]), static_cast<char>(bytes_[pos + 5])};
    const std::string_view vr(h.vr.data(), 2);
    if (!isKnownVr(vr)) {
      fail("element " + tagText(h.tag) + " at offset " + std::to_string(pos) + " has VR '" +
           printable(vr) + "', which is no DICOM VR (corrupt file, or not explicit VR)");
    }
    if (isLongVr(vr)) {
      need(pos, 12, "element " + tagText(h.tag));
      h.length = u32(pos + 8);
      h.valueOffset = pos + 12;
    } else {
      h.length = u16(pos + 6);
      h.valueOffset = pos + 8;
    }
    return h;
  }

  void needValue(const Header& h, std::uint64_t end) const {
    if (h.valueOffset + h.length > end) {
      fail("element " + tagText(h.tag) + " at offset " + std::to_string(h.valueOffset - 8) +
           " declares " + std::to_string(h.length) + " bytes, but only " +
           std::to_string(end > h.valueOffset ? end - h.valueOffset : 0) +
           " remain (truncated or corrupt)");
    }
  }

  // PS3.10 7.1: group 0002, always explicit VR little endian.
  void parseMeta() {
    std::uint64_t pos = 132;
    while (pos + 4 <= size() && u16(pos) == 0x0002) {
      const Header h = header(pos, false);
      if (h.length == kUndefinedLength) {
        fail("file meta element " + tagText(h.tag) + " has an undefined length");
      }
      needValue(h, size());
      if (h.tag == kTransferSyntaxUid) {
        if (h.length > 64) {
          fail("Transfer Syntax UID (0002,0010) is " + std::to_string(h.length) +
               " bytes long; a UID has at most 64");
        }
        syntaxUid_ =
            trimmed(std::string_view(reinterpret_cast<const char*>(at(h.valueOffset)), h.length));
      }
      pos = h.valueOffset + h.length;
    }
    if (syntaxUid_.empty()) {
      fail(
          "the file meta information has no Transfer Syntax UID (0002,0010) (not a valid "
          "Part-10 file)");
    }
    for (const TransferSyntax& ts : kSyntaxes) {
      if (syntaxUid_ == ts.uid) syntax_ = &ts;
    }
    datasetStart_ = pos;
  }

  std::string unsupportedSyntaxMessage() const {
    const std::string what = syntax_ != nullptr
                                 ? std::string(syntax_->name) + " (" + syntaxUid_ + ")"
                                 : "'" + printable(syntaxUid_) + "' (unknown)";
    return name_ + ": transfer syntax " + what + " is not read by this DICOM reader (it reads " +
           kReadsText +
           "); open the folder with the native tessera (DCMTK), or convert it, "
           "e.g. `gdcmconv --raw " +
           name_ + " out.dcm`";
  }

  void parseDataset(bool implicitVr) {
    std::uint64_t pos = datasetStart_;
    while (pos < size()) {
      const Header h = header(pos, implicitVr);
      if ((h.tag >> 16) == 0xfffe) {
        fail("item or delimiter " + tagText(h.tag) + " at offset " + std::to_string(pos) +
             " outside any sequence (corrupt file)");
      }
      if (h.tag == kPixelData) {
        parsePixelData(h);
        return;  // nothing after the pixels is read
      }
      std::vector<ItemNode>* keep = keepsItems(h.tag) ? &sequences_[h.tag] : nullptr;
      pos = skipValue(h, implicitVr, 0, size(), keep);
      if ((h.tag >> 16) != 0x0002) elements_[h.tag] = {h.valueOffset, h.length, h.vr};
    }
  }

  // Where the element after `h` begins; sequences (and undefined-length UN,
  // PS3.5 6.2.2, which holds implicit VR) are walked item by item. With
  // `keep`, a sequence's items are read into it (also those of defined
  // length, and a sequence of defined length: VR SQ, or any element in
  // implicit VR that the walk finds items in).
  std::uint64_t skipValue(const Header& h, bool implicitVr, int depth, std::uint64_t end,
                          std::vector<ItemNode>* keep = nullptr) {
    const std::string_view vr(h.vr.data(), 2);
    if (h.length != kUndefinedLength) {
      needValue(h, end);
      if (keep != nullptr && (vr == "SQ" || (implicitVr && looksLikeItem(h)))) {
        readDefinedSequence(h, implicitVr, depth + 1, *keep);
      }
      return h.valueOffset + h.length;
    }
    if (!implicitVr && vr != "SQ" && vr != "UN") {
      fail("element " + tagText(h.tag) + " at offset " + std::to_string(h.valueOffset - 12) +
           " has an undefined length but VR " + printable(vr) +
           " (only sequences, UN and encapsulated Pixel Data may)");
    }
    return skipSequence(h, implicitVr || vr == "UN", depth + 1, end, keep);
  }

  // Whether an implicit-VR value of defined length holds items (a sequence).
  bool looksLikeItem(const Header& h) const {
    return h.length >= 8 && h.valueOffset + 8 <= size() &&
           tagKey(u16(h.valueOffset), u16(h.valueOffset + 2)) == kItem;
  }

  // A sequence of defined length: items up to its end.
  void readDefinedSequence(const Header& seq, bool implicitVr, int depth,
                           std::vector<ItemNode>& keep) {
    if (depth > io_detail::kMaxSequenceNesting) {
      throw InputError(io_detail::sequencesTooDeepMessage(name_));
    }
    const std::uint64_t end = seq.valueOffset + seq.length;
    std::uint64_t pos = seq.valueOffset;
    while (pos < end) {
      const Header item = header(pos, true);
      if (item.tag != kItem) {
        fail("sequence " + tagText(seq.tag) + " holds " + tagText(item.tag) + " at offset " +
             std::to_string(pos) + " where an item (FFFE,E000) belongs (corrupt file)");
      }
      keep.emplace_back();
      if (item.length == kUndefinedLength) {
        pos = readItem(item.valueOffset, end, true, implicitVr, depth, &keep.back());
      } else {
        needValue(item, end);
        readItem(item.valueOffset, item.valueOffset + item.length, false, implicitVr, depth,
                 &keep.back());
        pos = item.valueOffset + item.length;
      }
    }
  }

  // The elements of one item into `node`: up to `end` for an item of defined
  // length, up to its delimiter otherwise. Returns where the item ends.
  std::uint64_t readItem(std::uint64_t pos, std::uint64_t end, bool delimited, bool implicitVr,
                         int depth, ItemNode* node) {
    for (;;) {
      if (!delimited && pos >= end) return pos;
      if (pos >= end) {
        fail(
            "an item of undefined length has no Item Delimitation Item (FFFE,E00D) before the "
            "end (truncated)");
      }
      const Header h = header(pos, implicitVr);
      if (delimited && h.tag == kItemEnd) return h.valueOffset;
      if ((h.tag >> 16) == 0xfffe) {
        fail(tagText(h.tag) + " at offset " + std::to_string(pos) +
             " inside an item, where an element or (FFFE,E00D) belongs (corrupt file)");
      }
      std::vector<ItemNode>* keep = node != nullptr ? &node->sequences[h.tag] : nullptr;
      pos = skipValue(h, implicitVr, depth, end, keep);
      if (node != nullptr) {
        node->elements[h.tag] = {h.valueOffset, h.length, h.vr};
        if (keep->empty()) node->sequences.erase(h.tag);
      }
    }
  }

  std::uint64_t skipSequence(const Header& seq, bool implicitVr, int depth, std::uint64_t end,
                             std::vector<ItemNode>* keep = nullptr) {
    // The walk recurses once per level: bounded like DCMTK's reader.
    if (depth > io_detail::kMaxSequenceNesting) {
      throw InputError(io_detail::sequencesTooDeepMessage(name_));
    }
    std::uint64_t pos = seq.valueOffset;
    for (;;) {
      if (pos >= end) {
        fail("sequence " + tagText(seq.tag) + " at offset " + std::to_string(seq.valueOffset) +
             " has no Sequence Delimitation Item (FFFE,E0DD) before the end (truncated)");
      }
      const Header item = header(pos, true);
      if (item.tag == kSequenceEnd) return item.valueOffset;
      if (item.tag != kItem) {
        fail("sequence " + tagText(seq.tag) + " holds " + tagText(item.tag) + " at offset " +
             std::to_string(pos) + " where an item (FFFE,E000) belongs (corrupt file)");
      }
      if (keep != nullptr) {
        keep->emplace_back();
        if (item.length == kUndefinedLength) {
          pos = readItem(item.valueOffset, end, true, implicitVr, depth, &keep->back());
        } else {
          needValue(item, end);
          readItem(item.valueOffset, item.valueOffset + item.length, false, implicitVr, depth,
                   &keep->back());
          pos = item.valueOffset + item.length;
        }
        continue;
      }
      if (item.length != kUndefinedLength) {
        needValue(item, end);
        pos = item.valueOffset + item.length;
        continue;
      }
      pos = skipItem(item.valueOffset, implicitVr, depth, end);
    }
  }

  // The elements of an undefined-length item, up to its delimiter.
  std::uint64_t skipItem(std::uint64_t pos, bool implicitVr, int depth, std::uint64_t end) {
    for (;;) {
      if (pos >= end) {
        fail(
            "an item of undefined length has no Item Delimitation Item (FFFE,E00D) before the "
            "end (truncated)");
      }
      const Header h = header(pos, implicitVr);
      if (h.tag == kItemEnd) return h.valueOffset;
      if ((h.tag >> 16) == 0xfffe) {
        fail(tagText(h.tag) + " at offset " + std::to_string(pos) +
             " inside an item, where an element or (FFFE,E00D) belongs (corrupt file)");
      }
      pos = skipValue(h, implicitVr, depth, end);
    }
  }

  // Native: one value. Encapsulated (PS3.5 A.4): items, the first the basic
  // offset table, then the fragments, up to the sequence delimiter.
  void parsePixelData(const Header& h) {
    if (!encapsulated_) {
      if (h.length == kUndefinedLength) {
        fail("Pixel Data (7fe0,0010) has an undefined length, but transfer syntax " + syntaxText() +
             " stores pixels natively (corrupt file)");
      }
      needValue(h, size());
      pixelData_ = Element{h.valueOffset, h.length, h.vr};
      return;
    }
    if (h.length != kUndefinedLength) {
      fail("Pixel Data (7fe0,0010) has a defined length (" + std::to_string(h.length) +
           " bytes), but transfer syntax " + syntaxText() +
           " encapsulates it (PS3.5 A.4: undefined length)");
    }
    std::uint64_t pos = h.valueOffset;
    bool offsetTable = true;
    for (;;) {
      if (pos >= size()) {
        fail(
            "encapsulated Pixel Data has no Sequence Delimitation Item (FFFE,E0DD) before the "
            "end (truncated)");
      }
      const Header item = header(pos, true);
      if (item.tag == kSequenceEnd) break;
      if (item.tag != kItem || item.length == kUndefinedLength) {
        fail("encapsulated Pixel Data holds " + tagText(item.tag) + " at offset " +
             std::to_string(pos) + " where an item of defined length belongs (corrupt file)");
      }
      needValue(item, size());
      if (offsetTable) {
        for (std::uint32_t k = 0; k + 4 <= item.length; k += 4) {
          offsetTable_.push_back(u32(item.valueOffset + k));
        }
      } else {
        fragments_.push_back({item.valueOffset, item.length, {}});
      }
      offsetTable = false;
      pos = item.valueOffset + item.length;
    }
    if (fragments_.empty()) fail("encapsulated Pixel Data has no fragment (no image)");
  }

  std::string name_;
  std::vector<std::uint8_t> bytes_;
  std::string syntaxUid_;
  const TransferSyntax* syntax_ = nullptr;
  std::uint64_t datasetStart_ = 0;
  bool encapsulated_ = false;
  std::map<std::uint32_t, Element> elements_;
  std::map<std::uint32_t, std::vector<ItemNode>> sequences_;
  std::vector<std::uint32_t> offsetTable_;
  std::optional<Element> pixelData_;
  std::vector<Element> fragments_;
};

// What the shared series code needs of a parsed file: a slice per frame.
std::vector<Slice> slicesOf(const Part10File& f) {
  Slice s = io_detail::sliceHeader(f.name(), f);
  s.transferSyntax = f.syntaxText();
  if (f.pixelData()) s.pixelBytes = f.pixelData()->length;
  if (f.encapsulated()) {
    std::uint64_t compressed = 0;
    for (const Element& e : f.fragments()) compressed += e.length;
    const bool rle = f.codec() == Codec::Rle;
    s.decodedBytesBound = compressed * (rle ? kMaxRleRatio : kMaxJpeg2000Ratio);
    s.compression = rle ? "RLE Lossless" : f.syntaxText();
    s.fragments = f.fragments().size();
  }
  return io_detail::framesOf(std::move(s), f);
}

// One PackBits segment (PS3.5 G.3.1) into `out`, which it must fill exactly.
void unpackSegment(const std::uint8_t* in, std::size_t inSize, std::uint8_t* out,
                   std::size_t outSize, const std::string& what) {
  std::size_t i = 0;
  std::size_t o = 0;
  while (o < outSize) {
    if (i >= inSize) {
      throw InputError(what + " ends after " + std::to_string(o) + " of " +
                       std::to_string(outSize) + " bytes (truncated or corrupt)");
    }
    const int n = static_cast<std::int8_t>(in[i++]);
    if (n == -128) continue;  // no operation
    const std::size_t count =
        n >= 0 ? static_cast<std::size_t>(n) + 1 : static_cast<std::size_t>(1 - n);
    if (o + count > outSize) {
      throw InputError(what + " decodes to more than the " + std::to_string(outSize) +
                       " bytes of the image (corrupt)");
    }
    if (n >= 0) {
      if (i + count > inSize) {
        throw InputError(what + ": a literal run of " + std::to_string(count) +
                         " bytes goes past its end (truncated or corrupt)");
      }
      std::memcpy(out + o, in + i, count);
      i += count;
    } else {
      if (i >= inSize) throw InputError(what + ": a replicate run has no byte to repeat");
      std::memset(out + o, in[i++], count);
    }
    o += count;
  }
}

// An RLE Lossless frame (PS3.5 G.4, G.5): a 64-byte header with the segment
// count and offsets; one segment per byte of a sample, most significant
// first. Returns the samples in host order (8- or 16-bit).
std::vector<std::uint8_t> decodeRle(const Slice& s, const std::vector<std::uint8_t>& frame) {
  const std::string f = io_detail::sliceName(s);
  const auto u32 = [&](std::size_t at) {
    return static_cast<std::uint32_t>(frame[at]) |
           (static_cast<std::uint32_t>(frame[at + 1]) << 8) |
           (static_cast<std::uint32_t>(frame[at + 2]) << 16) |
           (static_cast<std::uint32_t>(frame[at + 3]) << 24);
  };
  if (frame.size() < 64) {
    throw InputError(f + ": RLE data has " + std::to_string(frame.size()) +
                     " bytes, less than its 64-byte header (truncated)");
  }
  const std::size_t bytesPerSample = static_cast<std::size_t>(s.bitsAllocated / 8);
  const std::uint32_t segments = u32(0);
  if (segments != bytesPerSample) {
    throw InputError(f + ": RLE header says " + std::to_string(segments) + " segments, but " +
                     std::to_string(s.bitsAllocated) + "-bit single-sample pixels need " +
                     std::to_string(bytesPerSample) + " (corrupt)");
  }
  const std::size_t n = static_cast<std::size_t>(s.rows) * static_cast<std::size_t>(s.columns);
  std::vector<std::uint8_t> planes(n * bytesPerSample);
  for (std::size_t k = 0; k < segments; ++k) {
    const std::uint32_t begin = u32(4 + 4 * k);
    const std::uint64_t end = k + 1 < segments ? u32(8 + 4 * k) : frame.size();
    if (begin < 64 || begin > end || end > frame.size()) {
      throw InputError(f + ": RLE segment " + std::to_string(k + 1) + " spans bytes " +
                       std::to_string(begin) + " to " + std::to_string(end) + " of " +
                       std::to_string(frame.size()) + " (corrupt offsets)");
    }
    unpackSegment(frame.data() + begin, static_cast<std::size_t>(end - begin),
                  planes.data() + k * n, n, f + ": RLE segment " + std::to_string(k + 1));
  }
  if (bytesPerSample == 1) return planes;
  std::vector<std::uint8_t> out(n * 2);
  for (std::size_t i = 0; i < n; ++i) {
    const auto v = static_cast<std::uint16_t>((planes[i] << 8) | planes[n + i]);
    std::memcpy(out.data() + 2 * i, &v, 2);
  }
  return out;
}

// One encapsulated frame's samples (8- or 16-bit, host order).
std::vector<std::uint8_t> decodeFrame(const Slice& s, Codec codec,
                                      const std::vector<std::uint8_t>& frame) {
#ifndef __EMSCRIPTEN__
  if (codec == Codec::Jpeg2000 || codec == Codec::Htj2k) {
    const io_detail::FrameShape shape{.rows = s.rows,
                                      .columns = s.columns,
                                      .bitsAllocated = s.bitsAllocated,
                                      .bitsStored = s.bitsStored,
                                      .samplesPerPixel = s.samplesPerPixel,
                                      .isSigned = s.isSigned};
    return codec == Codec::Htj2k
               ? io_detail::decodeHtj2kSyntaxFrame(frame, shape, io_detail::sliceName(s))
               : io_detail::decodeJpeg2000Frame(frame, shape, io_detail::sliceName(s));
  }
#endif
  if (codec != Codec::Rle) throw InputError(s.file.string() + ": no decoder for its pixel data");
  return decodeRle(s, frame);
}

using Opener = std::function<std::unique_ptr<ByteSource>(const fs::path&)>;

// The fragments of frame `s.frame` (PS3.5 A.4): all of them for a file of
// one frame; one each when there are as many fragments as frames; else as
// the Basic Offset Table divides them.
std::vector<std::uint8_t> frameCodestream(const Part10File& f, const Slice& s) {
  const std::vector<Element>& fragments = f.fragments();
  std::vector<std::uint8_t> out;
  const auto append = [&](const Element& e) {
    out.insert(out.end(), f.at(e.offset), f.at(e.offset) + e.length);
  };
  if (s.frames <= 1) {
    for (const Element& e : fragments) append(e);
    return out;
  }
  const auto k = static_cast<std::size_t>(s.frame);
  if (fragments.size() == static_cast<std::size_t>(s.frames)) {
    append(fragments[k]);
    return out;
  }
  const std::vector<std::uint32_t>& table = f.offsetTable();
  if (table.size() != static_cast<std::size_t>(s.frames)) {
    throw InputError(io_detail::sliceName(s) + ": " + std::to_string(fragments.size()) +
                     " fragments for " + std::to_string(s.frames) + " frames, and the Basic " +
                     "Offset Table has " + std::to_string(table.size()) +
                     " entries, so the frames cannot be told apart");
  }
  // Offsets count from the first fragment's item tag, 8 bytes before its value.
  const std::uint64_t first = fragments.front().offset - 8;
  const std::uint64_t begin = table[k];
  const std::uint64_t end = k + 1 < table.size() ? table[k + 1] : ~std::uint64_t{0};
  for (const Element& e : fragments) {
    const std::uint64_t at = e.offset - 8 - first;
    if (at >= begin && at < end) append(e);
  }
  if (out.empty()) {
    throw InputError(io_detail::sliceName(s) + ": the Basic Offset Table puts frame " +
                     std::to_string(k + 1) + " at byte " + std::to_string(begin) +
                     ", where no fragment begins (corrupt offset table)");
  }
  return out;
}

// A parsed file kept while its frames are decoded.
struct ParsedFile {
  fs::path file;
  std::unique_ptr<Part10File> parsed;
};

// Decodes a slice's pixels. Only the headers of every file are kept while
// the series is assembled; a file is parsed again for its pixels, once for
// all its frames (the file last parsed is kept).
io_detail::PixelDecoder pixelDecoder(const Opener& open) {
  auto last = std::make_shared<ParsedFile>();
  return [open, last](const Slice& s, Volume& stored, int z) -> StoredRange {
    if (!last->parsed || last->file != s.file) {
      last->parsed.reset();
      auto parsed = std::make_unique<Part10File>(*open(s.file));
      parsed->parse();
      last->parsed = std::move(parsed);
      last->file = s.file;
    }
    const Part10File& f = *last->parsed;
    if (!f.hasPixelData()) throw InputError(s.file.string() + ": no Pixel Data (7fe0,0010)");
    if (f.encapsulated()) {
      const std::vector<std::uint8_t> samples = decodeFrame(s, f.codec(), frameCodestream(f, s));
      return io_detail::storePixels(s, samples.data(), samples.size(), stored, z);
    }
    const Element& e = *f.pixelData();
    const auto [begin, length] = io_detail::frameRange(s, e.length);
    const std::uint8_t* p = f.at(e.offset + begin);
    if (s.bitsAllocated == 8) return io_detail::storePixels(s, p, length, stored, z);
    // Little endian on disk, host order for storePixels.
    std::vector<std::uint16_t> words(length / 2);
    for (std::size_t i = 0; i < words.size(); ++i) {
      words[i] = static_cast<std::uint16_t>(p[2 * i] | (p[2 * i + 1] << 8));
    }
    return io_detail::storePixels(s, words.data(), length, stored, z);
  };
}

// Adds one file to a scan. `mustBeImage`: a file named on its own, whose
// problems are errors rather than notes.
void addFile(const ByteSource& source, bool mustBeImage, FolderScan& scan) {
  Part10File f(source);
  if (!f.isPart10()) {
    if (mustBeImage) {
      throw InputError(source.name() +
                       ": not a DICOM Part-10 file (no 'DICM' marker at byte 128); this reader "
                       "reads Part-10 files only");
    }
    ++scan.nonDicomFiles;
    return;
  }
  try {
    f.parse();
  } catch (const InputError& e) {
    if (mustBeImage) throw;
    scan.unreadable.push_back(io_detail::unreadableFile(source.name(), e.what(), f));
    return;
  }
  if (!f.hasPixelData()) {
    if (mustBeImage) {
      throw InputError(source.name() + ": a DICOM object without Pixel Data (7fe0,0010) (" +
                       f.text(io_detail::kTagModality).value_or("") + "); not an image");
    }
    ++scan.nonImageObjects;
    return;
  }
  for (auto& frame : slicesOf(f)) scan.slices.push_back(std::move(frame));
}

std::unique_ptr<ByteSource> openFile(const fs::path& p) {
  return std::make_unique<FileSource>(p);
}

void addFileOnDisk(const fs::path& file, bool mustBeImage, FolderScan& scan) {
  addFile(FileSource(file), mustBeImage, scan);
}

}  // namespace

Volume readDicomSeriesBasic(const fs::path& folderOrFile, const std::string& seriesUid) {
  return io_detail::readFolderOrFile(folderOrFile, seriesUid, addFileOnDisk,
                                     pixelDecoder(openFile));
}

Volume readDicomFilesBasic(const std::vector<fs::path>& files, const std::string& seriesUid) {
  if (files.empty()) throw InputError("readDicomFiles: no files given");
  FolderScan scan;
  scan.where = "the " + std::to_string(files.size()) + " files given";
  for (const auto& f : files) addFile(FileSource(f), true, scan);
  return io_detail::readSeries(std::move(scan), seriesUid, files.front().string(),
                               pixelDecoder(openFile));
}

Volume readDicomSeriesBasic(const ByteSource& named, const FileSet& files,
                            const std::string& seriesUid) {
  FolderScan own;  // its own errors first
  addFile(named, true, own);
  const std::vector<std::string> names = files.filesBeside(named);
  FolderScan scan;
  scan.where = "the " + std::to_string(names.size()) + " files opened together";
  for (const auto& n : names) addFile(*files.open(n), false, scan);
  const Opener open = [&files](const fs::path& p) { return files.open(p.string()); };
  return io_detail::readSeries(std::move(scan), seriesUid, named.name(), pixelDecoder(open),
                               named.name());
}

std::vector<DicomSeriesInfo> listDicomSeriesBasic(const fs::path& folder) {
  return io_detail::listFolderSeries(folder, addFileOnDisk);
}

std::vector<DicomSeriesInfo> listDicomSeriesBasic(const ByteSource& named, const FileSet& files) {
  FolderScan scan;  // filesBeside holds `named` too
  for (const auto& n : files.filesBeside(named)) addFile(*files.open(n), false, scan);
  return io_detail::listSeries(std::move(scan));
}

namespace {
// The reader without DCMTK behind the DicomDecoder interface: the syntaxes
// marked readable in kSyntaxes, from files on disk or in memory.
class BasicDicomDecoder final : public DicomDecoder {
 public:
  std::string name() const override { return "basic"; }
  bool canDecode(std::string_view uid) const override {
    return std::any_of(std::begin(kSyntaxes), std::end(kSyntaxes),
                       [&](const TransferSyntax& ts) { return ts.readable && uid == ts.uid; });
  }
  bool canRead(const FileSet&) const override { return true; }
  std::string decodes() const override {
    return kJpeg2000Codecs ? "uncompressed little endian, RLE, JPEG 2000, HTJ2K"
                           : "uncompressed little endian, RLE";
  }
  Volume read(const ByteSource& named, const FileSet& files,
              const std::string& seriesUid) const override {
    return readDicomSeriesBasic(named, files, seriesUid);
  }
  Volume readFolder(const fs::path& folderOrFile, const std::string& seriesUid) const override {
    return readDicomSeriesBasic(folderOrFile, seriesUid);
  }
};
}  // namespace

io_detail::InstanceFrame io_detail::instanceFrame(const ByteSource& file, const Slice& s) {
  Part10File f(file);
  if (!f.isPart10()) {
    throw InputError(file.name() + ": not a DICOM Part-10 file (no 'DICM' marker at byte 128)");
  }
  f.parseAnyLittleEndian();
  if (!f.hasPixelData()) throw InputError(file.name() + ": no Pixel Data (7fe0,0010)");
  InstanceFrame out{f.syntaxUid(), {}};
  if (f.encapsulated()) {
    const std::vector<std::uint8_t> c = frameCodestream(f, s);
    out.bytes.resize(c.size());
    if (!c.empty()) std::memcpy(out.bytes.data(), c.data(), c.size());
    return out;
  }
  const Element& e = *f.pixelData();
  const auto [begin, length] = io_detail::frameRange(s, e.length);
  out.bytes.resize(length);
  if (length > 0) std::memcpy(out.bytes.data(), f.at(e.offset + begin), length);
  return out;
}

const DicomDecoder& basicDicomDecoder() {
  static const BasicDicomDecoder decoder;
  return decoder;
}

}  // namespace tessera
