#include "io/Htj2kFrame.h"

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <utility>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

// ojph_arch.h first: it defines OJPH_EXPORT, which the others use.
#include <openjph/ojph_arch.h>
#include <openjph/ojph_codestream.h>
#include <openjph/ojph_file.h>
#include <openjph/ojph_mem.h>
#include <openjph/ojph_message.h>
#include <openjph/ojph_params.h>

#include "tessera/core/Error.h"

namespace tessera::io_detail {

namespace {

// ISO 15444-1 A.2: the markers walked here.
constexpr std::uint16_t kSoc = 0xff4f, kSot = 0xff90, kSod = 0xff93, kEoc = 0xffd9;
constexpr std::uint16_t kSiz = 0xff51, kCod = 0xff52, kCoc = 0xff53, kQcd = 0xff5c, kQcc = 0xff5d;
constexpr std::uint16_t kTlm = 0xff55, kPlm = 0xff57, kPlt = 0xff58, kCom = 0xff64;
// The main header's markers passed to OpenJPH: CAP, SIZ, COD, TLM, PLM,
// QCD, CRG, COM (A.5-A.9; Part 15 A.2).
const std::set<std::uint16_t> kMainMarkers = {0xff50, 0xff51, 0xff52, 0xff55,
                                              0xff57, 0xff5c, 0xff63, 0xff64};
// Bytes after each rebuilt tile-part that no valid packet reaches (any
// number > 0 does: a read that touches them is refused).
constexpr std::size_t kGuard = 16;
// More tiles than this in one frame is not a DICOM image: each costs OpenJPH
// an allocation however small the tile.
constexpr std::size_t kMaxTiles = 4096;

std::string hex16(unsigned v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%04X", v & 0xffffu);
  return buf;
}

std::string dims(long long w, long long h) {
  return std::to_string(w) + "x" + std::to_string(h);
}

// ---- OpenJPH's messages. Its 0.9 configure_error() copies the handler
// given into its own default by reference assignment (slicing it), so a
// custom handler never runs: the default prints "ojph error 0x... at
// FILE:LINE: TEXT" to the error stream and throws std::runtime_error("ojph
// error"). Its streams go to a sink that keeps the text per thread, for our
// message (and so that stderr carries only our one line).
thread_local std::string openJphText;

ssize_t keepOpenJphText(void*, const char* buffer, size_t size) {
  if (openJphText.size() < 4096) openJphText.append(buffer, std::min<size_t>(size, 4096));
  return static_cast<ssize_t>(size);
}

void configureOpenJph() {
  static std::once_flag once;
  std::call_once(once, [] {
    cookie_io_functions_t io{};
    io.write = keepOpenJphText;
    if (FILE* sink = fopencookie(nullptr, "w", io)) {
      std::setvbuf(sink, nullptr, _IONBF, 0);  // written by the thread that prints
      ojph::set_error_stream(sink);
      ojph::set_warning_stream(sink);
      ojph::set_info_stream(sink);
    }
  });
}

// The TEXT of OpenJPH's last error printed by this thread, else `fallback`.
std::string openJphError(const std::string& fallback) {
  const std::size_t at = openJphText.rfind("ojph error");
  if (at == std::string::npos) return fallback;
  const std::size_t colon = openJphText.find(": ", openJphText.find(" at ", at));
  if (colon == std::string::npos) return fallback;
  std::string text = openJphText.substr(colon + 2);
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text.empty() ? fallback : "OpenJPH: " + text.substr(0, 200);
}

// ---- The codestream's structure (ISO 15444-1 A.4), walked before OpenJPH.

std::uint16_t u16(std::span<const std::uint8_t> d, std::size_t at) {
  return static_cast<std::uint16_t>((d[at] << 8) | d[at + 1]);
}

std::uint32_t u32(std::span<const std::uint8_t> d, std::size_t at) {
  return (static_cast<std::uint32_t>(u16(d, at)) << 16) | u16(d, at + 2);
}

void put16(std::vector<std::uint8_t>& out, std::uint32_t v) {
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v));
}

struct Span {
  std::size_t begin = 0, end = 0;
};

