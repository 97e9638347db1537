#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"
#include "tessera/io/ByteSource.h"

namespace tessera {

// NIfTI-1 and NIfTI-2 (.nii, .nii.gz, and .hdr/.img pairs; ANALYZE 7.5
// .hdr/.img too), parsed from the header bytes in either byte order (not
// through nifticlib, which reads only paths and repairs bad headers
// silently). Supported datatypes: uint8, int8 (widened to i16), uint16,
// int16, float32, int32/uint32/float64 (converted to f32 with a note in the
// description). scl_slope/scl_inter are applied (non-identity scaling gives
// f32). Header dims, datatype and vox_offset are checked against the file
// size (for gzip, against the bytes the stream actually inflates to) before
// the voxel buffer is allocated. The .img of a pair is looked up in `files`.
// A 4-D file (dim[4] > 1: a time series such as fMRI) gives the volume at
// time point `time` (0-based; an InputError naming the count when out of
// range), its description saying which of how many; dim[5..7] must be 1.
Volume readNifti(const ByteSource& file, const FileSet& files, int time = 0);
Volume readNifti(const std::filesystem::path& path, int time = 0);

// The number of time points (dim[4], 1 for a 3-D file) of a NIfTI file,
// from its header alone.
int niftiTimePoints(const ByteSource& file);

}  // namespace tessera
