#include "io/Jpeg2000Frame.h"

#include "io/Htj2kFrame.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>

#include <openjpeg.h>

#include "tessera/core/Error.h"

namespace tessera::io_detail {

namespace {

std::string dims(long long w, long long h) {
  return std::to_string(w) + "x" + std::to_string(h);
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

// HTJ2K (T.814) codestreams carry a CAP marker (0xff50) in the main header,
// between SIZ and the first tile part (SOT, 0xff90); named so in messages.
bool isHtj2k(std::span<const std::uint8_t> d) {
  if (d.size() < 6 || d[0] != 0xff || d[1] != 0x4f) return false;
  std::size_t at = 4 + ((static_cast<std::size_t>(d[4]) << 8) | d[5]);
  for (int markers = 0; markers < 64 && at + 4 <= d.size() && d[at] == 0xff; ++markers) {
    if (d[at + 1] == 0x50) return true;
    if (d[at + 1] == 0x90) return false;
    at += 2 + ((static_cast<std::size_t>(d[at + 2]) << 8) | d[at + 3]);
  }
  return false;
}

}  // namespace

void checkFrameHeader(const FrameShape& shape, const std::string& what, const std::string& codec,
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

void putFrameSample(std::vector<std::uint8_t>& out, std::size_t index, std::int32_t value,
                    int bits) {
  if (bits == 8) {
    out[index] = static_cast<std::uint8_t>(static_cast<std::uint32_t>(value) & 0xffu);
    return;
  }
  const auto v = static_cast<std::uint16_t>(static_cast<std::uint32_t>(value) & 0xffffu);
  std::memcpy(out.data() + 2 * index, &v, 2);
}

std::vector<std::uint8_t> frameSamples(const FrameShape& shape, const std::string& what) {
  if (shape.bitsAllocated != 8 && shape.bitsAllocated != 16) {
    throw InputError(what + ": Bits Allocated is " + std::to_string(shape.bitsAllocated) +
                     "; compressed frames are read with 8 or 16");
  }
  return std::vector<std::uint8_t>(static_cast<std::size_t>(shape.rows) * shape.columns *
                                   (shape.bitsAllocated / 8));
}

std::vector<std::uint8_t> decodeHtj2kSyntaxFrame(std::span<const std::uint8_t> codestream,
                                                 const FrameShape& shape, const std::string& what) {
  const bool partOne = codestream.size() >= 2 && codestream[0] == 0xff && codestream[1] == 0x4f &&
                       !isHtj2k(codestream);
  return partOne ? decodeJpeg2000Frame(codestream, shape, what)
                 : decodeHtj2kFrame(codestream, shape, what);
}

std::vector<std::uint8_t> decodeJpeg2000Frame(std::span<const std::uint8_t> codestream,
                                              const FrameShape& shape, const std::string& what) {
  // Debian 12's OpenJPEG (2.5.0) aborts on an assertion in its HT block
  // decoder for corrupt HTJ2K code-block data (found by scripts/fuzz.sh), so
  // an HTJ2K codestream goes to OpenJPH whatever syntax the file declares.
  if (isHtj2k(codestream)) return decodeHtj2kFrame(codestream, shape, what);
  std::vector<std::uint8_t> out = frameSamples(shape, what);
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
  const std::string codecName = "JPEG 2000";
  const auto failed = [&](const std::string& step) {
    return InputError(what + ": the " + codecName + " frame cannot be decoded (" + step +
                      (error.empty() ? "" : ": " + error) + "; corrupt or truncated?)");
  };
  if (!opj_setup_decoder(codec.get(), &params)) throw failed("decoder setup");
  opj_image_t* raw = nullptr;
  const bool header = opj_read_header(stream.get(), codec.get(), &raw) != 0;
  std::unique_ptr<opj_image_t, ImageFree> image(raw);
  if (!header || !image) throw failed("its header");
  const opj_image_comp_t* c = image->numcomps > 0 ? &image->comps[0] : nullptr;
  checkFrameHeader(shape, what, codecName, static_cast<long long>(image->x1) - image->x0,
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
  for (std::size_t i = 0; i < n; ++i) putFrameSample(out, i, comp.data[i], shape.bitsAllocated);
  return out;
}

}  // namespace tessera::io_detail