// One tile's tile-parts: the first one's header markers (less PLT and COM,
// which only index and annotate the packets) and every tile-part's packet data, in order.
struct Tile {
  std::vector<Span> header;
  std::vector<Span> bodies;
  unsigned parts = 0;
};

// The codestream as OpenJPH reads it: main header, one tile-part per tile
// ending in kGuard zero bytes, EOC; `guards` are where those bytes lie.
struct Rebuilt {
  std::vector<std::uint8_t> bytes;
  std::vector<Span> guards;
};

class Walker {
 public:
  Walker(std::span<const std::uint8_t> d, const std::string& what) : d_(d), what_(what) {}

  Rebuilt rebuild() {
    const std::size_t mainEnd = mainHeader();
    std::size_t at = mainEnd;
    while (at + 2 <= end_ && u16(d_, at) == kSot) at = tilePart(at);
    if (tiles_.empty()) throw bad("no tile-part after the main header (truncated?)");
    if (at < end_ && !(at + 2 <= end_ && u16(d_, at) == kEoc)) {
      throw bad("marker " + hex16(at + 2 <= end_ ? u16(d_, at) : d_[at]) + " at byte " +
                std::to_string(at) + " where a tile-part or the end of the codestream belongs");
    }
    Rebuilt r;
    for (const Span& s : main_) copy(r, s);
    for (const auto& [index, tile] : tiles_) emit(r, index, tile);
    put16(r.bytes, kEoc);
    return r;
  }

 private:
  InputError bad(const std::string& why) const {
    return InputError(what_ + ": the HTJ2K frame cannot be decoded (" + why + ")");
  }

  // SOC, then marker segments up to the first SOT; returns where that is.
  std::size_t mainHeader() {
    if (d_.size() >= 12 && d_[4] == 'j' && d_[5] == 'P') {
      throw bad("a JP2 file, not the bare codestream PS3.5 A.4.11 stores");
    }
    if (d_.size() < 4 || u16(d_, 0) != kSoc) throw bad("no SOC marker: not a JPEG 2000 codestream");
    end_ = d_.size();
    std::size_t at = 2;
    main_.push_back({0, 2});
    for (int markers = 0; markers < 256; ++markers) {
      if (at + 4 > end_) throw bad("the main header is truncated at byte " + std::to_string(at));
      const std::uint16_t marker = u16(d_, at);
      if (marker == kSot) {
        checkQuantization();
        return at;
      }
      if ((marker >> 8) != 0xff || marker < 0xff30) {
        throw bad("byte " + std::to_string(at) + " holds " + hex16(marker) + ", not a marker");
      }
      const std::size_t length = u16(d_, at + 2);
      if (length < 2 || at + 2 + length > end_) {
        throw bad("marker " + hex16(marker) + " at byte " + std::to_string(at) + " claims " +
                  std::to_string(length) + " bytes, " + std::to_string(end_ - at - 2) +
                  " remain (truncated?)");
      }
      // COC and QCC (per-component coding and quantization) are not read:
      // OpenJPH 0.9 overflows its buffer on a QCC longer than it expects
      // (found by fuzzing it with ASan), and a greyscale frame needs neither.
      if (marker == kCoc || marker == kQcc) {
        throw bad("a " + std::string(marker == kCoc ? "COC" : "QCC") +
                  " marker (per-component settings) is not read");
      }
      // SIZ first (A.4.1), then each of the others OpenJPH 0.9 reads at most
      // once: it sizes its tables by SIZ (a stream without one overflowed
      // them: found by fuzzing it with ASan).
      const bool first = markers == 0;
      const bool once = marker == kSiz || marker == kCod || marker == kQcd || marker == 0xff50;
      if ((marker == kSiz) != first || !kMainMarkers.contains(marker) ||
          (once && !seen_.insert(marker).second)) {
        throw bad("marker " + hex16(marker) + " at byte " + std::to_string(at) +
                  (first ? " where SIZ belongs" : " is not one read in the main header here"));
      }
      if (marker == kCod) cod_ = {at, at + 2 + length};
      if (marker == kQcd) qcd_ = {at, at + 2 + length};
      // Tile and packet lengths (TLM, PLM) would not match the rebuilt
      // tile-parts; they only index the data, as comments annotate it.
      if (marker != kTlm && marker != kPlm && marker != kCom)
        main_.push_back({at, at + 2 + length});
      at += 2 + length;
    }
    throw bad("more than 256 marker segments in the main header");
  }

