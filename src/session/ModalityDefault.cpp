#include "tessera/session/ModalityDefault.h"

#include "tessera/core/ClinicalPresets.h"
#include "tessera/session/Settings.h"

namespace tessera::session {

namespace {

// The clinical preset that `name` selects: the window presets' names
// (ct-bone on the volume's window) shadow a clinical one of the same name,
// as TransferFunction::preset resolves them.
const ClinicalPreset* clinicalPresetNamed(const std::string& name) {
  for (const std::string& windowPreset : TransferFunction::windowPresetNames()) {
    if (windowPreset == name) return nullptr;
  }
  for (const ClinicalPreset& p : clinicalPresets()) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

// Where the window of the default comes from, for the note.
std::string windowText(const ClinicalPreset& p, const Volume& v) {
  const ValueRange w = v.window();
  if (v.hasWindow()) {
    return "the volume's own window " + numberText(0.5 * (w.min + w.max)) + "/" +
           numberText(w.width()) + " (centre/width)";
  }
  const ValueRange c = clinicalWindow(p, v);
  if (p.hounsfield)
    return "window " + numberText(c.min) + ".." + numberText(c.max) + " HU of the preset";
  return "window " + numberText(c.min) + ".." + numberText(c.max) + " (1st..99th percentile)";
}

}  // namespace

std::optional<ModalityDefault> modalityDefault(const Volume& volume) {
  const ClinicalPreset* p = defaultClinicalPreset(volume.modality());
  if (!p) return std::nullopt;
  return ModalityDefault{p->tf, volume.modality() + ": default transfer function " + p->name +
                                    " (modality " + volume.modality() + "), " +
                                    windowText(*p, volume) + "; --tf to change"};
}

std::optional<ValueRange> clinicalPresetWindow(const TransferFunction& tf, const Volume& volume) {
  const ClinicalPreset* p = clinicalPresetNamed(tf.name);
  if (!p) return std::nullopt;
  return clinicalWindow(*p, volume);
}

ValueRange sliceWindow(const Volume& volume, bool ownWindow, const TransferFunction* tf) {
  if (ownWindow) return volume.window();
  const ClinicalPreset* p =
      tf ? clinicalPresetNamed(tf->name) : defaultClinicalPreset(volume.modality());
  if (!p || (p->percentiles && !volume.hasData())) return volume.window();
  return clinicalWindow(*p, volume);
}

}  // namespace tessera::session
