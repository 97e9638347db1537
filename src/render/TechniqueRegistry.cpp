#include "tessera/render/TechniqueRegistry.h"

#include "tessera/core/Error.h"
#include "tessera/render/Raycaster.h"
#include "tessera/render/Slice2DRenderer.h"
#include "tessera/render/Slice3DRenderer.h"

namespace tessera::render {

TechniqueRegistry& TechniqueRegistry::global() {
  static TechniqueRegistry registry = [] {
    TechniqueRegistry r;
    r.add(Raycaster::registration());
    r.add(Slice3DRenderer::registration());
    r.add(Slice2DRenderer::registration());
    return r;
  }();
  return registry;
}

std::unique_ptr<Technique> TechniqueRegistry::create(const std::string& name,
                                                     const TechniqueSetup& setup) const {
  const TechniqueEntry& entry = find(name);
  if (!entry.create) throw Error("technique " + name + " was registered without a factory");
  return entry.create(setup);
}

std::string TechniqueRegistry::describe() const {
  std::string text;
  for (const TechniqueEntry& e : entries()) {
    text += (text.empty() ? "" : ", ") + e.name + (e.summary.empty() ? "" : " (" + e.summary + ")");
  }
  return text;
}

TechniqueOnVolume& TechniqueOnVolume::operator=(TechniqueOnVolume&& other) noexcept {
  technique.reset();
  upload = std::move(other.upload);
  requirements = std::move(other.requirements);
  technique = std::move(other.technique);
  return *this;
}

std::string TechniqueOnVolume::storageName() const {
  return upload.layout ? upload.layout->name() : technique->report().storage;
}

TechniqueOnVolume createTechnique(const std::string& name, gpu::GlContext& context,
                                  const gpu::DeviceLimits& limits, const lod::VolumeSource& source,
                                  const TechniqueOptions& options, const std::string& layoutWish) {
  const TechniqueEntry& entry = TechniqueRegistry::global().find(name);
  if (!entry.requirements)
    throw Error("technique " + name + " was registered without requirements");
  TechniqueOnVolume t;
  t.requirements = entry.requirements(limits, source.shape().dims(), options);
  const bool samplesLayout = t.requirements.ownStorage.empty();
  if (!samplesLayout && layoutWish != "auto") {
    throw InputError("--layout does not apply to " + name + ": " + t.requirements.ownStorage);
  }
  t.upload = layout::uploadVolume(context, limits, source,
                                  {.textureUnits = t.requirements.textureUnits,
                                   .bytes = t.requirements.bytes,
                                   .samplesLayout = samplesLayout},
                                  layoutWish);
  t.technique = entry.create({.context = context,
                              .limits = limits,
                              .volume = *t.upload.volume,
                              .layout = t.upload.layout.get(),
                              .options = options});
  return t;
}

}  // namespace tessera::render