  // The tile-part whose SOT is at `at`; returns where the next one begins.
  std::size_t tilePart(std::size_t at) {
    if (at + 14 > end_ || u16(d_, at + 2) != 10) throw bad("a truncated or malformed SOT marker");
    const unsigned index = u16(d_, at + 4);
    const std::uint32_t psot = u32(d_, at + 6);
    const unsigned part = d_[at + 10];
    std::size_t partEnd = at + psot;
    if (psot == 0) {  // to the end of the codestream (A.4.2): before EOC and a pad byte
      partEnd = end_;
      if (partEnd >= at + 3 && d_[partEnd - 1] == 0 && u16(d_, partEnd - 3) == kEoc) --partEnd;
      if (partEnd >= at + 2 && u16(d_, partEnd - 2) == kEoc) partEnd -= 2;
    }
    if (partEnd < at + 14 || partEnd > end_) {
      throw bad("tile-part " + std::to_string(part) + " of tile " + std::to_string(index) +
                " declares " + std::to_string(psot) + " bytes, " + std::to_string(end_ - at) +
                " remain (truncated?)");
    }
    // One tile (A.4.2: index 0): OpenJPH 0.9 decodes tiled codestreams
    // wrongly, and indexes its tiles by this number unchecked.
    if (index != 0) {
      throw InputError(what_ + ": a tiled HTJ2K frame (tile " + std::to_string(index) +
                       ") is not read: Debian 12's OpenJPH 0.9 decodes tiled codestreams wrongly");
    }
    Tile& tile = tiles_[index];
    if (tiles_.size() > kMaxTiles) throw bad("more than " + std::to_string(kMaxTiles) + " tiles");
    if (part != tile.parts) {
      throw bad("tile-part " + std::to_string(part) + " of tile " + std::to_string(index) +
                " where tile-part " + std::to_string(tile.parts) + " belongs");
    }
    std::size_t h = at + 12;
    while (true) {
      if (h + 2 > partEnd) throw bad("a tile-part header without SOD (truncated?)");
      const std::uint16_t marker = u16(d_, h);
      if (marker == kSod) break;
      if (h + 4 > partEnd || (marker >> 8) != 0xff || u16(d_, h + 2) < 2 ||
          h + 2 + u16(d_, h + 2) > partEnd) {
        throw bad("a malformed marker " + hex16(marker) + " in a tile-part header");
      }
      const std::size_t next = h + 2 + u16(d_, h + 2);
      if (marker != kPlt && marker != kCom) {
        // Tile-level coding settings would bypass the main header's checks.
        throw bad("marker " + hex16(marker) + " in a tile-part header is not read");
      }
      h = next;
    }
    checkPacketData({h + 2, partEnd});
    tile.bodies.push_back({h + 2, partEnd});
    ++tile.parts;
    return psot == 0 ? partEnd : at + psot;
  }

  // COD and QCD (A.6.1, A.6.4) agree as OpenJPH 0.9 asserts they do (its
  // param_qcd::get_Kmax and irrev_get_delta, found by fuzz_htj2k): a step
  // size for each of the 3 NL + 1 subbands, none for the 5/3 wavelet (style
  // 0) and expounded ones for the 9/7 (style 2).
  void checkQuantization() const {
    if (cod_.end < cod_.begin + 14 || qcd_.end < qcd_.begin + 5) {
      throw bad("no COD or QCD marker, or one too short, in the main header");
    }
    if (d_[cod_.begin + 5] > 4) {  // LRCP, RLCP, RPCL, PCRL, CPRL (A.6.1); else OpenJPH asserts
      throw bad("progression order " + std::to_string(d_[cod_.begin + 5]) + " in COD");
    }
    const unsigned levels = d_[cod_.begin + 9];
    const bool reversible = d_[cod_.begin + 13] == 1;
    const unsigned style = d_[qcd_.begin + 4] & 0x1f;
    const std::size_t stepBytes = qcd_.end - qcd_.begin - 5;
    const std::size_t steps = style == 0 ? stepBytes : stepBytes / 2;
    // Exactly 3 NL + 1 (A.6.4): OpenJPH 0.9 reads any number into an array
    // of 97 (a longer QCD overflowed it: found by fuzzing it with ASan).
    if (style != (reversible ? 0u : 2u) || steps != 3 * levels + 1 || levels > 32) {
      throw bad("QCD (quantization style " + std::to_string(style) + ", " + std::to_string(steps) +
                " step sizes) does not fit COD (" + (reversible ? "5/3" : "9/7") + " wavelet, " +
                std::to_string(levels) + " levels)");
    }
  }

