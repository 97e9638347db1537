// Multi-frame objects as slices (see framesOf in DicomSeries.h): each frame
// becomes one Slice, so that the series assembly sorts, checks and places
// frames exactly as it does single-frame files.
//
// Enhanced objects (Enhanced CT/MR/PET, Legacy Converted Enhanced; PS3.3
// C.7.6.16) place each frame through functional groups: a macro in the
// Per-frame Functional Groups Sequence item of the frame overrides the same
// macro in the Shared Functional Groups Sequence. Read here: Plane Position
// (Patient) (C.7.6.16.2.3), Plane Orientation (Patient) (C.7.6.16.2.4),
// Pixel Measures (C.7.6.16.2.1), Pixel Value Transformation (C.7.6.16.2.9),
// Frame VOI LUT (C.7.6.16.2.10) and Frame Content's Stack ID and In-Stack
// Position Number (C.7.6.16.2.2). Classic multi-frame objects (NM, RT Dose,
// CT/MR written with Number of Frames) have one plane for the first frame
// and a step: Grid Frame Offset Vector (RT Dose, C.8.8.3.2), else Spacing
// Between Slices, else Slice Thickness, along the plane's normal.
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "io/DicomSeries.h"

namespace tessera::io_detail {

namespace {

// No object holds more frames than this (a 4D cardiac MR has some
// thousands); a header claiming more while its pixel data's size is unknown
// (DICOMweb metadata) is refused before a slice is made per frame: at about
// half a KiB per slice, 32 MiB of headers at most (a 20-byte DICOM JSON
// header could otherwise make a million).
constexpr long kMostFrames = 1 << 16;

std::string count(std::uint64_t n, const char* what) {
  return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
}

std::uint64_t frameBytesOf(const Slice& s) {
  return static_cast<std::uint64_t>(s.rows) * static_cast<std::uint64_t>(s.columns) *
         static_cast<std::uint64_t>(s.bitsAllocated / 8);
}

// Why Number of Frames cannot be believed, before a slice is made per frame:
// it must match the per-frame functional groups, the native pixel data's
// length (whole frames; less than a frame more is padding) and the
// fragments of encapsulated data (each frame has one at least, PS3.5 A.4).
std::string frameCountProblem(const Slice& s, std::size_t perFrameItems, bool enhanced) {
  const std::string declared = "Number of Frames (0028,0008) is " + std::to_string(s.frames);
  if (s.frames < 1) return declared + "; an image has one frame at least";
  if (enhanced && perFrameItems != static_cast<std::size_t>(s.frames)) {
    return declared + ", but the Per-frame Functional Groups Sequence (5200,9230) has " +
           count(perFrameItems, "item") + " (one per frame)";
  }
  const std::uint64_t frameBytes = frameBytesOf(s);
  const auto frames = static_cast<std::uint64_t>(s.frames);
  if (s.pixelBytes && frameBytes > 0) {
    const std::uint64_t whole = *s.pixelBytes / frameBytes;
    const std::string held = "the pixel data has " + std::to_string(*s.pixelBytes) + " bytes, " +
                             count(whole, "whole frame") + " of " + std::to_string(s.columns) +
                             "x" + std::to_string(s.rows) + " x " +
                             std::to_string(s.bitsAllocated / 8) + " bytes";
    if (whole < frames) {
      return declared + ", but " + held + ": frame " + std::to_string(whole + 1) +
             " has no pixels (truncated, or Number of Frames wrong)";
    }
    if (whole > frames) return declared + ", but " + held + " (Number of Frames wrong?)";
  }
  if (s.fragments && *s.fragments < frames) {
    return declared + ", but the encapsulated pixel data has " + count(*s.fragments, "fragment") +
           " (each frame needs one at least): frame " + std::to_string(*s.fragments + 1) +
           " has no pixels";
  }
  if (!s.pixelBytes && !s.fragments && s.frames > kMostFrames) {
    return declared + ", more than the " + std::to_string(kMostFrames) + " read";
  }
  return "";
}

// The first item of `macro` within a functional-groups item, or nullptr.
std::unique_ptr<DicomAttributes> macroOf(const DicomAttributes* group, DicomTag macro) {
  if (group == nullptr) return nullptr;
  auto items = group->items(macro);
  if (items.empty()) return nullptr;
  return std::move(items.front());
}

// Reads one macro's attributes into frame `f`; a malformed value is the
// frame's defect, naming it.
void readMacro(const DicomAttributes* group, DicomTag macro, Slice& f) {
  const auto item = macroOf(group, macro);
  if (!item) return;
  const bool clean = f.defect.empty();
  readPlaneAttributes(*item, f);
  if (clean && !f.defect.empty())
    f.defect = "frame " + std::to_string(f.frame + 1) + ": " + f.defect;
}

// The macros that place a frame, shared first so that the frame's own win.
constexpr DicomTag kPlacingMacros[] = {
    kTagPixelMeasuresSequence, kTagPlaneOrientationSequence, kTagPlanePositionSequence,
    kTagPixelValueTransformationSequence, kTagFrameVoiLutSequence};

std::vector<Slice> enhancedFrames(const Slice& header, const DicomAttributes* shared,
                                  const std::vector<std::unique_ptr<DicomAttributes>>& perFrame) {
  std::vector<Slice> frames;
  frames.reserve(perFrame.size());
  for (std::size_t k = 0; k < perFrame.size(); ++k) {
    Slice f = header;
    f.frame = static_cast<int>(k);
    // Enhanced objects keep the plane in the functional groups only.
    f.position.reset();
    f.instanceNumber = static_cast<long>(k) + 1;
    for (DicomTag macro : kPlacingMacros) readMacro(shared, macro, f);
    for (DicomTag macro : kPlacingMacros) readMacro(perFrame[k].get(), macro, f);
    if (const auto content = macroOf(perFrame[k].get(), kTagFrameContentSequence)) {
      f.stack = content->text(kTagStackId).value_or("");
      if (const auto n = content->uint32(kTagInStackPositionNumber)) f.instanceNumber = *n;
    }
    if (!f.position && header.frames > 1 && f.defect.empty()) {
      f.defect = "frame " + std::to_string(k + 1) +
                 " has no Plane Position (Patient) (0020,9113) in its Per-frame or the Shared "
                 "Functional Groups, so it cannot be placed among the others";
    }
    frames.push_back(std::move(f));
  }
  return frames;
}

// One plane and a step along its normal (classic multi-frame).
std::vector<Slice> classicFrames(Slice header, const DicomAttributes& ds) {
  // NM keeps the plane in the Detector Information Sequence (C.8.4.10).
  if (!header.position || !header.rowDir) {
    const auto detectors = ds.items(kTagDetectorInformationSequence);
    if (!detectors.empty()) readPlaneAttributes(*detectors.front(), header);
  }
  const glm::dvec3 row = header.rowDir.value_or(glm::dvec3(1, 0, 0));
  const glm::dvec3 col = header.colDir.value_or(glm::dvec3(0, 1, 0));
  const glm::dvec3 normal = glm::normalize(glm::cross(row, col));
  const glm::dvec3 origin = header.position.value_or(glm::dvec3(0.0));
  std::vector<double> offsets;
  if (const auto t = header.frames > 1 ? ds.text(kTagGridFrameOffsetVector) : std::nullopt) {
    const auto v = parseNumbers(*t, static_cast<std::size_t>(header.frames));
    if (!v) {
      header.defect = "Grid Frame Offset Vector (3004,000c) does not hold " +
                      std::to_string(header.frames) + " numbers, one per frame";
      return {header};
    }
    // Relative (first 0) or absolute (first the position along the normal)
    // alike: frame k lies offset[k] - offset[0] beyond the first.
    for (double o : *v) offsets.push_back(o - v->front());
  } else {
    const double step = header.spacingBetweenSlices > 0 ? header.spacingBetweenSlices
                        : header.sliceThickness > 0     ? header.sliceThickness
                                                        : 1.0;
    for (long k = 0; k < header.frames; ++k) offsets.push_back(static_cast<double>(k) * step);
  }
  std::vector<Slice> frames;
  frames.reserve(offsets.size());
  for (std::size_t k = 0; k < offsets.size(); ++k) {
    Slice f = header;
    f.frame = static_cast<int>(k);
    f.instanceNumber = static_cast<long>(k) + 1;
    f.position = origin + offsets[k] * normal;
    frames.push_back(std::move(f));
  }
  return frames;
}

// Frames without a Stack ID form one stack per orientation: "1", "2", ...
// in the order of their first frames; a file of one orientation has one
// stack and no name for it.
void stacksByOrientation(std::vector<Slice>& frames) {
  std::vector<const Slice*> orientations;
  std::vector<std::size_t> which(frames.size(), 0);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    if (!frames[k].stack.empty()) continue;
    std::size_t o = 0;
    while (o < orientations.size() && !sameOrientation(*orientations[o], frames[k])) ++o;
    if (o == orientations.size()) orientations.push_back(&frames[k]);
    which[k] = o;
  }
  if (orientations.size() < 2) return;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    if (frames[k].stack.empty()) frames[k].stack = std::to_string(which[k] + 1);
  }
}

}  // namespace

std::vector<Slice> framesOf(Slice header, const DicomAttributes& ds) {
  const auto perFrame = ds.items(kTagPerFrameFunctionalGroups);
  const auto sharedItems = ds.items(kTagSharedFunctionalGroups);
  const bool enhanced = !perFrame.empty() || !sharedItems.empty();
  if (header.frames == 1 && !enhanced) return {std::move(header)};
  if (!header.defect.empty()) return {std::move(header)};
  const std::string problem = frameCountProblem(header, perFrame.size(), enhanced);
  if (!problem.empty()) {
    header.defect = problem;
    return {std::move(header)};
  }
  const DicomAttributes* shared = sharedItems.empty() ? nullptr : sharedItems.front().get();
  std::vector<Slice> frames =
      enhanced ? enhancedFrames(header, shared, perFrame) : classicFrames(std::move(header), ds);
  stacksByOrientation(frames);
  return frames;
}

}  // namespace tessera::io_detail
