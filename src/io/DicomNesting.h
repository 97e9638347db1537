#pragma once
// How deep a file's sequences nest, found before DCMTK reads it. DCMTK
// 3.6.7 (Debian 12's) parses a sequence by recursion, several stack frames
// per level (item -> element -> sequence -> item ...), with no limit: a
// crafted file nested some thousands of levels deep overflows the stack
// inside DcmFileFormat::loadFile. So a file nested deeper than
// kMaxSequenceNesting (io/DicomSeries.h) is refused before DCMTK sees it.
#include <filesystem>

namespace tessera::io_detail {

// Throws InputError(sequencesTooDeepMessage(file)) when `file` nests sequences deeper
// than kMaxSequenceNesting in any way DCMTK may read it. `part10`: the file
// has the 128-byte preamble and "DICM" (DCMTK reads its meta information,
// then the dataset in the transfer syntax the meta names); otherwise it is
// a bare dataset, whose syntax DCMTK guesses, so each of implicit VR little
// endian, explicit VR little and big endian is walked. The walk reads only
// element headers (values are skipped, not read; a deflated dataset is
// inflated as it goes) and keeps its own stack, so it is cheap and cannot
// overflow. It follows DCMTK's rules for what is a sequence (explicit SQ;
// implicit VR by DCMTK's data dictionary, private tags by their creator;
// UN, unknown and other non-Pixel-Data elements of undefined length) and
// stops where DCMTK stops reading (an element in a sequence that is no
// item, a delimiter where none belongs, the end of the file).
void checkSequenceNesting(const std::filesystem::path& file, bool part10);

}  // namespace tessera::io_detail
