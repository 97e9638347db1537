#pragma once
// Entry point for loading volumes: picks the reader from the file name, or a
// procedural source from a "gen:" spec.
#include <filesystem>
#include <string>

#include "tessera/core/Volume.h"

namespace tessera {

// Reads `.nii`, `.nii.gz` (NIfTI-1/2), `.nrrd`, `.nhdr`; or generates a
// procedural volume when `spec` starts with "gen:" (see io/Procedural.h).
// Throws InputError naming the file and the problem; never allocates more
// than the file can justify or the host budget allows.
Volume readVolume(const std::string& spec);

}  // namespace tessera
