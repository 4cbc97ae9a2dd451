#include "run/scene_hash.h"

#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <xxhash.h>

namespace morphoflow {

std::string hashHex(const void* data, size_t bytes) { return fmt::format("{:016x}", XXH64(data, bytes, 0)); }

std::string sceneHash(const Scene& scene) { return hashHex(scene.resolvedJson.data(), scene.resolvedJson.size()); }

namespace {

void flatten(const nlohmann::json& j, const std::string& prefix, std::map<std::string, std::string>* out) {
  if (j.is_object() && !j.empty()) {
    for (const auto& [k, v] : j.items()) flatten(v, prefix.empty() ? k : prefix + "." + k, out);
    return;
  }
  (*out)[prefix] = j.dump();
}

}  // namespace

std::vector<std::string> changedKeys(const std::string& a, const std::string& b) {
  // (a checkpoint's header may hold anything: no keys are named unless both are tables)
  const nlohmann::json ja = nlohmann::json::parse(a, nullptr, false), jb = nlohmann::json::parse(b, nullptr, false);
  if (!ja.is_object() || !jb.is_object()) return {};
  std::map<std::string, std::string> fa, fb;
  flatten(ja, "", &fa);
  flatten(jb, "", &fb);
  std::vector<std::string> keys;
  for (const auto& [k, v] : fa)
    if (!fb.count(k) || fb[k] != v) keys.push_back(k);
  for (const auto& [k, v] : fb)
    if (!fa.count(k)) keys.push_back(k);
  return keys;
}

}  // namespace morphoflow
