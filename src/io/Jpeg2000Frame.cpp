#include "io/Jpeg2000Frame.h"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <memory>
#include <mutex>
#include <stdexcept>

#include <openjpeg.h>
#include <openjph/ojph_arch.h>
#include <openjph/ojph_codestream.h>
#include <openjph/ojph_file.h>
#include <openjph/ojph_mem.h>
#include <openjph/ojph_message.h>
#include <openjph/ojph_params.h>

#include "tessera/core/Error.h"

namespace tessera::io_detail {

namespace {

std::string dims(long long w, long long h) {
  return std::to_string(w) + "x" + std::to_string(h);
}

// The checks both codecs make on a frame's header before decoding it.
void checkHeader(const FrameShape& shape, const std::string& what, const std::string& codec,
                 long long width, long long height, unsigned components, unsigned precision,
                 bool subsampled) {
  if (components != 1) {
    throw InputError(what + ": a " + codec + " frame of " + std::to_string(components) +
                     " components; only greyscale (one component) is read");
  }
  if (shape.samplesPerPixel != 1) {
    throw InputError(what + ": Samples per Pixel is " + std::to_string(shape.samplesPerPixel) +
                     "; only greyscale (1) is read");
  }
  if (width != shape.columns || height != shape.rows) {
    throw InputError(what + ": the " + codec + " frame is " + dims(width, height) +
                     " pixels, but the file declares " + dims(shape.columns, shape.rows) +
                     " (Columns x Rows)");
  }
  if (subsampled) throw InputError(what + ": a subsampled " + codec + " component is not read");
  if (precision == 0 || precision > static_cast<unsigned>(shape.bitsAllocated)) {
    throw InputError(what + ": the " + codec + " frame has " + std::to_string(precision) +
                     "-bit samples, more than the " + std::to_string(shape.bitsAllocated) +
                     " bits allocated per pixel");
  }
}

// Writes one sample as uncompressed pixel data holds it: the low
// bitsAllocated bits of its two's complement, host byte order.
void putSample(std::vector<std::uint8_t>& out, std::size_t index, std::int32_t value, int bits) {
  if (bits == 8) {
    out[index] = static_cast<std::uint8_t>(static_cast<std::uint32_t>(value) & 0xffu);
    return;
  }
  const auto v = static_cast<std::uint16_t>(static_cast<std::uint32_t>(value) & 0xffffu);
  std::memcpy(out.data() + 2 * index, &v, 2);
}

std::vector<std::uint8_t> samplesFor(const FrameShape& shape, const std::string& what) {
  if (shape.bitsAllocated != 8 && shape.bitsAllocated != 16) {
    throw InputError(what + ": Bits Allocated is " + std::to_string(shape.bitsAllocated) +
                     "; compressed frames are read with 8 or 16");
  }
  return std::vector<std::uint8_t>(static_cast<std::size_t>(shape.rows) * shape.columns *
                                   (shape.bitsAllocated / 8));
}

// ---- OpenJPEG

// The codestream as OpenJPEG's input stream.
struct MemoryReader {
  std::span<const std::uint8_t> data;
  std::size_t at = 0;
};

OPJ_SIZE_T readBytes(void* buffer, OPJ_SIZE_T count, void* user) {
  auto& r = *static_cast<MemoryReader*>(user);
  if (r.at >= r.data.size()) return static_cast<OPJ_SIZE_T>(-1);
  const std::size_t n = std::min<std::size_t>(count, r.data.size() - r.at);
  std::memcpy(buffer, r.data.data() + r.at, n);
  r.at += n;
  return n;
}

OPJ_OFF_T skipBytes(OPJ_OFF_T count, void* user) {
  auto& r = *static_cast<MemoryReader*>(user);
  if (count < 0) return -1;
  const std::size_t n =
      std::min<std::size_t>(static_cast<std::size_t>(count), r.data.size() - r.at);
  r.at += n;
  return static_cast<OPJ_OFF_T>(n);
}

OPJ_BOOL seekTo(OPJ_OFF_T position, void* user) {
  auto& r = *static_cast<MemoryReader*>(user);
  if (position < 0 || static_cast<std::uint64_t>(position) > r.data.size()) return OPJ_FALSE;
  r.at = static_cast<std::size_t>(position);
  return OPJ_TRUE;
}

// OpenJPEG's first error message, for ours.
void keepError(const char* message, void* user) {
  auto& text = *static_cast<std::string*>(user);
  if (text.empty() && message != nullptr) {
    text = message;
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  }
}

void ignoreMessage(const char*, void*) {}

// opj_codec_t and opj_stream_t are both void*: one deleter each.
struct CodecFree {
  void operator()(opj_codec_t* c) const { opj_destroy_codec(c); }
};
struct StreamFree {
  void operator()(opj_stream_t* s) const { opj_stream_destroy(s); }
};
struct ImageFree {
  void operator()(opj_image_t* i) const { opj_image_destroy(i); }
};

// A JP2 file (some writers wrap the codestream in one) or a bare codestream.
bool isJp2(std::span<const std::uint8_t> d) {
  static constexpr std::uint8_t kJp2Signature[] = {0, 0, 0, 0x0c, 'j', 'P', ' ', ' '};
  return d.size() >= sizeof kJp2Signature &&
         std::equal(std::begin(kJp2Signature), std::end(kJp2Signature), d.begin());
}

// ---- OpenJPH: its errors are thrown as runtime_error, without printing.
// (Its message classes have no virtual destructor; these are never deleted
// through a base pointer: they live as long as the process.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnon-virtual-dtor"
class ThrowingError final : public ojph::message_error {
 public:
  void operator()(int, const char*, int, const char* fmt, ...) override {
    char buf[512];
    va_list args;
    va_start(args, fmt);
    std::vsnprintf(buf, sizeof buf, fmt, args);
    va_end(args);
    throw std::runtime_error(buf);
  }
};

class SilentWarning final : public ojph::message_warning {
 public:
  void operator()(int, const char*, int, const char*, ...) override {}
};
#pragma GCC diagnostic pop

void configureOpenJph() {
  static std::once_flag once;
  std::call_once(once, [] {
    static ThrowingError error;
    static SilentWarning warning;
    ojph::configure_error(&error);
    ojph::configure_warning(&warning);
    // OpenJPH 0.9 still prints through its own handlers: into a sink, so
    // that stderr carries only our one line.
    if (FILE* sink = std::fopen("/dev/null", "w")) {
      ojph::set_error_stream(sink);
      ojph::set_warning_stream(sink);
      ojph::set_info_stream(sink);
    }
  });
}

// The tiling and code-block layout OpenJPH sizes its buffers by, checked
// as ISO 15444-1 A.5.1 and A.6.1 bound them before it divides by them (a
// zero tile size made its pre-allocation divide by zero: found by
// scripts/fuzz.sh).
void checkHtj2kLayout(ojph::param_siz siz, ojph::param_cod cod, const std::string& what) {
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

}  // namespace

std::vector<std::uint8_t> decodeJpeg2000Frame(std::span<const std::uint8_t> codestream,
                                              const FrameShape& shape, const std::string& what) {
  std::vector<std::uint8_t> out = samplesFor(shape, what);
  MemoryReader reader{codestream, 0};
  std::unique_ptr<opj_stream_t, StreamFree> stream(opj_stream_create(OPJ_J2K_STREAM_CHUNK_SIZE, 1));
  std::unique_ptr<opj_codec_t, CodecFree> codec(
      opj_create_decompress(isJp2(codestream) ? OPJ_CODEC_JP2 : OPJ_CODEC_J2K));
  if (!stream || !codec) throw Error(what + ": OpenJPEG could not start a decoder");
  opj_stream_set_user_data(stream.get(), &reader, nullptr);
  opj_stream_set_user_data_length(stream.get(), codestream.size());
  opj_stream_set_read_function(stream.get(), readBytes);
  opj_stream_set_skip_function(stream.get(), skipBytes);
  opj_stream_set_seek_function(stream.get(), seekTo);
  std::string error;
  opj_set_error_handler(codec.get(), keepError, &error);
  opj_set_warning_handler(codec.get(), ignoreMessage, nullptr);
  opj_set_info_handler(codec.get(), ignoreMessage, nullptr);
  opj_dparameters_t params;
  opj_set_default_decoder_parameters(&params);
  const auto failed = [&](const std::string& step) {
    return InputError(what + ": the JPEG 2000 frame cannot be decoded (" + step +
                      (error.empty() ? "" : ": " + error) + "; corrupt or truncated?)");
  };
  if (!opj_setup_decoder(codec.get(), &params)) throw failed("decoder setup");
  opj_image_t* raw = nullptr;
  const bool header = opj_read_header(stream.get(), codec.get(), &raw) != 0;
  std::unique_ptr<opj_image_t, ImageFree> image(raw);
  if (!header || !image) throw failed("its header");
  const opj_image_comp_t* c = image->numcomps > 0 ? &image->comps[0] : nullptr;
  checkHeader(shape, what, "JPEG 2000", static_cast<long long>(image->x1) - image->x0,
              static_cast<long long>(image->y1) - image->y0, image->numcomps,
              c != nullptr ? c->prec : 0, c != nullptr && (c->dx != 1 || c->dy != 1));
  if (!opj_decode(codec.get(), stream.get(), image.get()) ||
      !opj_end_decompress(codec.get(), stream.get())) {
    throw failed("its tiles");
  }
  const opj_image_comp_t& comp = image->comps[0];
  if (comp.data == nullptr || comp.w != static_cast<OPJ_UINT32>(shape.columns) ||
      comp.h != static_cast<OPJ_UINT32>(shape.rows)) {
    throw failed("its component came out " + dims(comp.w, comp.h));
  }
  const std::size_t n = static_cast<std::size_t>(shape.rows) * shape.columns;
  for (std::size_t i = 0; i < n; ++i) putSample(out, i, comp.data[i], shape.bitsAllocated);
  return out;
}

std::vector<std::uint8_t> decodeHtj2kFrame(std::span<const std::uint8_t> codestream,
                                           const FrameShape& shape, const std::string& what) {
  configureOpenJph();
  std::vector<std::uint8_t> out = samplesFor(shape, what);
  try {
    ojph::mem_infile in;
    in.open(codestream.data(), codestream.size());
    ojph::codestream cs;
    cs.read_headers(&in);
    ojph::param_siz siz = cs.access_siz();
    const ojph::point extent = siz.get_image_extent(), offset = siz.get_image_offset();
    const ojph::ui32 components = siz.get_num_components();
    const ojph::point sub = components > 0 ? siz.get_downsampling(0) : ojph::point(1, 1);
    checkHeader(shape, what, "HTJ2K", static_cast<long long>(extent.x) - offset.x,
                static_cast<long long>(extent.y) - offset.y, components,
                components > 0 ? siz.get_bit_depth(0) : 0, sub.x != 1 || sub.y != 1);
    checkHtj2kLayout(siz, cs.access_cod(), what);
    cs.create();
    for (int y = 0; y < shape.rows; ++y) {
      ojph::ui32 comp = 0;
      const ojph::line_buf* line = cs.pull(comp);
      if (line == nullptr || comp != 0 || line->size < static_cast<std::size_t>(shape.columns)) {
        throw std::runtime_error("row " + std::to_string(y) + " is missing");
      }
      const std::size_t row = static_cast<std::size_t>(y) * shape.columns;
      for (int x = 0; x < shape.columns; ++x) {
        putSample(out, row + x, line->i32[x], shape.bitsAllocated);
      }
    }
    cs.close();
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    const std::string why = e.what();
    // OpenJPH's own handler throws its bare prefix; ours carries the reason.
    throw InputError(what + ": the HTJ2K frame cannot be decoded (" +
                     (why == "ojph error" ? std::string("OpenJPH") : why) +
                     "; corrupt or truncated?)");
  }
  return out;
}

}  // namespace tessera::io_detail
