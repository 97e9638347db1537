// The page's series and stack choice for DICOM files (WebDicomStacks.h):
// the same selection as the CLI's --series ("UID" or "UID:stack",
// DicomSeriesInfo::selector), read by the same series code
// (io/DicomSeries.cpp, io/DicomMultiFrame.cpp) through the basic reader.
#include "WebDicomStacks.h"

#include <string>
#include <utility>
#include <vector>

#include "WebExports.h"
#include "tessera/core/Error.h"
#include "tessera/io/DicomBasicReader.h"
#include "tessera/io/DicomDecoder.h"
#include "tessera/io/VolumeReader.h"

namespace tessera::web {

namespace {

struct DicomChoice {
  std::string pending;  // for the next open only
  std::string name;     // the file the last list is of (a time series skips this reader)
  std::vector<DicomSeriesInfo> listed;
  std::string read;  // the selector of what the last open read
};

DicomChoice& choice() {
  static DicomChoice c;
  return c;
}

}  // namespace

Volume readPickedVolume(const ByteSource& file, const FileSet& files) {
  DicomChoice& c = choice();
  const std::string selection = std::exchange(c.pending, "");
  c.name = file.name();
  if (!hasDicomMarker(file)) {
    if (!selection.empty()) {
      throw InputError(file.name() + ": a DICOM series (" + selection +
                       ") was asked for, but this is not DICOM");
    }
    c.listed.clear();
    c.read.clear();
    return readVolume(file, files);
  }
  Volume v = readDicom(file, files, selection);
  c.listed = listDicomSeriesBasic(file, files);
  c.read.clear();
  for (const DicomSeriesInfo& s : c.listed) {
    if (v.description().starts_with("DICOM series " + s.selector() + " ")) c.read = s.selector();
  }
  return v;
}

}  // namespace tessera::web

using namespace tessera;

extern "C" {

// The series for the next tessera_load_files ("UID" or "UID:stack"; "" the
// default: the series of the first file, its largest stack).
EMSCRIPTEN_KEEPALIVE void tessera_dicom_select(const char* selector) {
  web::choice().pending = selector ? selector : "";
}

// What the last open found: {"name": the file read, "read": selector,
// "series": [{"select",
// "series_instance_uid", "stack", "slices", "description"}, ...]} (empty
// when it was not DICOM), the largest first.
EMSCRIPTEN_KEEPALIVE const char* tessera_dicom_stacks_json() {
  const web::DicomChoice& c = web::choice();
  nlohmann::json list = nlohmann::json::array();
  for (const DicomSeriesInfo& s : c.listed) {
    list.push_back({{"select", s.selector()},
                    {"series_instance_uid", s.seriesInstanceUid},
                    {"stack", s.stack},
                    {"slices", s.slices},
                    {"description", s.description}});
  }
  return web::jsonOut({{"name", c.name}, {"read", c.read}, {"series", list}});
}

}  // extern "C"
