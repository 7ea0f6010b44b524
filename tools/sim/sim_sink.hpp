#pragma once
// Where the simulator's output goes. The simulator only knows this interface, so every test runs
// without files; posectl sim binds it to the MCAP Recorder (tools/posectl/cmd_sim.cpp).
//
// Streams follow drivers/recording/raw_channels.hpp: one stream per (Source, source channel),
// the bytes exactly as the device delivers them, stamped with host arrival time.
// Calls come in non-decreasing host time across all streams (the simulator merges them), so a
// sink may write them straight to a log-time-ordered file.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "core/time.hpp"

namespace posed::sim {

struct SimStream {
  /// Source name ("imu", "lidar", "visible", "thermal", "depth")
  std::string name;
  /// how to decode the bytes (raw_channels.hpp kWire*, or a camera pixel format: "yuyv", "y8",
  /// "y16", "z16")
  std::string wire_format;
  /// the Source channel (lidar: 0 = data port, 1 = position port)
  std::uint32_t source_channel = 0;
  /// sensor configuration for the channel record (rates, geometry, clock model)
  std::map<std::string, std::string> metadata;
};

/// base_link (the IMU frame) in map at one instant.
struct GroundTruthPose {
  /// [m]
  Eigen::Vector3d p_map_base_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_map_base = Eigen::Quaterniond::Identity();
  /// velocity in map [m/s]
  Eigen::Vector3d v_map_mps = Eigen::Vector3d::Zero();
  /// angular rate in base axes [rad/s]
  Eigen::Vector3d w_base_radps = Eigen::Vector3d::Zero();
};

class SimSink {
 public:
  virtual ~SimSink() = default;
  /// Declares a stream before any data; returns its id (≥ 0), or -1 when the sink refuses it.
  virtual int add_stream(const SimStream& stream) = 0;
  /// One chunk as a Source's read() would return it. false: the sink failed (stop).
  virtual bool write_raw(int stream, HostTime host_time, std::span<const std::byte> bytes) = 0;
  /// The true pose at `stamp` (host time base: simulation start + true time).
  virtual bool write_ground_truth(HostTime stamp, const GroundTruthPose& pose) = 0;
};

/// FNV-1a 64 over everything written (stream declarations, stamps, bytes, poses): the
/// determinism check in tests and `posectl bench sim`.
class HashSink : public SimSink {
 public:
  int add_stream(const SimStream& stream) override;
  bool write_raw(int stream, HostTime host_time, std::span<const std::byte> bytes) override;
  bool write_ground_truth(HostTime stamp, const GroundTruthPose& pose) override;
  std::uint64_t hash() const { return hash_; }
  /// messages per stream id
  const std::vector<std::uint64_t>& messages() const { return messages_; }
  std::uint64_t bytes() const { return bytes_; }
  std::uint64_t poses() const { return poses_; }

 private:
  void mix(const void* data, std::size_t size);
  std::uint64_t hash_ = 0xcbf29ce484222325ull;
  std::vector<std::uint64_t> messages_;
  std::uint64_t bytes_ = 0, poses_ = 0;
};

/// Keeps everything in memory (tests).
class MemorySink : public SimSink {
 public:
  struct Message {
    int stream = 0;
    HostTime host_time;
    std::vector<std::byte> bytes;
  };
  struct Pose {
    HostTime stamp;
    GroundTruthPose pose;
  };
  int add_stream(const SimStream& stream) override;
  bool write_raw(int stream, HostTime host_time, std::span<const std::byte> bytes) override;
  bool write_ground_truth(HostTime stamp, const GroundTruthPose& pose) override;
  /// id of the stream with this name and source channel, or -1
  int find(const std::string& name, std::uint32_t source_channel = 0) const;

  std::vector<SimStream> streams;
  std::vector<Message> messages;
  std::vector<Pose> poses;
};

}  // namespace posed::sim
