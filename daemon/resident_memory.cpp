#include "daemon/resident_memory.hpp"

#include <cstdio>

namespace posed {

ResidentMemory read_resident_memory() {
  ResidentMemory out;
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (f == nullptr) return out;
  char line[256];
  while (std::fgets(line, sizeof line, f) != nullptr) {
    double kb = 0;
    if (std::sscanf(line, "VmHWM: %lf kB", &kb) == 1) out.peak_mb = kb / 1024.0;
    if (std::sscanf(line, "RssAnon: %lf kB", &kb) == 1) out.anon_mb = kb / 1024.0;
  }
  std::fclose(f);
  return out;
}

}  // namespace posed
