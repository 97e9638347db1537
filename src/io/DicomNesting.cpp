// The sequence-depth walk DCMTK's reader is guarded by (see DicomNesting.h).
// Structure from PS3.5 7.1 (element headers), 7.5 (sequences and items,
// defined and undefined lengths), 6.2.2 (UN of undefined length holds
// implicit VR little endian), A.4 (encapsulated Pixel Data) and PS3.10 7.1
// (preamble and file meta information); where DCMTK 3.6.7 departs from the
// standard or guesses, the walk does what DCMTK does (dcitem.cc,
// dcsequen.cc, dcmetinf.cc), or, where it cannot know, counts the deeper way.
#include "io/DicomNesting.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "io/DicomSeries.h"
#include "tessera/core/Error.h"

#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcistrmz.h>
#include <dcmtk/dcmdata/dcobject.h>
#include <dcmtk/dcmdata/dctag.h>
#include <dcmtk/dcmdata/dcvr.h>
#include <dcmtk/dcmdata/dcxfer.h>

namespace tessera::io_detail {

namespace fs = std::filesystem;

namespace {

constexpr std::uint32_t kUndefinedLength = 0xffffffffu;
constexpr std::uint64_t kNoEnd = ~std::uint64_t{0};
constexpr std::uint64_t kPart10DatasetStart = 132;  // preamble and "DICM"

// The bytes the walk reads: a file from an offset, or the inflated dataset
// of a deflated file. Positions count the bytes DCMTK counts lengths in.
class ByteInput {
 public:
  virtual ~ByteInput() = default;
  // False when fewer than `n` bytes are left.
  virtual bool read(void* out, std::size_t n) = 0;
  virtual bool skip(std::uint64_t n) = 0;
  virtual std::uint64_t tell() const = 0;
};

class FileInput final : public ByteInput {
 public:
  FileInput(const fs::path& file, std::uint64_t size, std::uint64_t at)
      : in_(file, std::ios::binary), size_(size), pos_(at), bufferAt_(at) {}
  bool read(void* out, std::size_t n) override {
    auto* dst = static_cast<char*>(out);
    while (n > 0) {
      if (pos_ >= bufferAt_ + filled_ && !fill()) return false;
      const std::size_t from = static_cast<std::size_t>(pos_ - bufferAt_);
      const std::size_t k = std::min(n, filled_ - from);
      std::copy_n(buffer_.data() + from, k, dst);
      dst += k;
      n -= k;
      pos_ += k;
    }
    return true;
  }
  // Within the file only; values are skipped without being read.
  bool skip(std::uint64_t n) override {
    if (pos_ > size_ || size_ - pos_ < n) return false;
    pos_ += n;
    return true;
  }
  std::uint64_t tell() const override { return pos_; }

 private:
  bool fill() {
    if (pos_ >= size_) return false;
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(pos_));
    in_.read(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    bufferAt_ = pos_;
    filled_ = static_cast<std::size_t>(in_.gcount());
    return filled_ > 0;
  }

  std::ifstream in_;
  std::uint64_t size_;
  std::uint64_t pos_;
  std::vector<char> buffer_ = std::vector<char>(std::size_t{1} << 16);
  std::uint64_t bufferAt_;
  std::size_t filled_ = 0;
};

// DCMTK inflates a deflated dataset (PS3.5 A.5) with zlib as it reads it:
// raw deflate unless told to expect a zlib header.
class InflatedInput final : public ByteInput {
 public:
  InflatedInput(const fs::path& file, std::uint64_t at) : in_(file, std::ios::binary) {
    in_.seekg(static_cast<std::streamoff>(at));
    ready_ =
        inflateInit2(&zs_, dcmZlibExpectRFC1950Encoding.get() ? MAX_WBITS : -MAX_WBITS) == Z_OK;
  }
  ~InflatedInput() override {
    if (ready_) inflateEnd(&zs_);
  }
  InflatedInput(const InflatedInput&) = delete;
  InflatedInput& operator=(const InflatedInput&) = delete;

