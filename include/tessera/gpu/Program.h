#pragma once
// Shader programs assembled from named GLSL parts. Part N is preceded by
// `#line N*100000+1 N` so the driver's line numbers map back to the part even
// where the source-string number is ignored (Mesa), and compile errors are
// reported as "render/raycast.frag.glsl:42: ...".
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "tessera/gpu/DeviceCaps.h"

namespace tessera::gpu {

struct ShaderPart {
  std::string name;  // file name, used in error messages
  std::string text;
};

// A GLSL file embedded at build time, by its path under src/ (e.g.
// "render/raycast.frag.glsl"). Throws GpuError if there is none.
ShaderPart embeddedShaderPart(const std::string& path);

// "#version ..." and precision statements for the API level, plus `defines`
// ("NAME VALUE" strings become #define lines). Parts written for both levels
// use TESSERA_GLSL (100 or 300), TEX2D(sampler, uv) for 2D fetches and, in
// fragment shaders, FRAG_COLOR for the output.
ShaderPart shaderPreamble(ApiLevel api, bool fragment, const std::vector<std::string>& defines);

// The single source string the driver compiles from `parts` (with the #line
// directives that map its lines back to the parts).
std::string assembleShader(const std::vector<ShaderPart>& parts);

class Program {
 public:
  Program() = default;
  Program(Program&& o) noexcept;
  Program& operator=(Program&& o) noexcept;
  ~Program();

  // Compiles and links; GpuError with "<part name>:<line>: <message>" lines.
  static Program build(const std::string& name, const std::vector<ShaderPart>& vertexParts,
                       const std::vector<ShaderPart>& fragmentParts);

  void use() const;
  unsigned id() const { return id_; }
  int uniformLocation(const char* name) const;    // -1 if absent (optimised out)
  int attributeLocation(const char* name) const;  // -1 if absent
  void set(const char* name, int v) const;
  void set(const char* name, float v) const;
  void set(const char* name, glm::vec2 v) const;
  void set(const char* name, glm::vec3 v) const;
  void set(const char* name, glm::vec4 v) const;
  void set(const char* name, const glm::mat3& m) const;
  void set(const char* name, const glm::mat4& m) const;

 private:
  unsigned id_ = 0;
  std::string name_;
};

}  // namespace tessera::gpu
