#pragma once
// The once-a-second progress line of long posectl commands (record, replay): rewritten in place
// on a terminal, one line per report when stderr is a pipe or the journal, so logs stay readable.

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace posed::posectl {

/// Bytes as megabytes (10^6 B) for progress lines and summaries [MB].
inline double megabytes(std::uint64_t bytes) { return static_cast<double>(bytes) / 1e6; }

class TerminalProgress {
 public:
  TerminalProgress() : tty_(::isatty(STDERR_FILENO) == 1) {}
  ~TerminalProgress() { finish(); }
  TerminalProgress(const TerminalProgress&) = delete;
  TerminalProgress& operator=(const TerminalProgress&) = delete;

  void show(const std::string& line) {
    if (tty_) {
      // Pad over the previous, possibly longer, line.
      const std::size_t pad = last_length_ > line.size() ? last_length_ - line.size() : 0;
      std::fprintf(stderr, "\r%s%*s", line.c_str(), static_cast<int>(pad), "");
      last_length_ = line.size();
      pending_newline_ = true;
    } else {
      std::fprintf(stderr, "%s\n", line.c_str());
    }
    std::fflush(stderr);
  }

  /// Ends an in-place line so what follows starts on its own line.
  void finish() {
    if (pending_newline_) std::fputc('\n', stderr);
    pending_newline_ = false;
    last_length_ = 0;
  }

 private:
  bool tty_;
  bool pending_newline_ = false;
  std::size_t last_length_ = 0;
};

}  // namespace posed::posectl