  bool read(void* out, std::size_t n) override {
    auto* dst = static_cast<unsigned char*>(out);
    while (n > 0) {
      if (head_ == tail_ && !refill()) return false;
      const std::size_t k = std::min(n, tail_ - head_);
      std::copy_n(out_.data() + head_, k, dst);
      head_ += k;
      dst += k;
      n -= k;
      pos_ += k;
    }
    return true;
  }
  bool skip(std::uint64_t n) override {
    while (n > 0) {
      if (head_ == tail_ && !refill()) return false;
      const std::uint64_t k = std::min<std::uint64_t>(n, tail_ - head_);
      head_ += static_cast<std::size_t>(k);
      n -= k;
      pos_ += k;
    }
    return true;
  }
  std::uint64_t tell() const override { return pos_; }

 private:
  bool refill() {
    if (!ready_ || ended_) return false;
    head_ = tail_ = 0;
    while (tail_ == 0) {
      if (zs_.avail_in == 0) {
        in_.read(reinterpret_cast<char*>(compressed_.data()),
                 static_cast<std::streamsize>(compressed_.size()));
        zs_.next_in = compressed_.data();
        zs_.avail_in = static_cast<uInt>(in_.gcount());
        if (zs_.avail_in == 0) return false;
      }
      zs_.next_out = out_.data();
      zs_.avail_out = static_cast<uInt>(out_.size());
      const int r = inflate(&zs_, Z_NO_FLUSH);
      tail_ = out_.size() - zs_.avail_out;
      if (r == Z_STREAM_END) {
        ended_ = true;
        break;
      }
      if (r != Z_OK && r != Z_BUF_ERROR) return tail_ > 0;
    }
    return tail_ > 0;
  }

  std::ifstream in_;
  z_stream zs_{};
  bool ready_ = false;
  bool ended_ = false;
  std::array<unsigned char, 1 << 16> compressed_{};
  std::array<unsigned char, 1 << 16> out_{};
  std::size_t head_ = 0;
  std::size_t tail_ = 0;
  std::uint64_t pos_ = 0;
};

struct Syntax {
  bool implicitVr = false;
  bool bigEndian = false;
};
constexpr Syntax kImplicitLittle{true, false};
constexpr Syntax kExplicitLittle{false, false};
constexpr Syntax kExplicitBig{false, true};

// An open container of DCMTK's reader.
struct Frame {
  enum class Kind { Item, Sequence, PixelSequence } kind = Kind::Item;
  std::uint64_t end = kNoEnd;  // past its value; kNoEnd for undefined length
  Syntax syntax;
  // (group << 8 | block) -> private creator, as DCMTK's cache per item
  // resolves private tags for the dictionary.
  std::map<std::uint32_t, std::string> creators;
};

// Where the top level of one walk ends.
struct TopLevel {
  std::uint64_t end = kNoEnd;  // group-length bound of the meta information
  bool metaGroupOnly = false;  // or: while the next tag is of group 0002
};

struct WalkResult {
  bool tooDeep = false;
  bool ended = false;             // the top level ended as DCMTK ends it (not at an error)
  std::uint64_t stoppedAt = 0;    // where the top level ended
  std::string transferSyntaxUid;  // a top-level (0002,0010), when read
};

class NestingWalk {
 public:
  NestingWalk(ByteInput& in, Syntax syntax) : in_(in) {
    Frame top;
    top.syntax = syntax;
    stack_.push_back(std::move(top));
  }

  WalkResult run(const TopLevel& top) {
    WalkResult r;
    stack_.front().end = top.end;
    for (;;) {
      Frame& f = stack_.back();
      const std::uint64_t pos = in_.tell();
      if (f.end != kNoEnd && pos >= f.end) {
        if (stack_.size() == 1) return ended(r, pos);
        close();
        continue;
      }
      std::uint16_t group = 0;
      std::uint16_t number = 0;
      if (!u16(group, f.syntax) || !u16(number, f.syntax)) return r;
      if (stack_.size() == 1 && top.metaGroupOnly && group != 0x0002) return ended(r, pos);
      const DcmTag tag(group, number);
      const bool step = f.kind == Frame::Kind::Item ? element(tag, f, r) : item(tag, f);
      if (r.tooDeep || !step) return r;
    }
  }

