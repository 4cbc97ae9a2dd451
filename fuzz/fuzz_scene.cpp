// libFuzzer target for the scene loader and the --set parser. An input is a
// scene's text, optionally followed by a line "--set" and one override per
// line. A UserError is the right answer to bad input; anything else (another
// exception, a crash, a sanitizer report, a hang) is a bug.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "fuzz/fuzz_support.h"
#include "scenes/scene_loader.h"
#include "scenes/vary.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) { return 0; }

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  std::string text = input;
  std::vector<std::string> overrides;
  if (const size_t at = input.find("\n--set\n"); at != std::string::npos) {
    text = input.substr(0, at);
    overrides = morphoflow::fuzz::nonEmptyLines(std::string_view(input).substr(at + 7));
  }
  try {
    // The scene's folder is the corpus's: relative image paths find nothing.
    morphoflow::parseScene(text, "fuzz/scene.toml", overrides);
  } catch (const morphoflow::UserError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "not a UserError: %s\n", e.what());
    std::abort();
  }
  for (const std::string& o : overrides) {
    try {
      morphoflow::parseVary(o);
    } catch (const morphoflow::UserError&) {
    }
  }
  return 0;
}
