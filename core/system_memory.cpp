#include "core/system_memory.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <utility>

#include <sys/resource.h>

namespace morphoflow {

namespace {

uintmax_t meminfoAvailable() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  uintmax_t kb = 0;
  std::string unit;
  while (in >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024;
  return UINTMAX_MAX;
}

uintmax_t cgroupRoom() {
  std::ifstream max("/sys/fs/cgroup/memory.max"), cur("/sys/fs/cgroup/memory.current");
  std::string m;
  uintmax_t c = 0;
  if (!(max >> m) || m == "max" || !(cur >> c)) return UINTMAX_MAX;
  const uintmax_t limit = std::stoull(m);
  return limit > c ? limit - c : 0;
}

// This process's status line `key` ("VmSize:", "VmData:") in bytes.
uintmax_t statusBytes(const std::string& key) {
  std::ifstream in("/proc/self/status");
  std::string k;
  while (in >> k) {
    if (k == key) {
      uintmax_t kb = 0;
      in >> kb;
      return kb * 1024;
    }
    in.ignore(1 << 12, '\n');
  }
  return 0;
}

// What ulimit -v (RLIMIT_AS) and ulimit -d (RLIMIT_DATA) leave this process.
uintmax_t rlimitRoom() {
  uintmax_t room = UINTMAX_MAX;
  for (const auto& [resource, key] : {std::pair{RLIMIT_AS, "VmSize:"}, std::pair{RLIMIT_DATA, "VmData:"}}) {
    rlimit r{};
    if (getrlimit(resource, &r) != 0 || r.rlim_cur == RLIM_INFINITY) continue;
    const uintmax_t used = statusBytes(key), limit = r.rlim_cur;
    room = std::min(room, limit > used ? limit - used : uintmax_t(0));
  }
  return room;
}

}  // namespace

uintmax_t availableBytes() { return std::min({meminfoAvailable(), cgroupRoom(), rlimitRoom()}); }

std::string humanBytes(uintmax_t b) {
  char text[32];
  if (b >= (uintmax_t(1) << 30))
    std::snprintf(text, sizeof text, "%.2f GiB", double(b) / double(1 << 30));
  else if (b >= (uintmax_t(1) << 20))
    std::snprintf(text, sizeof text, "%.0f MiB", double(b) / double(1 << 20));
  else
    std::snprintf(text, sizeof text, "%.0f KiB", double(b) / 1024.0);
  return text;
}

}  // namespace morphoflow
