#pragma once
// Transfer functions as clinicians expect them: CT presets defined in
// Hounsfield units (bone, soft tissue, lung, angio), so that one preset fits
// any CT whatever its stored range once the rescale slope/intercept has made
// its values HU; MR presets by percentiles of the volume's own histogram (MR
// values have no absolute scale); the modality decides the default.
//
// Each preset is a TransferFunction over [0,1] plus the window that [0,1]
// spans: fixed HU for CT, percentiles for MR. clinicalWindow() turns that
// into the volume window the renderers use (Volume::setWindow), so nothing
// downstream changes: x = (value - window.min) / window.width().
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tessera/core/TransferFunction.h"
#include "tessera/core/Volume.h"

namespace tessera {

struct ClinicalPreset {
  std::string name;      // "ct-bone-hu", "ct-soft-tissue", "ct-lung", "ct-angio", "mr-percentile"
  std::string modality;  // "CT" or "MR"
  TransferFunction tf;
  // CT: the HU that x = 0 and x = 1 stand for.
  std::optional<ValueRange> hounsfield;
  // MR: the histogram fractions that x = 0 and x = 1 stand for.
  std::optional<std::pair<double, double>> percentiles;
};

// Every clinical preset, CT first.
const std::vector<ClinicalPreset>& clinicalPresets();
// The preset called `name`; InputError listing them when there is none.
const ClinicalPreset& clinicalPreset(const std::string& name);

// The window `preset` puts on `volume`: its HU (CT; the volume's values must
// be HU, i.e. rescaled), or its percentiles of the volume's values (MR).
ValueRange clinicalWindow(const ClinicalPreset& preset, const Volume& volume);

// The default for a modality (DICOM Modality (0008,0060)): "CT" gives
// ct-soft-tissue, "MR" mr-percentile; nullptr for any other (the volume's
// own window and the usual default transfer function stay).
const ClinicalPreset* defaultClinicalPreset(const std::string& modality);

// The opacity `preset` gives a voxel of `value` in `volume` (through
// clinicalWindow), before distance correction: what a test measures.
double clinicalOpacity(const ClinicalPreset& preset, const Volume& volume, double value);

}  // namespace tessera
