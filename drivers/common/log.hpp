#pragma once
// Minimal leveled logging to stderr. Lines carry sd-daemon priority prefixes ("<4>") when stderr
// is the journal (JOURNAL_STREAM set), so `journalctl -p warning` filters them; on a terminal
// they read "posed: warning: ...". Deliberately printf-style: no format-library compile cost.

#include <cstdarg>

namespace posed::log {

enum class Level { kError = 3, kWarning = 4, kNotice = 5, kInfo = 6, kDebug = 7 };

/// Messages above this level are dropped (default kInfo; POSED_LOG=debug raises it).
void set_max_level(Level level);
Level max_level();
/// The program name shown on terminals ("posed", "posectl").
void set_program_name(const char* name);

void write(Level level, const char* fmt, ...) __attribute__((format(printf, 2, 3)));

#define POSED_LOG_ERROR(...) ::posed::log::write(::posed::log::Level::kError, __VA_ARGS__)
#define POSED_LOG_WARN(...) ::posed::log::write(::posed::log::Level::kWarning, __VA_ARGS__)
#define POSED_LOG_NOTICE(...) ::posed::log::write(::posed::log::Level::kNotice, __VA_ARGS__)
#define POSED_LOG_INFO(...) ::posed::log::write(::posed::log::Level::kInfo, __VA_ARGS__)
#define POSED_LOG_DEBUG(...) ::posed::log::write(::posed::log::Level::kDebug, __VA_ARGS__)

}  // namespace posed::log
