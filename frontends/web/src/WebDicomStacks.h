#pragma once
// Choosing among the series and stacks of DICOM files opened in the page (a
// dropped folder, or a DICOMweb series the page rebuilt as files): the
// page's pending choice, and what the last open found to choose from.
#include "tessera/core/Volume.h"
#include "tessera/io/ByteSource.h"

namespace tessera::web {

// The picked files read as readVolume reads them; DICOM with the series
// the page chose (tessera_dicom_select: "UID" or "UID:stack", once), its
// series and stacks kept for tessera_dicom_stacks_json.
Volume readPickedVolume(const ByteSource& file, const FileSet& files);

}  // namespace tessera::web