  // Packet data never holds 0xFF followed by a byte above 0x8F but the SOP
  // and EPH markers (ISO 15444-1 A.1 and B.10.1: bit-stuffing in packet
  // headers, the code-block coders' own stuffing in their data; T.814 keeps
  // it for HT segments). OpenJPH 0.9 asserts on two such cases (bb_terminate
  // on 0xFFFF closing a packet header; mel_init on an HT MEL segment
  // starting 0xFF9x: found by fuzz_htj2k): refused here first.
  void checkPacketData(const Span& body) const {
    for (std::size_t i = body.begin; i + 1 < body.end; ++i) {
      if (d_[i] == 0xff && d_[i + 1] > 0x8f && d_[i + 1] != 0x91 && d_[i + 1] != 0x92) {
        throw bad("marker code " + hex16(u16(d_, i)) + " inside packet data at byte " +
                  std::to_string(i) + "; corrupt?");
      }
    }
  }

  void emit(Rebuilt& r, unsigned index, const Tile& tile) const {
    std::size_t length = 12 + 2 + kGuard;
    for (const Span& s : tile.header) length += s.end - s.begin;
    for (const Span& s : tile.bodies) length += s.end - s.begin;
    if (length > 0xffffffffu) throw bad("a tile of more than 4 GiB");
    put16(r.bytes, kSot);
    put16(r.bytes, 10);
    put16(r.bytes, index);
    put16(r.bytes, static_cast<std::uint32_t>(length) >> 16);
    put16(r.bytes, static_cast<std::uint32_t>(length) & 0xffffu);
    r.bytes.push_back(0);  // TPsot: the only tile-part
    r.bytes.push_back(1);  // TNsot
    for (const Span& s : tile.header) copy(r, s);
    put16(r.bytes, kSod);
    for (const Span& s : tile.bodies) copy(r, s);
    r.guards.push_back({r.bytes.size(), r.bytes.size() + kGuard});
    r.bytes.resize(r.bytes.size() + kGuard, 0);
  }

  void copy(Rebuilt& r, const Span& s) const {
    r.bytes.insert(r.bytes.end(), d_.begin() + static_cast<std::ptrdiff_t>(s.begin),
                   d_.begin() + static_cast<std::ptrdiff_t>(s.end));
  }

  std::span<const std::uint8_t> d_;
  const std::string& what_;
  std::size_t end_ = 0;
  std::vector<Span> main_;  // SOC and the main header's segments kept
  Span cod_, qcd_;
  std::set<std::uint16_t> seen_;
  std::map<unsigned, Tile> tiles_;
};

// The rebuilt codestream as OpenJPH's input. OpenJPH 0.9 reads a code-block's
// data with min(claimed length, bytes left in the tile-part) and zero-fills
// the rest of the claimed length past the buffer it sized by the smaller
// number; a claim beyond the tile-part's real end reads into the guard, and
// is refused here before that fill.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnon-virtual-dtor"
class GuardedInput final : public ojph::infile_base {
 public:
  explicit GuardedInput(const Rebuilt& r) : r_(r) {}

  size_t read(void* ptr, size_t size) override {
    const std::size_t n = std::min(size, r_.bytes.size() - at_);
    for (const Span& g : r_.guards) {
      if (at_ < g.end && at_ + n > g.begin) {
        throw std::runtime_error("packet data runs past the end of its tile-part");
      }
    }
    std::memcpy(ptr, r_.bytes.data() + at_, n);
    at_ += n;
    return n;
  }