 private:
  static WalkResult& ended(WalkResult& r, std::uint64_t pos) {
    r.ended = true;
    r.stoppedAt = pos;
    return r;
  }

  bool u16(std::uint16_t& v, Syntax s) {
    unsigned char b[2];
    if (!in_.read(b, 2)) return false;
    v = s.bigEndian ? static_cast<std::uint16_t>(b[0] << 8 | b[1])
                    : static_cast<std::uint16_t>(b[1] << 8 | b[0]);
    return true;
  }
  bool u32(std::uint32_t& v, Syntax s) {
    std::uint16_t a = 0;
    std::uint16_t b = 0;
    if (!u16(a, s) || !u16(b, s)) return false;
    v = s.bigEndian ? (std::uint32_t{a} << 16 | b) : (std::uint32_t{b} << 16 | a);
    return true;
  }

  int sequencesOpen() const {
    int n = 0;
    for (const Frame& f : stack_) n += f.kind == Frame::Kind::Sequence ? 1 : 0;
    return n;
  }

  void open(Frame::Kind kind, std::uint32_t length, Syntax syntax) {
    Frame f;
    f.kind = kind;
    f.syntax = syntax;
    f.end = length == kUndefinedLength ? kNoEnd : in_.tell() + length;
    stack_.push_back(std::move(f));
  }
  void close() { stack_.pop_back(); }

  // Inside a sequence: an item opens, the delimiter closes it; DCMTK stops
  // at anything else (EC_InvalidTag). Pixel items are values, not items
  // holding elements.
  bool item(const DcmTag& tag, Frame& f) {
    std::uint32_t length = 0;
    if (!u32(length, f.syntax)) return false;
    if (tag == DCM_SequenceDelimitationItem) {
      close();
      return true;
    }
    if (tag != DCM_Item) return false;
    if (f.kind == Frame::Kind::PixelSequence) {
      return length != kUndefinedLength && in_.skip(length);
    }
    open(Frame::Kind::Item, length, f.syntax);
    return true;
  }

  // Inside an item or the dataset: an element, maybe a sequence.
  bool element(const DcmTag& tag, Frame& f, WalkResult& r) {
    // Items and delimiters have no VR, also in explicit VR syntaxes.
    if (tag.getEVR() == EVR_na) {
      std::uint32_t length = 0;
      if (!u32(length, f.syntax)) return false;
      if (tag != DCM_ItemDelimitationItem) return false;  // DCMTK: parse error
      if (stack_.size() > 1) close();
      return true;
    }
    DcmEVR evr = EVR_UNKNOWN;
    std::uint32_t length = 0;
    if (f.syntax.implicitVr) {
      if (!u32(length, f.syntax)) return false;
      evr = dictionaryVr(tag, f);
    } else {
      std::array<char, 3> vr{};
      if (!in_.read(vr.data(), 2)) return false;
      DcmVR v(vr.data());
      if (tag == DCM_PixelData && vr[0] == 'O' && vr[1] == 'X') v.setVR(EVR_OW);
      evr = v.getEVR();
      if (v.usesExtendedLengthEncoding()) {
        std::uint16_t reserved = 0;
        if (!u16(reserved, f.syntax) || !u32(length, f.syntax)) return false;
      } else {
        std::uint16_t shortLength = 0;
        if (!u16(shortLength, f.syntax)) return false;
        length = shortLength;
      }
    }
    const bool undefined = length == kUndefinedLength;
    // DCMTK's DcmPixelData: encapsulated fragments, values rather than items.
    const bool pixelData = evr == EVR_ox || evr == EVR_px || evr == EVR_PixelData ||
                           (tag == DCM_PixelData && (evr == EVR_OB || evr == EVR_OW));
    if (pixelData && undefined) {
      open(Frame::Kind::PixelSequence, length, f.syntax);
      return true;
    }
    if (const auto s = sequenceSyntax(tag, evr, undefined, f)) {
      if (sequencesOpen() + 1 > kMaxSequenceNesting) {
        r.tooDeep = true;
        return false;
      }
      open(Frame::Kind::Sequence, length, *s);
      return true;
    }
    if (undefined) return false;  // DCMTK reads 4 GiB of value: the end of any file
    return value(tag, length, f, r);
  }

