#pragma once
// Techniques by name: each registers what it needs of a device (a function
// of the device's limits, the volume's dims and the options, known before it
// exists) and a factory. Built in: raycast (render/Raycaster.h), slice3d
// (render/Slice3DRenderer.h) and slice2d (render/Slice2DRenderer.h), each
// defining its entry in its own file. Adding a technique is its own file
// and one registration: a line in TechniqueRegistry::global(), or add() from
// anywhere (tests/render/TechniqueRegistryTest.cpp registers one).
//
// createTechnique() is the path every front end takes: find the entry, ask
// its requirements, upload the volume for them (layout::uploadVolume), and
// build the technique on the upload.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/NamedRegistry.h"
#include "tessera/core/Volume.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/layout/Layout.h"
#include "tessera/layout/VolumeUpload.h"
#include "tessera/lod/VolumeSource.h"
#include "tessera/render/Technique.h"

namespace tessera::render {

// What a technique is built on.
struct TechniqueSetup {
  gpu::GlContext& context;
  const gpu::DeviceLimits& limits;
  const Volume& volume;          // at the layout's resolution; outlives the technique
  const layout::Layout* layout;  // outlives it; null for a technique with its own storage
  const TechniqueOptions& options;
};

struct TechniqueEntry {
  std::string name;
  std::string summary;  // a few words for --help and the viewers' menus
  // What callers ask of a technique, instead of comparing its name:
  // honoursSampling: it takes RenderSettings::sampling (pre-integration,
  // adaptive steps); the others take every sample post-classified, and
  // their reference must assume neither.
  bool honoursSampling = false;
  // scissorsToVolume: pixels outside the volume's projection come out
  // transparent black (its rays miss the box), so a frame scissored to that
  // part of the view draws the same image.
  bool scissorsToVolume = false;
  // drawsChannels: it draws several channels over a layout that holds them
  // in core (docs/channels.md); drawsChannelBricks: also over the bricks
  // layout's channel atlases (the streaming refinement).
  bool drawsChannels = false;
  bool drawsChannelBricks = false;
  std::function<TechniqueRequirements(const gpu::DeviceLimits& limits, glm::ivec3 volumeDims,
                                      const TechniqueOptions& options)>
      requirements;
  std::function<std::unique_ptr<Technique>(const TechniqueSetup& setup)> create;
};

// add() a technique after the others (or in place of one of its name);
// names() in registration order; find() throws InputError "unknown technique
// 'x' (expected raycast, slice3d or slice2d)".
class TechniqueRegistry : public NamedRegistry<TechniqueEntry> {
 public:
  TechniqueRegistry() : NamedRegistry("technique") {}
  // The built-in techniques: raycast, slice3d, slice2d.
  static TechniqueRegistry& global();

  // The technique of that name on a volume and layout uploaded already
  // (benchmarks compare several on one upload; createTechnique makes both).
  std::unique_ptr<Technique> create(const std::string& name, const TechniqueSetup& setup) const;
  // "raycast (single-pass ray casting), slice3d (...), ...": names and summaries.
  std::string describe() const;
};

// A technique on a volume uploaded for it. The technique goes first, on
// destruction and on assignment: it refers to the upload's volume and layout.
struct TechniqueOnVolume {
  layout::VolumeUpload upload;
  TechniqueRequirements requirements;
  std::unique_ptr<Technique> technique;

  TechniqueOnVolume() = default;
  TechniqueOnVolume(TechniqueOnVolume&&) = default;
  TechniqueOnVolume& operator=(TechniqueOnVolume&& other) noexcept;

  // The layout's name, or the technique's own storage ("slice-stacks").
  std::string storageName() const;
};

// `layoutWish`: "auto" or a registered layout (InputError for a technique
// with its own storage, or one the device cannot hold).
TechniqueOnVolume createTechnique(const std::string& name, gpu::GlContext& context,
                                  const gpu::DeviceLimits& limits, const lod::VolumeSource& source,
                                  const TechniqueOptions& options,
                                  const std::string& layoutWish = "auto");

}  // namespace tessera::render
