#pragma once
// The one thing posed reads from DDS: an initial pose, as RViz's "2D Pose Estimate" tool
// publishes it (geometry_msgs/PoseWithCovarianceStamped on /initialpose, i.e. DDS topic
// rt/initialpose, in RViz's fixed frame, normally "map"). Localisation on a saved map (--map)
// starts from it. A person clicks it, so it is rare: the reader keeps the newest few and the
// consumer polls, never blocks.

#include <Eigen/Geometry>
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "core/time.hpp"
#include "daemon/dds/messages.hpp"

namespace posed::dds {

class Publisher;
namespace detail {
class Participant;
}

/// One received initial pose: the base's pose in `frame_id`, with its covariance.
struct InitialPose {
  /// header.stamp (wall clock, UNIX epoch; RViz stamps the click) [ns]
  std::int64_t stamp_ns = 0;
  /// header.frame_id: the frame the pose is in (RViz's fixed frame; posed expects the map's)
  std::string frame_id;
  /// pose of the base in frame_id (maps base points into frame_id) [m, -]
  Eigen::Isometry3d T_frame_base = Eigen::Isometry3d::Identity();
  /// row-major 6x6 over (x, y, z, rot x, rot y, rot z) [m^2, m*rad, rad^2]; RViz sets x, y
  /// (0.25 m^2) and yaw ((pi/12)^2 rad^2), the rest 0
  std::array<double, 36> covariance{};
};

/// A reader on DdsConfig::initial_pose_topic with RViz's QoS (reliable, volatile, keep-last 5).
/// Thread-safety: take_newest from one consumer thread; the counters from any thread.
class InitialPoseReader {
 public:
  /// On its own participant (config's domain, Cyclone XML and DDS Security). nullptr with
  /// `error` set on failure, or when config.initial_pose_topic is empty (error empty then).
  static std::unique_ptr<InitialPoseReader> create(const DdsConfig& config, std::string& error);
  /// On `publisher`'s participant (created from the same `config`): what the daemon does.
  static std::unique_ptr<InitialPoseReader> create(const Publisher& publisher,
                                                   const DdsConfig& config, std::string& error);
  ~InitialPoseReader();
  InitialPoseReader(const InitialPoseReader&) = delete;
  InitialPoseReader& operator=(const InitialPoseReader&) = delete;

  /// Never blocks. Takes every waiting sample and returns the newest one that passes the checks
  /// (finite position; finite quaternion with |‖q‖ − 1| <= 1e-3, then normalised); the older
  /// good ones are counted in dropped(), the bad ones in refused() and logged (at most one line
  /// per 5 s, naming the topic and the fault). nullopt when none waits.
  std::optional<InitialPose> take_newest();

  /// Good samples a newer one replaced before they were taken [count].
  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  /// Samples refused for a non-finite position or a non-finite or non-unit quaternion [count].
  std::uint64_t refused() const { return refused_.load(std::memory_order_relaxed); }
  /// Writers currently matched (RViz, posectl initialpose) [count].
  std::uint32_t matched_publishers() const;
  /// The DDS topic read, e.g. "rt/initialpose".
  const std::string& topic() const { return topic_; }

 private:
  InitialPoseReader(std::shared_ptr<detail::Participant> participant, std::string topic);
  bool open(std::string& error);
  /// Logs a refusal unless one was logged in the last 5 s (then counts it for the next line).
  void log_refused(const std::string& why, HostTime now);

  std::shared_ptr<detail::Participant> participant_;
  std::string topic_;
  std::int32_t topic_entity_ = 0;  // dds_entity_t, without dds.h in this header
  std::int32_t reader_ = 0;
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::uint64_t> refused_{0};
  /// rate limit of the refusal log (consumer thread only)
  std::optional<HostTime> last_log_;
  std::uint64_t unlogged_refusals_ = 0;
};

}  // namespace posed::dds
