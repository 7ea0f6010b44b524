#pragma once
// Writes a recorded serial byte stream (the A9's) to a pseudo-terminal, so a serial driver (posed's
// SerialSource, minicom, ...) reads it as from the device: posix_openpt/grantpt/unlockpt, the
// line discipline in raw mode (no echo, no CR/LF translation, no signals on 0x03), and a
// symlink at a fixed path so a config can name the device (`imu.serial_device: /tmp/a9`).
//
// Like a UART, the pty does not keep bytes for a reader that is not there: while no process has
// the slave open (the master then polls POLLHUP) written bytes are discarded and counted, and
// bytes a slow reader leaves in a full pty buffer are dropped and counted as overrun, instead of
// delaying the schedule. Whatever the reader writes back is read and discarded.

#include <atomic>
#include <cstdint>
#include <span>
#include <string>

#include "core/time.hpp"

namespace posed::hil {

struct PtyCounters {
  std::uint64_t writes = 0;             ///< chunks written in full
  std::uint64_t bytes = 0;              ///< bytes written [B]
  std::uint64_t bytes_no_reader = 0;    ///< discarded: no process had the pty open [B]
  std::uint64_t bytes_overrun = 0;      ///< dropped: the pty buffer was full (slow reader) [B]
  std::uint64_t bytes_from_reader = 0;  ///< written by the reader to the device, discarded [B]
};

class PtyEmitter {
 public:
  /// `link_path`: where the symlink to the slave goes ("" = none; slave_path() names the pty).
  explicit PtyEmitter(std::string link_path) : link_path_(std::move(link_path)) {}
  /// Closes the pty and removes the symlink if it still points at this pty.
  ~PtyEmitter();
  PtyEmitter(const PtyEmitter&) = delete;
  PtyEmitter& operator=(const PtyEmitter&) = delete;

  /// Creates the pty in raw mode and the symlink (atomically replacing an older symlink; a file
  /// or directory at the path is refused). false + `error` ("pty LINK: reason").
  bool open(std::string& error);
  /// Closes the pty and removes the symlink, as a pulled USB adapter's device goes away: a reader
  /// gets a hang-up. open() makes a new one at the same link.
  void close();
  /// true while some process has the slave open.
  bool has_reader();
  /// Waits until has_reader(), `timeout` passes, or `stop` is set; returns has_reader().
  bool wait_for_reader(Duration timeout, const std::atomic<bool>& stop);
  /// Writes `bytes` without blocking; false when some or all were discarded (counted).
  bool write(std::span<const std::byte> bytes);

  PtyCounters counters() const;
  /// the pty's own name, e.g. /dev/pts/7
  const std::string& slave_path() const { return slave_path_; }
  const std::string& link_path() const { return link_path_; }

 private:
  void drain_reader_output();

  std::string link_path_;
  std::string slave_path_;
  int master_ = -1;
  bool linked_ = false;
  std::atomic<std::uint64_t> writes_{0}, bytes_{0}, no_reader_{0}, overrun_{0}, from_reader_{0};
};

}  // namespace posed::hil