  int seek(ojph::si64 offset, enum infile_base::seek origin) override {
    const ojph::si64 base = origin == OJPH_SEEK_SET   ? 0
                            : origin == OJPH_SEEK_CUR ? static_cast<ojph::si64>(at_)
                                                      : static_cast<ojph::si64>(r_.bytes.size());
    const ojph::si64 to = base + offset;
    if (to < 0 || to > static_cast<ojph::si64>(r_.bytes.size())) return -1;
    at_ = static_cast<std::size_t>(to);
    return 0;
  }

  ojph::si64 tell() override { return static_cast<ojph::si64>(at_); }
  bool eof() override { return at_ >= r_.bytes.size(); }

 private:
  const Rebuilt& r_;
  std::size_t at_ = 0;
};
#pragma GCC diagnostic pop

// The tiling and code-block layout OpenJPH sizes its buffers by, checked as
// ISO 15444-1 A.5.1 and A.6.1 bound them before it divides by them (a zero
// tile size made its pre-allocation divide by zero: found by scripts/fuzz.sh).
void checkLayout(ojph::param_siz siz, ojph::param_cod cod, const std::string& what) {
  const ojph::size tile = siz.get_tile_size();
  const ojph::point tileAt = siz.get_tile_offset(), imageAt = siz.get_image_offset();
  const ojph::point extent = siz.get_image_extent();
  const auto bad = [&](const std::string& why) {
    return InputError(what + ": the HTJ2K frame's header is invalid (" + why + ")");
  };
  if (tile.w == 0 || tile.h == 0) throw bad("tile size " + dims(tile.w, tile.h));
  if (tileAt.x > imageAt.x || tileAt.y > imageAt.y ||
      std::uint64_t(tileAt.x) + tile.w <= imageAt.x ||
      std::uint64_t(tileAt.y) + tile.h <= imageAt.y || extent.x <= imageAt.x ||
      extent.y <= imageAt.y) {
    throw bad("tile or image offsets outside the image");
  }
  const std::uint64_t across = (std::uint64_t(extent.x) - tileAt.x + tile.w - 1) / tile.w;
  const std::uint64_t down = (std::uint64_t(extent.y) - tileAt.y + tile.h - 1) / tile.h;
  // OpenJPH 0.9 decodes codestreams tiled in both directions wrongly (the
  // last tiles' samples differ from the original and from OpenJPEG's decode
  // of the same stream, also in its own ojph_expand); one tile is what DICOM
  // writers use, so a tiled frame is refused rather than read wrong.
  if (across * down > 1) {
    throw InputError(what + ": a tiled HTJ2K frame (" + std::to_string(across) + "x" +
                     std::to_string(down) +
                     " tiles) is not read: Debian 12's OpenJPH 0.9 decodes tiled codestreams "
                     "wrongly");
  }
  const ojph::ui32 levels = cod.get_num_decompositions();
  if (levels > 32) throw bad(std::to_string(levels) + " decomposition levels");
  const ojph::size block = cod.get_log_block_dims();
  if (block.w < 2 || block.h < 2 || block.w > 10 || block.h > 10 || block.w + block.h > 12) {
    throw bad("code-block size 2^" + std::to_string(block.w) + " x 2^" + std::to_string(block.h));
  }
  for (ojph::ui32 level = 0; level <= levels; ++level) {
    const ojph::size precinct = cod.get_precinct_size(level);
    if (precinct.w == 0 || precinct.h == 0) throw bad("an empty precinct");
  }
}

void checkSiz(ojph::param_siz siz, const FrameShape& shape, const std::string& what) {
  const ojph::point extent = siz.get_image_extent(), offset = siz.get_image_offset();
  const ojph::ui32 components = siz.get_num_components();
  const ojph::point sub = components > 0 ? siz.get_downsampling(0) : ojph::point(1, 1);
  checkFrameHeader(shape, what, "HTJ2K", static_cast<long long>(extent.x) - offset.x,
                   static_cast<long long>(extent.y) - offset.y, components,
                   components > 0 ? siz.get_bit_depth(0) : 0, sub.x != 1 || sub.y != 1);
  if (shape.isSigned && siz.is_signed(0) != *shape.isSigned) {
    throw InputError(what + ": the HTJ2K frame holds " +
                     (siz.is_signed(0) ? "signed" : "unsigned") +
                     " samples, but the file declares Pixel Representation " +
                     (*shape.isSigned ? "1 (signed)" : "0 (unsigned)"));
  }
}

