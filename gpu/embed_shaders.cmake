# Writes OUT: every shader of SHADERS (a ;-list of paths: *.comp programs, the
# *.glsl code they share and the kernels/ files shared with the CPU) as a C++ raw string,
# looked up by file name through gpu/shader_source.h.
set(body "// Generated from gpu/shaders/*.comp by gpu/embed_shaders.cmake.\n")
string(APPEND body "#include \"gpu/shader_source.h\"\n#include <map>\n#include <stdexcept>\nnamespace morphoflow {\n")
string(APPEND body "const std::string& shaderSource(const std::string& name) {\n")
string(APPEND body "  static const std::map<std::string, std::string> sources = {\n")
foreach(path ${SHADERS})
  get_filename_component(name ${path} NAME)
  file(READ ${path} text)
  string(APPEND body "    {\"${name}\", R\"glsl(${text})glsl\"},\n")
endforeach()
string(APPEND body "  };\n  const auto it = sources.find(name);\n")
string(APPEND body "  if (it == sources.end()) throw std::logic_error(\"no shader \" + name);\n")
string(APPEND body "  return it->second;\n}\n}  // namespace morphoflow\n")
file(WRITE ${OUT}.tmp "${body}")
file(COPY_FILE ${OUT}.tmp ${OUT} ONLY_IF_DIFFERENT)