  // The VR DCMTK gives an implicit-VR element: the dictionary's, private
  // tags with the creator the item reserved them for.
  static DcmEVR dictionaryVr(const DcmTag& tag, const Frame& f) {
    if (tag.isPrivate() && tag.getElement() >= 0x1000) {
      const auto c = f.creators.find(creatorKey(tag.getGroup(), tag.getElement() >> 8));
      if (c != f.creators.end()) return DcmTag(tag, c->second.c_str()).getEVR();
    }
    return tag.getEVR();
  }

  static std::uint32_t creatorKey(std::uint16_t group, unsigned block) {
    return std::uint32_t{group} << 8 | (block & 0xff);
  }

  // The syntax a sequence's items are read in, when DCMTK reads this
  // element as a sequence (DcmItem::newDicomElement): SQ; UN or an unknown
  // VR of undefined length (CP-246: implicit VR little endian inside); OB/OW
  // of undefined length that is not Pixel Data (an error unless DCMTK is
  // told to read it as a sequence; counted as one either way); and the
  // conversions DCMTK may be configured for.
  static std::optional<Syntax> sequenceSyntax(const DcmTag& tag, DcmEVR evr, bool undefined,
                                              const Frame& f) {
    if (evr == EVR_SQ) return f.syntax;
    const bool unknown = evr == EVR_UN || evr == EVR_UNKNOWN || evr == EVR_UNKNOWN2B;
    if (unknown && undefined) {
      return dcmEnableCP246Support.get() ? kImplicitLittle : f.syntax;
    }
    if (evr == EVR_UN && dcmEnableUnknownVRConversion.get() && dictionaryVr(tag, f) == EVR_SQ) {
      return kImplicitLittle;
    }
    if ((evr == EVR_OB || evr == EVR_OW) && !undefined && tag == DCM_VOILUTSequence &&
        dcmConvertVOILUTSequenceOWtoSQ.get()) {
      return f.syntax;
    }
    // Any other element of undefined length: DCMTK either fails on it or
    // reads it as a sequence; the walk assumes the deeper.
    if (undefined) return f.syntax;
    return std::nullopt;
  }

  // A value: skipped, but private creators (PS3.5 7.8.1) and the Transfer
  // Syntax UID of the meta information are kept.
  bool value(const DcmTag& tag, std::uint32_t length, Frame& f, WalkResult& r) {
    const bool creator = tag.isPrivateReservation();
    const bool syntaxUid = stack_.size() == 1 && tag == DCM_TransferSyntaxUID;
    if ((creator || syntaxUid) && length <= 64) {
      std::string text(length, '\0');
      if (!in_.read(text.data(), length)) return false;
      while (!text.empty() && (text.back() == ' ' || text.back() == '\0')) text.pop_back();
      std::size_t lead = 0;
      while (lead < text.size() && text[lead] == ' ') ++lead;
      text.erase(0, lead);
      if (creator) f.creators[creatorKey(tag.getGroup(), tag.getElement())] = text;
      if (syntaxUid) r.transferSyntaxUid = text;
      return true;
    }
    return in_.skip(length);
  }

