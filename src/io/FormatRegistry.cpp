#include "tessera/io/FormatRegistry.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <set>

#include "io/HeaderText.h"
#include "io/Inflater.h"
#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/io/DicomDecoder.h"
#include "tessera/io/MetaImageReader.h"
#include "tessera/io/NiftiReader.h"
#include "tessera/io/NrrdReader.h"
#include "tessera/io/PvmReader.h"
#include "tessera/io/RawSidecarReader.h"
#include "tessera/io/VtiReader.h"
// The writers, DCMTK and the OME-Zarr writer are native only (cmake/Web.cmake
// leaves them out of the browser build): the browser's entries have no
// writer and no loss notes.
#ifndef __EMSCRIPTEN__
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/io/MetaImageWriter.h"
#include "tessera/io/NiftiWriter.h"
#include "tessera/io/NrrdWriter.h"
#include "tessera/io/PvmWriter.h"
#include "tessera/io/RawSidecarWriter.h"
#include "tessera/io/VolumeWriter.h"
#include "tessera/io/VtiWriter.h"
#include "tessera/io/ZarrWriter.h"
#endif

namespace tessera {

namespace fs = std::filesystem;

std::string_view ContentPrefix::header() const {
  const auto& b = gzip ? inflated : bytes;
  return {reinterpret_cast<const char*>(b.data()), b.size()};
}

std::string_view ContentPrefix::raw() const {
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

ContentPrefix readContentPrefix(const ByteSource& file) {
  ContentPrefix p;
  p.bytes.resize(kSniffBytes);
  p.bytes.resize(file.read(0, p.bytes.data(), p.bytes.size()));
  p.gzip = p.bytes.size() >= 2 && p.bytes[0] == std::byte{0x1f} && p.bytes[1] == std::byte{0x8b};
  if (!p.gzip) return p;
  // The first kSniffBytes of the inflated stream; deflate expands, so a few
  // reads of compressed input suffice. Corrupt data leaves what inflated.
  auto inflater = io_detail::Inflater::create();
  p.inflated.resize(kSniffBytes);
  std::vector<std::byte> in(kSniffBytes);
  std::uint64_t offset = 0;
  std::size_t produced = 0;
  for (int round = 0; round < 64 && produced < p.inflated.size(); ++round) {
    const std::size_t n = file.read(offset, in.data(), in.size());
    std::size_t used = 0;
    bool stalled = false;
    while (used < n && produced < p.inflated.size()) {
      const auto step = inflater->inflate(std::span<const std::byte>(in).subspan(used, n - used),
                                          std::span<std::byte>(p.inflated).subspan(produced));
      used += step.consumed;
      produced += step.produced;
      if (!step.error.empty() || step.ended) {
        stalled = true;
        break;
      }
      if (step.consumed == 0 && step.produced == 0) break;
    }
    offset += used;
    if (stalled || n == 0 || used == 0) break;
  }
  p.inflated.resize(produced);
  return p;
}

bool VolumeFormat::hasExtension(std::string_view lowerName) const {
  return std::any_of(extensions.begin(), extensions.end(),
                     [&](const std::string& e) { return lowerName.ends_with(e); });
}

namespace {

bool at(std::string_view s, std::size_t offset, std::string_view magic) {
  return s.size() >= offset + magic.size() && s.substr(offset, magic.size()) == magic;
}

// NIfTI-1: "n+1\0" (one file) or "ni1\0" (.hdr + .img) at byte 344 of the
// 348-byte header; NIfTI-2: "n+2\0"/"ni2\0" at byte 4 of the 540-byte one.
bool sniffNifti(const ContentPrefix& p) {
  const std::string_view h = p.header();
  using namespace std::string_view_literals;
  return at(h, 344, "n+1\0"sv) || at(h, 344, "ni1\0"sv) || at(h, 4, "n+2\0"sv) ||
         at(h, 4, "ni2\0"sv);
}

bool sniffNrrd(const ContentPrefix& p) {
  return at(p.raw(), 0, "NRRD000");
}

bool sniffDicom(const ContentPrefix& p) {
  return at(p.raw(), 128, "DICM");
}

// A MetaImage header is "Key = Value" lines; the first is ObjectType or
// NDims in every writer we know (ITK, VTK, Tessera).
bool sniffMetaImage(const ContentPrefix& p) {
  const std::string_view h = p.raw();
  const std::size_t end = h.find('\n');
  const std::string line = io_detail::trim(h.substr(0, end == std::string_view::npos ? 256 : end));
  for (std::string_view key : {"ObjectType", "NDims"}) {
    if (line.starts_with(key) && io_detail::trim(line.substr(key.size())).starts_with("=")) {
      return true;
    }
  }
  return false;
}

// VTK XML: the root element, after an optional XML declaration or comments.
bool sniffVti(const ContentPrefix& p) {
  const std::string_view h = p.raw().substr(0, 1024);
  const std::size_t first = h.find_first_not_of(" \t\r\n");
  return first != std::string_view::npos && h[first] == '<' &&
         h.find("<VTKFile") != std::string_view::npos;
}

// "PVM", "PVM2", "PVM3" then a newline; or a DDS-compressed PVM.
bool sniffPvm(const ContentPrefix& p) {
  const std::string_view h = p.raw();
  return at(h, 0, "PVM\n") || at(h, 0, "PVM2\n") || at(h, 0, "PVM3\n") || at(h, 0, "DDS v3d\n") ||
         at(h, 0, "DDS v3e\n");
}

std::string pointText(const glm::dvec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", v.x, v.y, v.z);
  return buf;
}

// PVM's header has dims, spacing and components only. writePvm keeps the
// origin in a "tessera origin:" comment that readPvm reads back but other
// PVM readers (V^3) ignore; the direction has no place at all.
std::vector<std::string> pvmLossNotes(const Volume& v) {
  const bool rotated = v.direction() != glm::dmat3(1.0);
  const bool moved = v.origin() != glm::dvec3(0.0);
  if (!rotated && !moved) return {};
  const std::string origin = "origin " + pointText(v.origin());
  if (!rotated) {
    return {"PVM stores spacing only: the " + origin +
            " is kept in a comment that only Tessera reads back"};
  }
  std::string note = "PVM stores spacing only: orientation " +
                     orientationOf(v.direction()).describe() + " is lost (read back as RAS)";
  if (moved) note += ", and the " + origin + " is kept only in a comment Tessera reads back";
  return {note};
}

std::vector<std::string> zarrLossNotes(const Volume& v) {
  if (v.direction() == glm::dmat3(1.0)) return {};
  return {"OME-NGFF (0.4 and 0.5) has no orientation: other readers see the axes of orientation " +
          orientationOf(v.direction()).describe() +
          " as RAS; Tessera reads the direction back from its \"tessera\" attribute"};
}

#ifndef __EMSCRIPTEN__
std::vector<std::string> dicomLossNotes(const Volume& v) {
  if (v.type() != ScalarType::F32 || !v.hasData()) return {};
  // DICOM stores integers with a rescale slope/intercept: f32 is quantised.
  const double error = dicomQuantisationError(v);
  if (error <= 0.0) return {};
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "DICOM stores 16-bit integers with a rescale slope: these f32 values are "
                "quantised, max error %.3g (value range %.6g .. %.6g)",
                error, v.valueRange().min, v.valueRange().max);
  return {buf};
}

// Writers that write one file through writeAtomically; the others
// (NIfTI, PVM, raw, DICOM, OME-Zarr) make their files appear whole themselves.
template <typename Write>
auto atomically(Write write) {
  return [write](const Volume& v, const fs::path& path) {
    writeAtomically(path, [&](const fs::path& temp) { write(v, temp); });
  };
}
#endif

std::vector<VolumeFormat> makeFormats() {
  std::vector<VolumeFormat> f;
  {
    VolumeFormat n;
    n.id = "nifti";
    n.name = "NIfTI";
    n.extensions = {".nii.gz", ".nii", ".hdr.gz", ".hdr"};
    n.companions = {".img.gz", ".img"};
    n.writeExtensions = {".nii.gz", ".nii"};
    n.magic =
        "`n+1`/`ni1` at byte 344 (NIfTI-1) or `n+2`/`ni2` at byte 4 (NIfTI-2), also "
        "inside gzip";
    n.sniff = sniffNifti;
    n.read = [](const ByteSource& s, const FileSet& fs) { return readNifti(s, fs); };
    n.timePoints = [](const ByteSource& s) { return niftiTimePoints(s); };
    n.readTimePoint = [](const ByteSource& s, const FileSet& fs, int t) {
      return readNifti(s, fs, t);
    };
    n.loses = "nothing (sform and qform hold the affine)";
    n.nativeWrite = "nifticlib, zlib";
    n.browserReads = true;
#ifndef __EMSCRIPTEN__
    n.write = [](const Volume& v, const fs::path& p) { writeNifti(v, p); };
#endif
    f.push_back(std::move(n));
  }
  {
    VolumeFormat n;
    n.id = "nrrd";
    n.name = "NRRD";
    n.extensions = {".nrrd", ".nhdr"};
    n.companions = {".raw.gz", ".raw"};
    n.writeExtensions = {".nrrd"};
    n.magic = "`NRRD000` at byte 0";
    n.sniff = sniffNrrd;
    n.read = [](const ByteSource& s, const FileSet& fs) { return readNrrd(s, fs); };
    n.loses = "nothing (space directions and origin hold the affine)";
    n.nativeWrite = "zlib";
    n.browserReads = true;
#ifndef __EMSCRIPTEN__
    n.write = atomically([](const Volume& v, const fs::path& p) { writeNrrd(v, p, true); });
#endif
    f.push_back(std::move(n));
  }
  {
    VolumeFormat n;
    n.id = "metaimage";
    n.name = "MetaImage";
    n.extensions = {".mha", ".mhd"};
    n.companions = {".zraw"};
    n.writeExtensions = {".mha"};
    n.magic = "first line `ObjectType = ...` or `NDims = ...`";
    n.sniff = sniffMetaImage;
    n.read = [](const ByteSource& s, const FileSet& fs) { return readMetaImage(s, fs); };
    n.loses = "nothing (TransformMatrix and Offset hold the affine)";
    n.nativeWrite = "zlib";
    n.browserReads = true;
#ifndef __EMSCRIPTEN__
    n.write = atomically([](const Volume& v, const fs::path& p) { writeMetaImage(v, p, true); });
#endif
    f.push_back(std::move(n));
  }
  {
    VolumeFormat n;
    n.id = "vti";
    n.name = "VTK ImageData";
    n.extensions = {".vti"};
    n.writeExtensions = {".vti"};
    n.magic = "`<VTKFile` root element";
    n.sniff = sniffVti;
    n.read = [](const ByteSource& s, const FileSet&) { return readVti(s); };
    n.loses = "nothing (Origin, Spacing and Direction hold the affine)";
    n.nativeWrite = "zlib";
    n.browserReads = true;
#ifndef __EMSCRIPTEN__
    n.write = atomically([](const Volume& v, const fs::path& p) { writeVti(v, p, true); });
#endif
    f.push_back(std::move(n));
  }
  {
    VolumeFormat n;
    n.id = "pvm";
    n.name = "PVM";
    n.extensions = {".pvm"};
    n.writeExtensions = {".pvm"};
    n.magic = "a `PVM`, `PVM2` or `PVM3` line at byte 0, or `DDS v3d`/`DDS v3e` (DDS-compressed)";
    n.sniff = sniffPvm;
    n.read = [](const ByteSource& s, const FileSet&) { return readPvm(s); };
    n.lossNotes = pvmLossNotes;
    n.loses = "orientation (spacing only; the origin only in a comment Tessera reads back)";
    n.browserReads = true;
#ifndef __EMSCRIPTEN__
    n.write = [](const Volume& v, const fs::path& p) { writePvm(v, p); };
#endif
    f.push_back(std::move(n));
  }
  {
    VolumeFormat n;
    n.id = "raw";
    n.name = "raw + JSON sidecar";
    n.extensions = {".raw", ".json"};
    n.writeExtensions = {".raw"};
    // Raw data has no header to recognise; its sidecar is found by name.
    n.read = [](const ByteSource& s, const FileSet& fs) { return readRawWithSidecar(s, fs); };
    n.loses = "nothing (the sidecar holds the affine)";
    n.browserReads = true;
#ifndef __EMSCRIPTEN__
    n.write = [](const Volume& v, const fs::path& p) { writeRawWithSidecar(v, p); };
#endif
    f.push_back(std::move(n));
  }
  {
    VolumeFormat n;
    n.id = "dicom";
    n.name = "DICOM";
    n.extensions = {".dcm", ".ima", "/"};
    n.writeExtensions = {"/", ".dcm.d"};
    n.magic = "`DICM` at byte 128 (Part-10); a folder of such files";
    n.sniff = sniffDicom;
    n.read = [](const ByteSource& s, const FileSet& fs) { return readDicom(s, fs, ""); };
    n.loses = "f32 precision (16-bit integers with a rescale slope)";
    n.nativeRead =
        "DCMTK for JPEG, JPEG-LS and deflate, OpenJPEG for JPEG 2000, OpenJPH for HTJ2K (the basic "
        "reader needs none)";
    n.nativeWrite = "DCMTK";
    n.browserReads = true;
#ifndef __EMSCRIPTEN__
    n.write = [](const Volume& v, const fs::path& p) { writeDicomSeries(v, p); };
    n.lossNotes = dicomLossNotes;
#endif
    f.push_back(std::move(n));
  }
  {
    VolumeFormat n;
    n.id = "ome-zarr";
    n.name = "OME-Zarr";
    n.container = FormatContainer::Folder;
    n.extensions = {".ome.zarr", ".zarr", "http://", "https://"};
    n.writeExtensions = {".ome.zarr", ".zarr"};
    n.magic =
        "a folder with `.zgroup`, `.zattrs`, `.zarray` or `zarr.json` (any name), or an http(s) "
        "URL";
    n.lossNotes = zarrLossNotes;
    n.loses = "orientation for other readers (NGFF 0.4 and 0.5 have none; Tessera keeps it)";
    n.nativeRead = "zlib, zstd, blosc; libcurl for URLs (the page: fetch, pako, numcodecs)";
    n.nativeWrite = "zlib, zstd, blosc";
    n.browserReads = true;
#ifndef __EMSCRIPTEN__
    n.write = [](const Volume& v, const fs::path& p) { writeOmeZarr(v, p); };
#endif
    f.push_back(std::move(n));
  }
  {
    VolumeFormat n;
    n.id = "procedural";
    n.name = "generated";
    n.container = FormatContainer::Spec;
    n.extensions = {"gen:"};
    n.magic = "`gen:sphere`, `gen:shepp-logan`, `gen:marschner-lobb` (`:N` for the size)";
    n.browserReads = true;
    f.push_back(std::move(n));
  }
  return f;
}

std::string lowerName(const std::string& name) {
  return io_detail::lower(name);
}

// What is not a volume but often lands where one was expected.
struct KnownContent {
  std::string_view magic;
  const char* what;
};
constexpr KnownContent kNotVolumes[] = {
    {"\x89PNG\r\n\x1a\n", "a PNG image"},
    {"\xff\xd8\xff", "a JPEG image"},
    {"GIF8", "a GIF image"},
    {"II*", "a TIFF image"},
    {std::string_view("MM\0*", 4), "a TIFF image"},
    {"%PDF", "a PDF document"},
    {"PK\x03\x04", "a ZIP archive"},
    {"BZh", "bzip2 data"},
    {"\xfd"
     "7zXZ",
     "xz data"},
    {"\x28\xb5\x2f\xfd", "zstd data"},
};

std::string hexStart(std::string_view s) {
  std::string out;
  char buf[4];
  for (std::size_t i = 0; i < std::min<std::size_t>(8, s.size()); ++i) {
    std::snprintf(buf, sizeof buf, "%s%02x", i ? " " : "", static_cast<unsigned char>(s[i]));
    out += buf;
  }
  return out;
}

const char* knownNonVolume(std::string_view s) {
  for (const KnownContent& k : kNotVolumes) {
    if (s.starts_with(k.magic)) return k.what;
  }
  const std::string head = io_detail::lower(s.substr(0, 64));
  if (head.find("<!doctype html") != std::string::npos || head.find("<html") != std::string::npos) {
    return "an HTML page";
  }
  return nullptr;
}

std::string joined(const std::vector<std::string>& items, const std::string& sep) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : sep) + s;
  return out;
}

}  // namespace

