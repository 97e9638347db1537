#pragma once
// The look a volume opens with when the user named no transfer function:
// its modality (Volume::modality, DICOM Modality (0008,0060)) picks a
// clinical preset (core/ClinicalPresets.h). CT gets ct-soft-tissue: a
// generic CT (chest, abdomen, head) is read in the soft-tissue window 40/400
// HU, which is that preset's window, so the slices show what a radiologist
// expects first; in 3D the same preset shows soft tissue faint and
// translucent and bone (above ~200 HU) opaque ivory, the usual "bone and
// soft tissue" view. MR gets mr-percentile (MR values have no absolute
// scale). Any other modality, and every format without one (NIfTI, NRRD,
// ...), keeps the front end's default (mr-default on the volume's window).
//
// One window maps values to the TF's [0,1], for the 3D view and the slices
// alike; the first of these that applies is it:
//   1. the user's window (--window, the window/level control, a state);
//   2. the volume's own window: a DICOM series' Window Center/Width (first
//      value), a NIfTI's cal_min/cal_max, a store's declared window;
//   3. the clinical preset's window, when the TF is one (by name): its HU
//      (CT) or the volume's percentiles (MR);
//   4. the volume's value range.
// A TF the user names (--tf, a menu, a state) is always kept; a clinical
// one gets its window by rule 3 just as the default does, so that the
// default render of a CT is the render with `--tf ct-soft-tissue`.
#include <optional>
#include <string>

#include "tessera/core/TransferFunction.h"
#include "tessera/core/Volume.h"

namespace tessera::session {

struct ModalityDefault {
  TransferFunction tf;
  // "CT: default transfer function ct-soft-tissue (modality CT), window
  // -160..240 HU from the preset; --tf to change"
  std::string note;
};

// The default for `volume`'s modality; nullopt when it has none.
std::optional<ModalityDefault> modalityDefault(const Volume& volume);

// Rule 3: the window the clinical preset named like `tf` puts on `volume`;
// nullopt when `tf` is not a clinical preset.
std::optional<ValueRange> clinicalPresetWindow(const TransferFunction& tf, const Volume& volume);

// The window a slice of `volume` shows when the user gave none (rules 2-4;
// `ownWindow`: the volume came with its own, which a pyramid's shape does
// not tell, its slab read from level 0 does): `tf` is the TF the user
// named, or null for none, when the modality's
// default preset stands in (a CT without its own window: -160..240 HU).
// Percentiles need voxels: a shape without them (a pyramid's) keeps its
// value range for an MR.
ValueRange sliceWindow(const Volume& volume, bool ownWindow, const TransferFunction* tf);

// A note for a TF the user named that is easily mistaken on `volume`:
// ct-bone on a CT (the bone ramp over the volume's window, not the HU
// preset ct-bone-hu); "" otherwise.
std::string presetNote(const TransferFunction& tf, const Volume& volume);

}  // namespace tessera::session
