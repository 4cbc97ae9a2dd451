#include "gpu/compute_program.h"

#include <epoxy/gl.h>

#include "gpu/gl_context.h"
#include "gpu/shader_source.h"

namespace morphoflow {

ComputeProgram::ComputeProgram(const std::string& shader, const std::string& prologue,
                               const std::function<std::string(const std::string&)>& expand) {
  const std::string& source = shaderSource(shader);
  const std::string text = "#version 430 core\n" + prologue + "\n#line 1\n" + (expand ? expand(source) : source);
  const char* src = text.c_str();
  const GLuint s = glCreateShader(GL_COMPUTE_SHADER);
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  auto logOf = [](GLuint object, bool isProgram) {
    GLint n = 0;
    isProgram ? glGetProgramiv(object, GL_INFO_LOG_LENGTH, &n) : glGetShaderiv(object, GL_INFO_LOG_LENGTH, &n);
    std::string log(size_t(std::max(n, 1)), '\0');
    isProgram ? glGetProgramInfoLog(object, n, nullptr, log.data())
              : glGetShaderInfoLog(object, n, nullptr, log.data());
    return log;
  };
  if (!ok) {
    const std::string log = logOf(s, false);
    glDeleteShader(s);
    throw GpuError("shader " + shader + " does not compile:\n" + log);
  }
  id_ = glCreateProgram();
  glAttachShader(id_, s);
  glLinkProgram(id_);
  glDeleteShader(s);
  glGetProgramiv(id_, GL_LINK_STATUS, &ok);
  if (!ok) {
    const std::string log = logOf(id_, true);
    glDeleteProgram(id_);
    throw GpuError("shader " + shader + " does not link:\n" + log);
  }
}

ComputeProgram::~ComputeProgram() {
  if (id_) glDeleteProgram(id_);
}

void ComputeProgram::use() const { glUseProgram(id_); }

int ComputeProgram::uniform(const char* name) const { return glGetUniformLocation(id_, name); }

bool ComputeProgram::singlePrecision(const char* name) const {
  auto it = single_.find(name);
  if (it != single_.end()) return it->second;
  const GLuint index = glGetProgramResourceIndex(id_, GL_UNIFORM, name);
  GLint type = 0;
  if (index != GL_INVALID_INDEX) {
    const GLenum property = GL_TYPE;
    glGetProgramResourceiv(id_, GL_UNIFORM, index, 1, &property, 1, nullptr, &type);
  }
  const bool single = type == GL_FLOAT || type == GL_FLOAT_VEC2 || type == GL_FLOAT_VEC3 || type == GL_FLOAT_VEC4;
  return single_.emplace(name, single).first->second;
}

}  // namespace morphoflow