const std::vector<VolumeFormat>& volumeFormats() {
  static const std::vector<VolumeFormat> formats = makeFormats();
  return formats;
}

const VolumeFormat* volumeFormatById(std::string_view id) {
  for (const VolumeFormat& f : volumeFormats()) {
    if (f.id == id) return &f;
  }
  return nullptr;
}

const VolumeFormat* formatForReadName(const std::string& name) {
  const std::string lower = lowerName(fs::path(name).filename().string());
  const VolumeFormat* best = nullptr;
  std::size_t bestLength = 0;
  for (const VolumeFormat& f : volumeFormats()) {
    if (f.container != FormatContainer::File) continue;
    for (const std::string& e : f.extensions) {
      if (e.size() > bestLength && e != "/" && lower.ends_with(e)) {
        best = &f;
        bestLength = e.size();
      }
    }
  }
  return best;
}

const VolumeFormat* formatForWriteName(const fs::path& path) {
  std::string text = path.string();
  // A folder name: OME-Zarr when it ends in .zarr (with or without "/").
  std::string trimmed = text;
  while (!trimmed.empty() && trimmed.back() == '/') trimmed.pop_back();
  const std::string lower = lowerName(trimmed);
  const std::string lowerFile = lowerName(path.filename().string());
  const VolumeFormat* best = nullptr;
  std::size_t bestLength = 0;
  for (const VolumeFormat& f : volumeFormats()) {
    for (const std::string& e : f.writeExtensions) {
      const bool match =
          e == "/" ? (!text.empty() && text.back() == '/')
                   : (f.container == FormatContainer::Folder ? lower : lowerFile).ends_with(e);
      if (match && e.size() > bestLength) {
        best = &f;
        bestLength = e.size();
      }
    }
  }
  // "/" is the shortest write extension: "x.ome.zarr/" stays OME-Zarr.
  return best;
}