// The rows, each sample clamped to the codestream's range (`bits` deep,
// signed or not): the 9/7 wavelet overshoots it near the extremes, and a
// value wrapped into Bits Allocated would turn black into white.
void decodeRows(ojph::codestream& cs, const FrameShape& shape, unsigned bits, bool isSigned,
                std::vector<std::uint8_t>& out) {
  const std::int32_t lo = isSigned ? -(std::int32_t{1} << (bits - 1)) : 0;
  const std::int32_t hi = isSigned ? (std::int32_t{1} << (bits - 1)) - 1
                                   : static_cast<std::int32_t>((std::int64_t{1} << bits) - 1);
  for (int y = 0; y < shape.rows; ++y) {
    ojph::ui32 comp = 0;
    const ojph::line_buf* line = cs.pull(comp);
    if (line == nullptr || comp != 0 || line->i32 == nullptr ||
        line->size < static_cast<std::size_t>(shape.columns)) {
      throw std::runtime_error("row " + std::to_string(y) + " is missing");
    }
    const std::size_t row = static_cast<std::size_t>(y) * shape.columns;
    for (int x = 0; x < shape.columns; ++x) {
      putFrameSample(out, row + x, std::clamp(line->i32[x], lo, hi), shape.bitsAllocated);
    }
  }
}

// The frame decoded by OpenJPH in this process (see decodeHtj2kFrame).
std::vector<std::uint8_t> decodeHere(const Rebuilt& rebuilt, const FrameShape& shape,
                                     const std::string& what) {
  configureOpenJph();
  openJphText.clear();
  std::vector<std::uint8_t> out = frameSamples(shape, what);
  const auto failed = [&](const std::string& why) {
    return InputError(what + ": the HTJ2K frame cannot be decoded (" + why +
                      "; corrupt or truncated?)");
  };
  try {
    GuardedInput in(rebuilt);
    ojph::codestream cs;
    cs.read_headers(&in);
    checkSiz(cs.access_siz(), shape, what);
    checkLayout(cs.access_siz(), cs.access_cod(), what);
    const unsigned bits = cs.access_siz().get_bit_depth(0);
    const bool isSigned = cs.access_siz().is_signed(0);
    cs.create();
    decodeRows(cs, shape, bits, isSigned, out);
    cs.close();
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw failed(openJphError(e.what()));
  } catch (const char* e) {  // OpenJPH's own throws, where it does not catch them
    throw failed(e != nullptr ? e : "OpenJPH");
  }
  return out;
}

// A shared anonymous mapping: the child's samples, then its message.
class SharedBytes {
 public:
  explicit SharedBytes(std::size_t size) : size_(size) {
    void* p = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (p != MAP_FAILED) data_ = static_cast<std::uint8_t*>(p);
  }
  ~SharedBytes() {
    if (data_ != nullptr) munmap(data_, size_);
  }
  SharedBytes(const SharedBytes&) = delete;
  SharedBytes& operator=(const SharedBytes&) = delete;
  std::uint8_t* data() const { return data_; }

 private:
  std::size_t size_;
  std::uint8_t* data_ = nullptr;
};

constexpr std::size_t kMessageBytes = 1024;
// The child's exit status for an InputError (its message in the mapping);
// not 1, a sanitizer's.
constexpr int kChildInputError = 37;
// A frame takes milliseconds; a child still running after this is stuck.
constexpr unsigned kChildSeconds = 60;

