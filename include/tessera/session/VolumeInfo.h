#pragma once
// A volume's description as one JSON object: dims, spacing, orientation and
// the index -> world (RAS+ mm) affine, type, value range, histogram summary,
// bytes, and for an OME-Zarr store its levels, for a DICOM folder its series.
// What `tessera info --json` prints and the Python module's tessera.info()
// returns, so the two always agree.
#include <string>

#include <nlohmann/json.hpp>

#include "tessera/core/Volume.h"

namespace tessera::session {

// `volume` as read from `spec` (a file, folder, store or URL, whose store
// levels or DICOM series are listed too), or an array's name.
nlohmann::json volumeInfo(const std::string& spec, const Volume& volume, int time = 0,
                          int channel = 0);

}  // namespace tessera::session