const VolumeFormat* sniffFormat(const ContentPrefix& prefix) {
  for (const VolumeFormat& f : volumeFormats()) {
    if (f.sniff && f.sniff(prefix)) return &f;
  }
  return nullptr;
}

std::string describeContent(const ContentPrefix& prefix) {
  const std::string_view s = prefix.raw();
  if (s.empty()) return "empty";
  if (prefix.gzip) {
    const std::string_view inner = prefix.header();
    if (const char* what = knownNonVolume(inner)) return std::string("gzip data holding ") + what;
    return "gzip data (inflating to " +
           (inner.empty() ? std::string("nothing readable") : "bytes starting " + hexStart(inner)) +
           ")";
  }
  if (const char* what = knownNonVolume(s))
    return std::string(what) + " (starts " + hexStart(s) + ")";
  const std::string_view start = s.substr(0, 64);
  const bool text = std::all_of(start.begin(), start.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return u == '\t' || u == '\n' || u == '\r' || (u >= 0x20 && u < 0x7f);
  });
  if (text) {
    const std::size_t eol = start.find('\n');
    return "text starting '" + io_detail::printable(start.substr(0, eol), 40) + "'";
  }
  return "binary data starting " + hexStart(s);
}

const VolumeFormat& chooseReadFormat(const ByteSource& file) {
  const ContentPrefix prefix = readContentPrefix(file);
  const std::string lower = lowerName(fs::path(file.name()).filename().string());
  const VolumeFormat* byName = formatForReadName(file.name());
  const VolumeFormat* byContent = sniffFormat(prefix);
  if (byName != nullptr) {
    if (byContent == byName) return *byName;
    // The bytes are another format's: they, not the name, say how to read it.
    if (byContent != nullptr && byContent->read) return *byContent;
    // A name that promises gzip on bytes that are not gzip.
    if (lower.ends_with(".gz") && !prefix.gzip) {
      std::string ext;
      for (const std::string& e : byName->extensions) {
        if (lower.ends_with(e) && e.size() > ext.size()) ext = e;
      }
      throw InputError(file.name() + ": named " + ext + " (gzip-compressed " + byName->name +
                       ") but its bytes are not gzip: " + describeContent(prefix));
    }
    // Something well known that is no volume: say so instead of a parse error.
    if (const char* what = knownNonVolume(prefix.header())) {
      throw InputError(
          file.name() + ": not a " + byName->name + " file: its bytes are " +
          (prefix.gzip ? std::string("gzip data holding ") + what : describeContent(prefix)));
    }
    // Unrecognised bytes: the format's reader says what is wrong with them.
    return *byName;
  }
  if (byContent != nullptr && byContent->read) return *byContent;
  throw InputError(file.name() + ": unknown volume format (supported: " + readExtensionsText() +
                   "; its bytes are " + describeContent(prefix) + ")");
}

