#pragma once
// Sensor faults laid over a simulated run (`posectl sim --fault KIND@T+D`, issue 22): a SimSink
// between the simulator and the recording that drops, freezes, blanks, corrupts, duplicates or
// reorders what the devices deliver inside a window of true time, as real devices fail. The
// world and the ground truth are untouched, so a faulted run is judged against the same truth
// as a clean one of the same seed; the faults go into the recording's metadata so an evaluation
// knows when they happened.
//
// Faults act on the bytes the devices send, in the wire formats of raw_channels.hpp:
//   lidar_outage     the lidar's data and position packets stop (a cable shaken loose)
//   imu_gap          the A9's frames stop
//   camera_blackout  the visible and thermal frames keep coming, black (visible: Y 16, U V 128)
//                    or flat at the frame's mean (thermal): a covered lens, a blinding light
//   camera_freeze    the visible and thermal frames repeat the last frame before the window
//   thermal_ffc      the thermal frames repeat the last one (the PLUG 617's flat-field
//                    correction shutter; ~0.5 s)
//   corrupt_burst    every stream's messages get random bytes flipped (1 in 64, seeded)
//   duplicate        every message is delivered twice
//   reorder          each stream's messages arrive in swapped pairs (the later one first)
//   imu_reset        the A9 reboots: silent for the window, then its µs counter restarts from
//                    where a counter started at the window's beginning would be (CRC redone)
//   pps_loss         the lidar loses its PPS: for the window, position packets say "absent" and
//                    the device clock free-runs kFreeRunPpm fast; at the end it re-locks and its
//                    time steps back onto the PPS-aligned line

#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "tools/sim/sim_sink.hpp"

namespace posed::sim {

enum class FaultKind {
  kLidarOutage,
  kImuGap,
  kCameraBlackout,
  kCameraFreeze,
  kThermalFfc,
  kCorruptBurst,
  kDuplicate,
  kReorder,
  kImuReset,
  kPpsLoss,
};

/// How fast the lidar's clock runs without PPS (its crystal, a VLP-32C-class part) [ppm]
inline constexpr double kFreeRunPpm = 100.0;

struct Fault {
  FaultKind kind = FaultKind::kLidarOutage;
  /// from the start of the run (true time) [s]
  double start_s = 0;
  /// [s]
  double duration_s = 0;
  bool active(double t_s) const { return t_s >= start_s && t_s < start_s + duration_s; }
};

std::string_view to_string(FaultKind kind);
/// "lidar_outage@30+5"
std::string to_string(const Fault& fault);
/// Every kind's name, comma-separated (for --help and errors).
std::string fault_kind_names();
/// Parses "KIND@T+D" (T, D in seconds; D > 0). False with `error` saying what is wrong.
bool parse_fault(std::string_view text, Fault& out, std::string& error);

/// What the faults did to each stream.
struct FaultCounts {
  std::uint64_t dropped = 0;
  std::uint64_t blanked = 0;
  std::uint64_t frozen = 0;
  std::uint64_t corrupted = 0;
  std::uint64_t duplicated = 0;
  std::uint64_t reordered = 0;
  /// messages whose device time the fault rewrote (imu_reset, pps_loss)
  std::uint64_t restamped = 0;
};

class FaultSink : public SimSink {
 public:
  /// `host_epoch_ns`: the host time of the run's start (SimOptions::host_epoch_ns).
  FaultSink(SimSink& inner, std::vector<Fault> faults, std::int64_t host_epoch_ns,
            std::uint64_t seed);

  int add_stream(const SimStream& stream) override;
  bool write_raw(int stream, HostTime host_time, std::span<const std::byte> bytes) override;
  bool write_ground_truth(HostTime stamp, const GroundTruthPose& pose) override;
  /// Writes a message still held back by `reorder` (call at the end of the run).
  bool finish();

  /// Per stream id, as add_stream() returned them.
  const std::vector<FaultCounts>& counts() const { return counts_; }
  const std::vector<SimStream>& streams() const { return streams_; }

 private:
  struct Held {
    bool held = false;
    std::vector<std::byte> bytes;
  };
  bool is_frame(int stream) const;
  bool applies(const Fault& f, int stream) const;
  /// imu_reset: the A9 frame's counter minus every restart behind `t_s`; false if unchanged.
  bool restart_counter(double t_s, std::vector<std::byte>& frame);
  /// pps_loss: the lidar packet's µs past the hour free-running, PPS status absent.
  bool free_run(double t_s, int stream, std::vector<std::byte>& packet) const;

  SimSink& inner_;
  std::vector<Fault> faults_;
  std::int64_t host_epoch_ns_;
  std::mt19937_64 random_;
  std::vector<SimStream> streams_;
  std::vector<FaultCounts> counts_;
  /// per stream: the last frame delivered before a freeze began
  std::vector<std::vector<std::byte>> last_frame_;
  /// per stream: a message reorder holds back until the next one
  std::vector<Held> held_;
  HostTime last_host_time_;
  /// per fault: imu_reset's counter at the reboot (the first frame it silenced) [µs]
  std::vector<std::optional<std::uint32_t>> reset_counter_us_;
};

}  // namespace posed::sim
