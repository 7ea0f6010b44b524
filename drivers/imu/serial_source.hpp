#pragma once
// Live serial-port Source (termios raw mode) for the A9 and other serial IMUs. Moves bytes only;
// decoding is the caller's (A9Decoder). Survives unplug/replug: a lost device is reopened on
// later reads with exponential back-off, counted, with one log line per transition.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/time.hpp"
#include "drivers/common/source.hpp"
#include "drivers/common/wire_format.hpp"

namespace posed::drivers {

struct SerialConfig {
  /// device path; a /dev/serial/by-id/... symlink is preferred (stable across replugs)
  std::string path;
  /// line rate [baud]; one of the standard termios rates up to 4000000
  int baud = 921600;
  /// refuse further opens of the port while we hold it (TIOCEXCL)
  bool exclusive = true;
  /// first reopen delay after the device is lost [ns]
  Duration reopen_backoff_min = Duration::from_ms(100);
  /// reopen delay cap; the delay doubles per failed attempt up to this [ns]
  Duration reopen_backoff_max = Duration::from_s(2);
  /// stream name for logs and status
  std::string name = "imu";
};

/// Maps a numeric baud rate to its termios speed constant; false if unsupported.
bool baud_to_speed(int baud, unsigned& speed);

class SerialSource final : public Source {
 public:
  explicit SerialSource(SerialConfig config);
  ~SerialSource() override;
  SerialSource(const SerialSource&) = delete;
  SerialSource& operator=(const SerialSource&) = delete;

  std::string_view name() const override { return config_.name; }
  std::string_view wire_format(std::uint32_t channel) const override {
    return channel == 0 ? wire::kA9Serial : std::string_view{};
  }
  bool open(std::string& error) override;
  /// kData, kTimeout, kEndOfStream (after request_stop), or kDeviceLost while the device is
  /// absent (the read then waits out the back-off, bounded by `timeout`, and retries itself).
  ReadStatus read(RawChunk& chunk, Duration timeout) override;
  void request_stop() override;
  SourceCounters counters() const override;

  /// failed reopen attempts since the device was last lost
  std::uint32_t reopen_attempts() const { return reopen_attempts_; }
  bool is_open() const { return fd_ >= 0; }

 private:
  bool open_device(std::string& error);
  void close_device();
  void mark_lost(const char* why, int err);

  SerialConfig config_;
  int fd_ = -1;
  /// eventfd that wakes a blocked poll() on request_stop()
  int stop_fd_ = -1;
  std::atomic<bool> stop_requested_{false};
  bool ever_opened_ = false;
  bool lost_ = false;
  HostTime next_reopen_;
  Duration backoff_;
  std::uint32_t reopen_attempts_ = 0;
  std::array<std::byte, 4096> buffer_{};

  AtomicSourceCounters counts_;
};

}  // namespace posed::drivers