  ByteInput& in_;
  std::vector<Frame> stack_;
};

struct FileFacts {
  fs::path path;
  std::uint64_t size = 0;
};

bool datasetTooDeep(const FileFacts& file, std::uint64_t at, Syntax syntax, bool deflated) {
  std::unique_ptr<ByteInput> in;
  if (deflated) {
    in = std::make_unique<InflatedInput>(file.path, at);
  } else {
    in = std::make_unique<FileInput>(file.path, file.size, at);
  }
  return NestingWalk(*in, syntax).run({}).tooDeep;
}

// DCMTK's meta information ends after as many bytes as a leading File Meta
// Information Group Length (0002,0000) says, else before the first tag of
// another group. Returns the first bound, when the file has one.
std::optional<std::uint64_t> groupLengthEnd(const FileFacts& file, Syntax syntax) {
  FileInput in(file.path, file.size, kPart10DatasetStart);
  std::array<unsigned char, 12> b{};
  if (!in.read(b.data(), 8)) return std::nullopt;
  if (b[0] != 0x02 || b[1] != 0 || b[2] != 0 || b[3] != 0) return std::nullopt;
  std::uint32_t length = 0;
  std::uint64_t header = 8;
  if (syntax.implicitVr) {
    length = b[4] | b[5] << 8 | b[6] << 16 | static_cast<std::uint32_t>(b[7]) << 24;
  } else {
    const std::array<char, 3> vr{static_cast<char>(b[4]), static_cast<char>(b[5]), '\0'};
    if (DcmVR(vr.data()).usesExtendedLengthEncoding()) {
      if (!in.read(b.data() + 8, 4)) return std::nullopt;
      length = b[8] | b[9] << 8 | b[10] << 16 | static_cast<std::uint32_t>(b[11]) << 24;
      header = 12;
    } else {
      length = b[6] | b[7] << 8;
    }
  }
  std::array<unsigned char, 4> v{};
  if (length < 4 || length == kUndefinedLength || !in.read(v.data(), 4)) return std::nullopt;
  const std::uint32_t groupLength =
      v[0] | v[1] << 8 | v[2] << 16 | static_cast<std::uint32_t>(v[3]) << 24;
  return kPart10DatasetStart + header + length + groupLength;
}

bool part10TooDeep(const FileFacts& file) {
  // DCMTK guesses the meta information's encoding (PS3.10 says explicit VR
  // little endian; some writers used implicit) and where it ends: every
  // guess is walked, and the dataset from wherever a guess ends it.
  std::set<std::pair<std::uint64_t, std::string>> datasets;
  for (const Syntax meta : {kExplicitLittle, kImplicitLittle}) {
    std::vector<TopLevel> tops = {{kNoEnd, true}};
    if (const auto end = groupLengthEnd(file, meta)) tops.push_back({*end, false});
    for (const TopLevel& top : tops) {
      FileInput in(file.path, file.size, kPart10DatasetStart);
      const WalkResult r = NestingWalk(in, meta).run(top);
      if (r.tooDeep) return true;
      if (r.ended) datasets.insert({r.stoppedAt, r.transferSyntaxUid});
    }
  }
  for (const auto& [at, uid] : datasets) {
    // DCMTK refuses a Part-10 file whose meta names no syntax it knows.
    const DcmXfer x(uid.c_str());
    if (uid.empty() || x.getXfer() == EXS_Unknown) continue;
    const Syntax s{!x.isExplicitVR(), x.getByteOrder() == EBO_BigEndian};
    if (datasetTooDeep(file, at, s, x.getStreamCompression() == ESC_zlib)) return true;
  }
  return false;
}

}  // namespace

void checkSequenceNesting(const fs::path& file, bool part10) {
  std::error_code ec;
  const FileFacts facts{file, fs::file_size(file, ec)};
  if (ec) throw InputError(file.string() + ": cannot read: " + ec.message());
  bool tooDeep = false;
  if (part10) {
    tooDeep = part10TooDeep(facts);
  } else {
    // A bare dataset: DCMTK guesses its syntax from its first bytes.
    for (const Syntax s : {kImplicitLittle, kExplicitLittle, kExplicitBig}) {
      tooDeep = tooDeep || datasetTooDeep(facts, 0, s, false);
    }
  }
  if (tooDeep) throw InputError(sequencesTooDeepMessage(file.string()));
}

}  // namespace tessera::io_detail
