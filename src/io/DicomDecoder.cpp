#include "tessera/io/DicomDecoder.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>

#include "tessera/core/Error.h"

namespace tessera {

namespace {

namespace fs = std::filesystem;

// PS3.5 A.1: a dataset without file meta information is implicit VR little endian.
constexpr const char* kImplicitLittleEndian = "1.2.840.10008.1.2";

std::uint16_t u16(const std::byte* p) {
  return static_cast<std::uint16_t>(std::to_integer<unsigned>(p[0]) |
                                    (std::to_integer<unsigned>(p[1]) << 8));
}
std::uint32_t u32(const std::byte* p) {
  return static_cast<std::uint32_t>(u16(p)) | (static_cast<std::uint32_t>(u16(p + 2)) << 16);
}

std::string syntaxOrDefault(std::string uid) {
  return uid.empty() ? kImplicitLittleEndian : uid;
}

}  // namespace

bool hasDicomMarker(const ByteSource& file) {
  std::array<char, 4> marker{};
  return file.read(128, reinterpret_cast<std::byte*>(marker.data()), marker.size()) == 4 &&
         std::memcmp(marker.data(), "DICM", 4) == 0;
}

std::string dicomTransferSyntaxOf(const ByteSource& file) {
  if (!hasDicomMarker(file)) return "";
  // The file meta group (0002,xxxx) is explicit VR little endian (PS3.10
  // 7.1); it is small, so its first few KiB hold (0002,0010).
  std::vector<std::byte> meta(8192);
  meta.resize(file.read(132, meta.data(), meta.size()));
  std::size_t at = 0;
  while (at + 8 <= meta.size()) {
    const std::uint16_t group = u16(&meta[at]);
    const std::uint16_t element = u16(&meta[at + 2]);
    if (group != 0x0002) break;
    const char vr[2] = {static_cast<char>(meta[at + 4]), static_cast<char>(meta[at + 5])};
    const std::string_view v(vr, 2);
    const bool longForm = v == "OB" || v == "OW" || v == "OF" || v == "SQ" || v == "UT" ||
                          v == "UN" || v == "UC" || v == "UR" || v == "OD" || v == "OL";
    std::uint64_t length = 0;
    std::size_t value = 0;
    if (longForm) {
      if (at + 12 > meta.size()) break;
      length = u32(&meta[at + 8]);
      value = at + 12;
    } else {
      length = u16(&meta[at + 6]);
      value = at + 8;
    }
    if (value + length > meta.size()) break;
    if (element == 0x0010) {
      std::string uid(reinterpret_cast<const char*>(&meta[value]), length);
      // UIDs are padded to even length with NUL (PS3.5 9.1).
      while (!uid.empty() && (uid.back() == '\0' || uid.back() == ' ')) uid.pop_back();
      return uid;
    }
    at = value + length;
  }
  return "";
}

const DicomDecoder* chooseDicomDecoder(const std::vector<const DicomDecoder*>& decoders,
                                       const std::vector<std::string>& transferSyntaxUids,
                                       const FileSet& files) {
  const DicomDecoder* fallback = nullptr;
  for (const DicomDecoder* d : decoders) {
    if (!d->canRead(files)) continue;
    if (fallback == nullptr) fallback = d;
    const bool all = std::all_of(transferSyntaxUids.begin(), transferSyntaxUids.end(),
                                 [&](const std::string& uid) { return d->canDecode(uid); });
    if (all) return d;
  }
  return fallback;
}

const std::vector<const DicomDecoder*>& dicomDecoders() {
  static const std::vector<const DicomDecoder*> decoders = {
#ifndef __EMSCRIPTEN__
      &dcmtkDicomDecoder(),
#endif
      &basicDicomDecoder()};
  return decoders;
}

Volume readDicom(const ByteSource& named, const FileSet& files, const std::string& seriesUid) {
  // The syntaxes of the files the series may come from: the named file and
  // the Part-10 files beside it (others are skipped by both readers).
  std::vector<std::string> syntaxes = {syntaxOrDefault(dicomTransferSyntaxOf(named))};
  for (const std::string& beside : files.filesBeside(named)) {
    try {
      const auto f = files.open(beside);
      if (hasDicomMarker(*f)) syntaxes.push_back(syntaxOrDefault(dicomTransferSyntaxOf(*f)));
    } catch (const InputError&) {
      // Unreadable files beside it are the decoder's to report or skip.
    }
  }
  std::sort(syntaxes.begin(), syntaxes.end());
  syntaxes.erase(std::unique(syntaxes.begin(), syntaxes.end()), syntaxes.end());
  const DicomDecoder* d = chooseDicomDecoder(dicomDecoders(), syntaxes, files);
  if (d == nullptr) {
    throw InputError(named.name() + ": no DICOM reader of this build reads these files");
  }
  return d->read(named, files, seriesUid);
}

Volume readDicomFolder(const fs::path& folderOrFile, const std::string& seriesUid) {
  std::vector<std::string> syntaxes;
  std::error_code ec;
  const fs::path folder =
      fs::is_directory(folderOrFile, ec) ? folderOrFile : folderOrFile.parent_path();
  if (!fs::is_directory(folderOrFile, ec)) {
    syntaxes.push_back(syntaxOrDefault(dicomTransferSyntaxOf(FileSource(folderOrFile))));
  }
  for (fs::directory_iterator it(folder.empty() ? fs::path(".") : folder, ec), end;
       !ec && it != end; it.increment(ec)) {
    if (!it->is_regular_file(ec)) continue;
    try {
      const FileSource f(it->path());
      if (hasDicomMarker(f)) syntaxes.push_back(syntaxOrDefault(dicomTransferSyntaxOf(f)));
    } catch (const InputError&) {
      // Unreadable files are the decoder's to report or skip.
    }
  }
  std::sort(syntaxes.begin(), syntaxes.end());
  syntaxes.erase(std::unique(syntaxes.begin(), syntaxes.end()), syntaxes.end());
  // Every decoder reads files on disk.
  const FolderFiles disk;
  const DicomDecoder* d = chooseDicomDecoder(dicomDecoders(), syntaxes, disk);
  if (d == nullptr) {
    throw InputError(folderOrFile.string() + ": no DICOM reader of this build reads these files");
  }
  return d->readFolder(folderOrFile, seriesUid);
}

}  // namespace tessera
