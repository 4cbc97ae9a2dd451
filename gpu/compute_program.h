// A linked GLSL compute program: an embedded shader with a prologue of
// #version and #defines; a compile or link error is a GpuError with the log.
#pragma once

#include <functional>
#include <map>
#include <string>

namespace morphoflow {

class ComputeProgram {
 public:
  // `expand` (if given) rewrites the shader's text before it compiles (includes).
  ComputeProgram(const std::string& shader, const std::string& prologue,
                 const std::function<std::string(const std::string&)>& expand = {});
  ComputeProgram(const ComputeProgram&) = delete;
  ComputeProgram& operator=(const ComputeProgram&) = delete;
  ~ComputeProgram();

  void use() const;
  int uniform(const char* name) const;  // its location (-1 when the compiler removed it)
  // Whether the uniform is declared in single precision (float, vecN; REAL
  // in float); false for double ones and those the compiler removed.
  bool singlePrecision(const char* name) const;
  unsigned id() const { return id_; }

 private:
  unsigned id_ = 0;
  mutable std::map<std::string, bool> single_;
};

}  // namespace morphoflow