std::string readExtensionsText() {
  std::vector<std::string> extensions;
  std::vector<std::string> others;
  for (const VolumeFormat& f : volumeFormats()) {
    switch (f.container) {
      case FormatContainer::File:
        for (const std::string& e : f.extensions) {
          if (e != "/") extensions.push_back(e);
        }
        if (f.sniff &&
            std::find(f.extensions.begin(), f.extensions.end(), "/") != f.extensions.end()) {
          others.push_back("a " + f.name + " file of any name or a folder of them");
        }
        break;
      case FormatContainer::Folder:
        others.push_back("an " + f.name + " store (folder or http(s):// URL)");
        break;
      case FormatContainer::Spec:
        others.push_back("gen:sphere|shepp-logan|marschner-lobb[:N]");
        break;
    }
  }
  std::string text = joined(extensions, " ");
  for (std::size_t i = 0; i < others.size(); ++i) {
    text += (i + 1 == others.size() ? ", or " : ", ") + others[i];
  }
  return text;
}

std::string writeExtensionsText() {
  std::vector<std::string> items;
  for (const VolumeFormat& f : volumeFormats()) {
    for (const std::string& e : f.writeExtensions) {
      if (e == "/") {
        items.push_back("FOLDER/ (" + f.name + " series)");
      } else if (e == ".dcm.d") {
        items.push_back("NAME.dcm.d (" + f.name + " series)");
      } else if (f.container == FormatContainer::Folder) {
        items.push_back("NAME" + e + " (" + f.name + ")");
      } else {
        items.push_back(e);
      }
    }
  }
  return joined(items, " ");
}

