#include "tessera/gpu/Program.h"

#include <map>
#include <regex>
#include <sstream>
#include <utility>

#include <glm/gtc/type_ptr.hpp>

#include "gpu/gl.h"
#include "tessera/core/Error.h"

namespace tessera::gpu {

const std::map<std::string, std::string_view>& embeddedShaders();  // generated

ShaderPart embeddedShaderPart(const std::string& path) {
  const auto& all = embeddedShaders();
  auto it = all.find(path);
  if (it == all.end()) throw GpuError("no embedded shader '" + path + "'");
  return {path, std::string(it->second)};
}

ShaderPart shaderPreamble(ApiLevel api, bool fragment, const std::vector<std::string>& defines) {
  std::string s;
  if (api == ApiLevel::Gles3) {
    s = "#version 300 es\n";
    if (fragment) s += "precision highp float;\nprecision highp int;\nprecision highp sampler3D;\n";
    s += "#define TESSERA_GLSL 300\n#define TEX2D(s, p) texture(s, p)\n";
    if (fragment) s += "out vec4 tessera_FragColor;\n#define FRAG_COLOR tessera_FragColor\n";
  } else {
    s = "#version 100\n";
    if (fragment) {
      s += "#ifdef GL_FRAGMENT_PRECISION_HIGH\nprecision highp float;\n#else\nprecision mediump "
           "float;\n#endif\n";
    }
    s += "#define TESSERA_GLSL 100\n#define TEX2D(s, p) texture2D(s, p)\n";
    if (fragment) s += "#define FRAG_COLOR gl_FragColor\n";
  }
  for (const std::string& d : defines) s += "#define " + d + "\n";
  return {"<preamble>", s};
}

namespace {
constexpr std::size_t kLinesPerPart = 100000;
}  // namespace

std::string assembleShader(const std::vector<ShaderPart>& parts) {
  // The first part holds #version, which must come first; every later part
  // restarts line numbering with its own source-string index.
  std::string source;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (i > 0) {
      source += "#line " + std::to_string(i * kLinesPerPart + 1) + " " + std::to_string(i) + "\n";
    }
    source += parts[i].text;
    if (source.empty() || source.back() != '\n') source += '\n';
  }
  return source;
}

namespace {

// Driver logs look like "0:12(3): error: ..." (Mesa) or "ERROR: 0:12: ..."
// (ANGLE, NVIDIA). The first number is our source-string index (set by
// #line), the second the line inside that part.
std::string mapLog(const std::string& log, const std::vector<ShaderPart>& parts) {
  static const std::regex loc(R"((\d+):(\d+)(\(\d+\))?:)");
  std::ostringstream out;
  std::istringstream in(log);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_search(line, m, loc)) {
      // Mesa ignores the source-string number of #line, so the part index
      // is also encoded in the line number itself (see compile()).
      std::size_t index = std::stoul(m[1]);
      std::size_t lineNo = std::stoul(m[2]);
      if (lineNo >= kLinesPerPart) {
        index = lineNo / kLinesPerPart;
        lineNo %= kLinesPerPart;
      }
      const std::string file =
          index < parts.size() ? parts[index].name : "part " + std::to_string(index);
      out << file << ":" << lineNo << ": "
          << line.substr(static_cast<std::size_t>(m.position(0) + m.length(0))) << "\n";
    } else if (!line.empty()) {
      out << line << "\n";
    }
  }
  return out.str();
}

GLuint compile(GLenum stage, const std::string& programName, const std::vector<ShaderPart>& parts) {
  const std::string source = assembleShader(parts);
  GLuint s = glCreateShader(stage);
  const char* src = source.c_str();
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = GL_FALSE;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetShaderiv(s, GL_INFO_LOG_LENGTH, &len);
    std::string log(static_cast<std::size_t>(std::max(len, 1)), '\0');
    glGetShaderInfoLog(s, len, nullptr, log.data());
    glDeleteShader(s);
    throw GpuError("shader program '" + programName +
                   "': " + (stage == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                   " shader does not compile:\n" + mapLog(log, parts));
  }
  return s;
}

}  // namespace

Program::Program(Program&& o) noexcept : id_(std::exchange(o.id_, 0)), name_(std::move(o.name_)) {}

Program& Program::operator=(Program&& o) noexcept {
  if (this != &o) {
    if (id_) glDeleteProgram(id_);
    id_ = std::exchange(o.id_, 0);
    name_ = std::move(o.name_);
  }
  return *this;
}

Program::~Program() {
  if (id_) glDeleteProgram(id_);
}

Program Program::build(const std::string& name, const std::vector<ShaderPart>& vertexParts,
                       const std::vector<ShaderPart>& fragmentParts) {
  const GLuint vs = compile(GL_VERTEX_SHADER, name, vertexParts);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, name, fragmentParts);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  Program p;
  p.name_ = name;
  p.id_ = glCreateProgram();
  glAttachShader(p.id_, vs);
  glAttachShader(p.id_, fs);
  glBindAttribLocation(p.id_, 0, "a_position");
  glLinkProgram(p.id_);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(p.id_, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetProgramiv(p.id_, GL_INFO_LOG_LENGTH, &len);
    std::string log(static_cast<std::size_t>(std::max(len, 1)), '\0');
    glGetProgramInfoLog(p.id_, len, nullptr, log.data());
    throw GpuError("shader program '" + name + "' does not link:\n" + log);
  }
  return p;
}

void Program::use() const {
  glUseProgram(id_);
}
int Program::uniformLocation(const char* n) const {
  return glGetUniformLocation(id_, n);
}
int Program::attributeLocation(const char* n) const {
  return glGetAttribLocation(id_, n);
}
void Program::set(const char* n, int v) const {
  glUniform1i(uniformLocation(n), v);
}
void Program::set(const char* n, float v) const {
  glUniform1f(uniformLocation(n), v);
}
void Program::set(const char* n, glm::vec2 v) const {
  glUniform2fv(uniformLocation(n), 1, glm::value_ptr(v));
}
void Program::set(const char* n, glm::vec3 v) const {
  glUniform3fv(uniformLocation(n), 1, glm::value_ptr(v));
}
void Program::set(const char* n, glm::vec4 v) const {
  glUniform4fv(uniformLocation(n), 1, glm::value_ptr(v));
}
void Program::set(const char* n, const glm::mat3& m) const {
  glUniformMatrix3fv(uniformLocation(n), 1, GL_FALSE, glm::value_ptr(m));
}
void Program::set(const char* n, const glm::mat4& m) const {
  glUniformMatrix4fv(uniformLocation(n), 1, GL_FALSE, glm::value_ptr(m));
}

}  // namespace tessera::gpu
