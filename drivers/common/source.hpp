#pragma once
// A Source only moves bytes (DESIGN.md, Data flow): a live socket/device or a recording, behind
// one interface, never a mode flag inside a driver. The recorder taps RawChunks here, before
// decoding, so a replay exercises decoding, clock sync and fusion exactly as on the robot.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "core/time.hpp"

namespace posed::drivers {

/// One read: the exact bytes the device gave, and when the host received them.
struct RawChunk {
  /// valid until the next read() on the same Source
  std::span<const std::byte> bytes;
  /// host CLOCK_MONOTONIC when the bytes arrived (live) or the recorded log time (replay)
  HostTime host_receive;
  /// which of the Source's channels, e.g. 0 = lidar data port, 1 = position port
  std::uint32_t channel = 0;
};

enum class ReadStatus : std::uint8_t {
  kData,         ///< `chunk` holds bytes
  kTimeout,      ///< nothing arrived within the timeout; call again
  kEndOfStream,  ///< a recording ended, or the Source was stopped; no more data will come
  kDeviceLost,   ///< the device went away; the Source reopens it itself on later reads
};

constexpr std::string_view to_string(ReadStatus s) {
  switch (s) {
    case ReadStatus::kData:
      return "data";
    case ReadStatus::kTimeout:
      return "timeout";
    case ReadStatus::kEndOfStream:
      return "end_of_stream";
    case ReadStatus::kDeviceLost:
      return "device_lost";
  }
  return "unknown";
}

/// Counters every Source keeps; read by the status publisher from another thread via snapshot.
struct SourceCounters {
  std::uint64_t chunks = 0;    ///< reads that returned data
  std::uint64_t bytes = 0;     ///< [B]
  std::uint64_t rejected = 0;  ///< chunks refused at the Source (wrong sender, oversize, ...)
  std::uint64_t reopened = 0;  ///< times the device was lost and opened again
};

/// SourceCounters as a Source keeps them: counted by its reading thread, read by the status
/// snapshot from any other thread (relaxed: each figure is a monotonic count on its own).
struct AtomicSourceCounters {
  std::atomic<std::uint64_t> chunks{0};    ///< reads that returned data
  std::atomic<std::uint64_t> bytes{0};     ///< [B]
  std::atomic<std::uint64_t> rejected{0};  ///< chunks refused at the Source
  std::atomic<std::uint64_t> reopened{0};  ///< times the device was lost and opened again

  /// One chunk of `size` bytes handed out.
  void count_chunk(std::size_t size) {
    chunks.fetch_add(1, std::memory_order_relaxed);
    bytes.fetch_add(size, std::memory_order_relaxed);
  }
  SourceCounters snapshot() const {
    return {chunks.load(std::memory_order_relaxed), bytes.load(std::memory_order_relaxed),
            rejected.load(std::memory_order_relaxed), reopened.load(std::memory_order_relaxed)};
  }
};

class Source {
 public:
  virtual ~Source() = default;
  /// Stream name used in logs, status and recordings ("imu", "lidar", ...).
  virtual std::string_view name() const = 0;
  /// Opens the device or file. On failure returns false and says why in `error` (with the
  /// path/address); the caller may retry. A Source that is already open returns true.
  virtual bool open(std::string& error) = 0;
  /// Waits up to `timeout` for the next chunk. Never throws on bad data; never blocks longer.
  virtual ReadStatus read(RawChunk& chunk, Duration timeout) = 0;
  /// Makes a blocked or later read() return kEndOfStream. Safe from any thread.
  virtual void request_stop() = 0;
  virtual SourceCounters counters() const = 0;
  /// What the bytes of `channel` are (drivers/common/wire_format.hpp, or a camera pixel format);
  /// empty for a channel this Source never produces. Stages choose their decoder by it.
  virtual std::string_view wire_format(std::uint32_t channel) const = 0;
  /// Live: data arrives in real time and must never wait for the pipeline (queues drop the
  /// oldest). Not live (recordings, generators at full speed): nothing may be lost, so the
  /// pipeline blocks the Source instead, and results are deterministic.
  virtual bool live() const { return true; }
};

}  // namespace posed::drivers