// The child: decodes into `shared` and exits 0, or writes the InputError's
// message after the samples and exits 1. It never returns: _exit skips the
// parent's atexit handlers and destructors (temporary folders, caches).
[[noreturn]] void decodeInChild(const Rebuilt& rebuilt, const FrameShape& shape,
                                const std::string& what, std::uint8_t* shared, std::size_t bytes,
                                int errorPipe) {
  // The parent's crash handlers (a fuzzer's, a sanitizer's) are not the
  // child's: an abort here is the parent's to report, with what the child
  // printed (an assertion's text) in the pipe.
  for (int sig : {SIGABRT, SIGSEGV, SIGFPE, SIGBUS, SIGILL}) std::signal(sig, SIG_DFL);
  dup2(errorPipe, STDERR_FILENO);
  alarm(kChildSeconds);
  int code = 0;
  try {
    const std::vector<std::uint8_t> out = decodeHere(rebuilt, shape, what);
    std::memcpy(shared, out.data(), std::min(bytes, out.size()));
  } catch (const std::exception& e) {
    std::snprintf(reinterpret_cast<char*>(shared + bytes), kMessageBytes, "%s", e.what());
    code = kChildInputError;
  } catch (...) {
    code = kChildInputError + 1;
  }
  _exit(code);
}

// Why the child failed, for the message: OpenJPH's failed assertion, or
// the signal. A sanitizer's report in a sanitized build (the fuzzer) is a
// crash of this process too, so that fuzzing finds memory errors in OpenJPH.
std::string childFailure(int status, const std::string& printed) {
#if defined(__SANITIZE_ADDRESS__)
  if (printed.find("Sanitizer") != std::string::npos) {
    std::fputs(printed.c_str(), stderr);
    std::abort();
  }
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
  if (printed.find("Sanitizer") != std::string::npos) {
    std::fputs(printed.c_str(), stderr);
    std::abort();
  }
#endif
#endif
  const std::size_t assertion = printed.find("Assertion");
  if (assertion != std::string::npos) {
    const std::size_t from = printed.rfind(": ", printed.rfind(": ", assertion) - 1);
    std::string text = printed.substr(from == std::string::npos ? assertion : from + 2, 160);
    text = text.substr(0, text.find('\n'));
    return "OpenJPH failed an assertion: " + text;
  }
  if (WIFSIGNALED(status)) return std::string("OpenJPH died of ") + strsignal(WTERMSIG(status));
  return "OpenJPH's process exited with " + std::to_string(WEXITSTATUS(status));
}

}  // namespace

std::vector<std::uint8_t> decodeHtj2kFrame(std::span<const std::uint8_t> codestream,
                                           const FrameShape& shape, const std::string& what) {
  const std::size_t bytes = frameSamples(shape, what).size();
  const Rebuilt rebuilt = Walker(codestream, what).rebuild();
  // OpenJPH 0.9 is built with its assertions on (Debian), and some fire on
  // corrupt packet headers that only a packet parser of our own could rule
  // out (bb_read_bits' num_bits <= 32, found by fuzz_htj2k): it decodes in a
  // child process, so that an abort there is an error here, never the end
  // of this process.
  SharedBytes shared(bytes + kMessageBytes);
  if (shared.data() == nullptr) throw Error(what + ": no memory to decode the HTJ2K frame in");
  // The child's stderr; non-blocking, so that a long report cannot stall it.
  int pipeEnds[2];
  if (pipe2(pipeEnds, O_NONBLOCK | O_CLOEXEC) != 0) {
    throw Error(what + ": cannot start the HTJ2K decoder process (" + std::strerror(errno) + ")");
  }
  const pid_t child = fork();
  if (child == 0) decodeInChild(rebuilt, shape, what, shared.data(), bytes, pipeEnds[1]);
  close(pipeEnds[1]);
  int status = 0;
  while (child > 0 && waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  std::string printed;
  char buffer[4096];
  for (ssize_t n = 0; (n = read(pipeEnds[0], buffer, sizeof buffer)) > 0;)
    printed.append(buffer, n);
  close(pipeEnds[0]);
  if (child < 0) {
    throw Error(what + ": cannot start the HTJ2K decoder process (" + std::strerror(errno) + ")");
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    return std::vector<std::uint8_t>(shared.data(), shared.data() + bytes);
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == kChildInputError) {
    throw InputError(std::string(reinterpret_cast<const char*>(shared.data() + bytes)));
  }
  throw InputError(what + ": the HTJ2K frame cannot be decoded (" + childFailure(status, printed) +
                   "; corrupt?)");
}

}  // namespace tessera::io_detail