std::string browserAcceptList() {
  std::vector<std::string> items;
  bool gzip = false;
  auto add = [&](const std::string& e) {
    // File pickers match the last extension only: ".nii.gz" is ".gz".
    const std::string last = e.substr(e.rfind('.'));
    gzip = gzip || last == ".gz";
    if (std::find(items.begin(), items.end(), last) == items.end()) items.push_back(last);
  };
  for (const VolumeFormat& f : volumeFormats()) {
    if (!f.browserReads || f.container != FormatContainer::File) continue;
    for (const std::string& e : f.extensions) {
      if (e != "/") add(e);
    }
    for (const std::string& e : f.companions) add(e);
  }
  if (gzip) items.push_back("application/gzip");
  return joined(items, ",");
}

std::string formatsTable(bool markdown) {
  const std::vector<std::string> head = {
      "Format",           "Read",   "Write", "Content sniffer", "Conversion loses",
      "Native libraries", "Browser"};
  std::vector<std::vector<std::string>> rows;
  auto code = [&](const std::vector<std::string>& items) {
    std::vector<std::string> out;
    for (const std::string& s : items) out.push_back(markdown ? "`" + s + "`" : s);
    return out.empty() ? std::string("-") : joined(out, " ");
  };
  for (const VolumeFormat& f : volumeFormats()) {
    std::vector<std::string> read;
    for (const std::string& e : f.extensions) read.push_back(e == "/" ? "FOLDER/" : e);
    for (const std::string& c : f.companions) read.push_back("+" + c);
    std::string natives;
    if (!f.nativeRead.empty()) natives += "read: " + f.nativeRead;
    if (!f.nativeWrite.empty())
      natives += (natives.empty() ? "" : "; ") + ("write: " + f.nativeWrite);
    std::string magic = f.magic;
    if (!markdown) magic.erase(std::remove(magic.begin(), magic.end(), '`'), magic.end());
    std::string browser = f.browserReads ? "reads" : "-";
    if (f.id == "dicom")
      browser = "reads (basic decoder; JPEG, JPEG-LS, JPEG 2000, HTJ2K through npm's decoders)";
    if (f.id == "ome-zarr") browser = "reads URLs";
    std::vector<std::string> write;
    for (const std::string& e : f.writeExtensions) write.push_back(e == "/" ? "FOLDER/" : e);
    rows.push_back({f.name, code(read), code(write), magic.empty() ? "-" : magic,
                    f.writeExtensions.empty() ? "-" : f.loses, natives.empty() ? "none" : natives,
                    browser});
  }
  std::string out;
  if (markdown) {
    auto line = [&](const std::vector<std::string>& cells) {
      std::string l = "|";
      for (const std::string& c : cells) l += " " + c + " |";
      return l + "\n";
    };
    out += line(head);
    out += line(std::vector<std::string>(head.size(), "---"));
    for (const auto& r : rows) out += line(r);
    return out;
  }
  // Text: one block per format, as a terminal is narrower than the table.
  for (const auto& r : rows) {
    out += r[0] + "\n";
    for (std::size_t c = 1; c < head.size(); ++c) {
      char label[24];
      std::snprintf(label, sizeof label, "  %-18s", (head[c] + ":").c_str());
      out += label + r[c] + "\n";
    }
  }
  return out;
}

}  // namespace tessera
