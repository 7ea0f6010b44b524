#include "drivers/common/log.hpp"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>

namespace posed::log {
namespace {
std::atomic<Level> g_max_level{Level::kInfo};
const char* g_program = "posed";
std::mutex g_write_mutex;

bool to_journal() {
  static const bool journal = std::getenv("JOURNAL_STREAM") != nullptr;
  return journal;
}

const char* level_name(Level level) {
  switch (level) {
    case Level::kError:
      return "error";
    case Level::kWarning:
      return "warning";
    case Level::kNotice:
      return "notice";
    case Level::kInfo:
      return "info";
    case Level::kDebug:
      return "debug";
  }
  return "?";
}

struct EnvLevel {
  EnvLevel() {
    if (const char* v = std::getenv("POSED_LOG")) {
      if (std::strcmp(v, "debug") == 0) g_max_level = Level::kDebug;
      if (std::strcmp(v, "warning") == 0) g_max_level = Level::kWarning;
      if (std::strcmp(v, "error") == 0) g_max_level = Level::kError;
    }
  }
} g_env_level;
}  // namespace

void set_max_level(Level level) { g_max_level = level; }
Level max_level() { return g_max_level; }
void set_program_name(const char* name) { g_program = name; }

void write(Level level, const char* fmt, ...) {
  if (static_cast<int>(level) > static_cast<int>(g_max_level.load())) return;
  char line[1024];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(line, sizeof line, fmt, args);
  va_end(args);
  std::lock_guard lock(g_write_mutex);
  if (to_journal()) {
    std::fprintf(stderr, "<%d>%s\n", static_cast<int>(level), line);
  } else {
    std::fprintf(stderr, "%s: %s: %s\n", g_program, level_name(level), line);
  }
}

}  // namespace posed::log
