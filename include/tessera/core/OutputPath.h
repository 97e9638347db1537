#pragma once
// Where an output file goes when its path names something other than a
// file: writers that write a temporary sibling and rename it into place
// (a reader never sees half a file) write such a path directly instead.
#include <filesystem>

namespace tessera {

// Whether `path` exists and is neither a regular file nor a folder (after
// symbolic links): a character device such as /dev/null or /dev/stdout, a
// FIFO, a socket. Renaming a finished file over it would replace the
// device with that file (as root, /dev/null itself), so output is written
// straight to it.
bool writesInPlace(const std::filesystem::path& path);

}  // namespace tessera
