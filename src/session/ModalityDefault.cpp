#include "tessera/session/ModalityDefault.h"

#include "tessera/core/ClinicalPresets.h"
#include "tessera/session/Session.h"
#include "tessera/session/Settings.h"
#include "tessera/viewer/Viewer.h"

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

std::string presetNote(const TransferFunction& tf, const Volume& volume) {
  if (tf.name != "ct-bone" || volume.modality() != "CT") return "";
  return "CT: ct-bone is the bone ramp over the volume's own window; the bone preset in "
         "Hounsfield units, the same on every CT, is ct-bone-hu";
}

// Session's (session/Session.h), here with the rules it follows: the TF the
// user chose, then the window rules 1-4 of ModalityDefault.h, so that a
// preset picked from a menu looks as `--tf NAME` renders.
void Session::choosePreset(const std::string& name) {
  settings_.tf = TransferFunction::preset(name);  // InputError naming the presets
  settings_.tfIsDefault = false;
  tfBeforeDefault_.reset();
  defaultNote_.clear();
  if (inCore_) {
    Volume& v = inCore_->volume();
    defaultNote_ = presetNote(settings_.tf, v);
    // Rule 3 replaces the window of the TF chosen before, if it was one.
    if (!settings_.window && !ownWindow_) v.resetWindow();
  }
  applyVolumeSettings();
  if (!view_) return;
  viewer::Viewer& view = *view_;
  if (!settings_.labels) view.tfEditor().setTransferFunction(settings_.tf);
  if (!inCore_ || !view.hasVolume() || settings_.window) return;
  const Volume& v = inCore_->volume();
  if (v.hasWindow()) {
    view.setWindow(v.window());
  } else {
    view.resetWindow();
  }
}

}  // namespace tessera::session
