#pragma once
// The volume formats Tessera reads and writes, as one table: readVolume and
// writeVolume look formats up here (by extension, then by content), and the
// CLI's help, `tessera formats`, docs/formats.md and the web page's file
// picker list them from it.
//
// Choosing a reader: a known extension picks its format, unless the bytes
// say otherwise. The sniffers (magic bytes, see each entry) decide when the
// extension is unknown (`scan.dat` holding a NIfTI opens as NIfTI) or when
// it contradicts the content (a `.nrrd` whose bytes are a NIfTI header is
// read as NIfTI, a `.nrrd` that is a PNG is refused naming both). Bytes that
// match no sniffer go to the extension's reader, whose own errors say what
// is wrong with them.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tessera/core/Volume.h"
#include "tessera/io/ByteSource.h"

namespace tessera {

// The first bytes of a file, and when they are gzip, the first bytes of what
// they inflate to: what sniffers look at.
struct ContentPrefix {
  std::vector<std::byte> bytes;     // up to kSniffBytes from the start
  bool gzip = false;                // bytes start with the gzip magic 1f 8b
  std::vector<std::byte> inflated;  // gzip: up to kSniffBytes inflated (fewer if corrupt)
  // The bytes a format's header starts at: `inflated` for gzip, else `bytes`.
  std::string_view header() const;
  std::string_view raw() const;
};
inline constexpr std::size_t kSniffBytes = 4096;
ContentPrefix readContentPrefix(const ByteSource& file);

// How a format is named on the command line.
enum class FormatContainer {
  File,    // a file (with perhaps a companion data file), read from a ByteSource
  Folder,  // a folder of files (DICOM series) or a store (OME-Zarr folder or URL)
  Spec,    // not a file: a generator spec such as gen:sphere
};

struct VolumeFormat {
  std::string id;    // "nifti": stable, for tests and scripts
  std::string name;  // "NIfTI-1/2": for people, and "not a <name> file" errors
  FormatContainer container = FormatContainer::File;
  // Names the format is read from, lower case, longest first where one ends
  // another (".nii.gz" before ".nii"); "gen:" for a spec prefix, "/" for a
  // folder. Unique across the registry.
  std::vector<std::string> extensions;
  // Files that hold only data and are read through a header naming them
  // (".img" beside ".hdr", ".raw" beside ".mhd"): picked with their header in
  // the browser, never chosen on their own.
  std::vector<std::string> companions;
  // The extensions writeVolume writes this format to (empty: read only).
  std::vector<std::string> writeExtensions;
  // Sentence for the table: what the sniffer looks for ("" if none).
  std::string magic;
  // True when `prefix` holds this format's header (header() for formats that
  // may be gzipped as a whole, raw() otherwise). Empty: not identified by
  // content (raw data, folders, specs).
  std::function<bool(const ContentPrefix&)> sniff;
  // Reads one file of this format, the files it names found in `files`.
  // Empty for folders and specs (readVolume(string) handles those).
  std::function<Volume(const ByteSource&, const FileSet&)> read;
  // Formats whose files may hold a time series (4-D NIfTI): how many time
  // points a file holds, and the reader of one of them (0-based; `read`
  // reads time point 0). Empty: one volume per file.
  std::function<int(const ByteSource&)> timePoints;
  std::function<Volume(const ByteSource&, const FileSet&, int time)> readTimePoint;
  // Writes `volume` to `path` (complete or not at all). Empty: read only,
  // and always empty in the browser build (its writers are native).
  std::function<void(const Volume&, const std::filesystem::path&)> write;
  // What writing `volume` in this format loses (see writeLossNotes).
  std::function<std::vector<std::string>(const Volume&)> lossNotes;
  // In one sentence, for the table: what a conversion to it always loses.
  std::string loses;
  // Native libraries it needs beyond what the readers parse themselves
  // ("" if none); the browser build reads only formats that need none to read.
  std::string nativeRead;
  std::string nativeWrite;
  bool browserReads = false;

  bool hasExtension(std::string_view lowerName) const;
};

// Every format, in the order of the table.
const std::vector<VolumeFormat>& volumeFormats();
// By id; nullptr if none.
const VolumeFormat* volumeFormatById(std::string_view id);

// The format whose read extension `name` (a path or file name, any case)
// ends with, the longest match first; nullptr if none.
const VolumeFormat* formatForReadName(const std::string& name);
// The format writeVolume writes `path` as: an extension in writeExtensions,
// a name ending in "/" or ".dcm.d" (DICOM series) or ".ome.zarr"/".zarr"
// (OME-Zarr). nullptr if none.
const VolumeFormat* formatForWriteName(const std::filesystem::path& path);

// The format whose sniffer recognises `prefix`, the first in table order;
// nullptr if none.
const VolumeFormat* sniffFormat(const ContentPrefix& prefix);

// What bytes that are no volume format look like, for error messages:
// "a PNG image (starts 89 50 4e 47)", "text starting 'hello'", "empty", or
// "binary data starting 00 01 ...". Also says "gzip data" for gzip.
std::string describeContent(const ContentPrefix& prefix);

// The reader for `file`: by extension, the sniffer deciding when the
// extension is unknown or contradicts the content (see the top of this
// file). InputError naming the file when nothing reads it.
const VolumeFormat& chooseReadFormat(const ByteSource& file);

// The help texts, from the table: ".nii .nii.gz .hdr ..." (read) and
// ".nrrd .nii ..." (write), and the web page's file picker `accept` list
// (the browser-readable extensions and companions, ".nii.gz" as ".gz" plus
// application/gzip: pickers match the last extension only).
std::string readExtensionsText();
std::string writeExtensionsText();
std::string browserAcceptList();

// The table as text (`tessera formats`) or as the Markdown of docs/formats.md.
std::string formatsTable(bool markdown);

}  // namespace tessera
