#pragma once
// Pose interpolation at arbitrary host times: linear in position, SLERP (shortest arc) in
// rotation, as seed 002 does to bring one odometry's poses to another measurement's stamps
// before forming relative-pose factors. PoseHistory keeps a bounded window of recent poses and
// answers at(t).
//
// Extrapolation is refused beyond a configurable margin (std::nullopt): a pose guessed far
// outside the data is worse than no pose, and the caller can wait or count instead.
//
// Pure: no clock is read; events travel as return values and counters.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "core/sync/stamped_ring.hpp"
#include "core/time.hpp"

namespace posed {

/// A rigid-body pose T_world_body at one instant.
struct Pose {
  /// host-clock time of the pose [ns]
  HostTime stamp;
  /// position of the body origin in the world frame [m]
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  /// rotation body -> world (unit quaternion; q and -q are the same rotation) [1]
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
};

/// The pose at `t` between `a` and `b` (a.stamp <= b.stamp): position linear in time, rotation
/// by SLERP along the shortest arc (q and -q are treated as the same rotation). Exact at the
/// endpoints (returns a's or b's p and q unchanged). For t outside [a.stamp, b.stamp] by at
/// most `max_extrapolation` the same formulas extrapolate; beyond it, or if a.stamp > b.stamp,
/// or if a.stamp == b.stamp and t is not within the margin of it, nullopt. With equal stamps
/// there is no motion to extend, so a's pose is returned (restamped) within the margin.
std::optional<Pose> interpolate_pose(const Pose& a, const Pose& b, HostTime t,
                                     Duration max_extrapolation = Duration::from_ns(0));

/// Rotation `s` of the way from qa to qb along the shortest arc (s in [0, 1] interpolates,
/// outside extrapolates on the same great circle). Normalises its inputs.
Eigen::Quaterniond slerp_shortest(const Eigen::Quaterniond& qa, const Eigen::Quaterniond& qb,
                                  double s);

struct PoseHistoryConfig {
  /// poses kept; the oldest is overwritten when full [1]
  std::size_t capacity = 256;
  /// how far before the oldest / after the newest pose at() extrapolates [ns]
  Duration max_extrapolation = Duration::from_ns(0);
};

struct PoseHistoryCounters {
  /// poses stored [1]
  std::uint64_t accepted = 0;
  /// poses not newer than the newest held, discarded (never reordered) [1]
  std::uint64_t out_of_order_dropped = 0;
  /// poses overwritten because the history was full [1]
  std::uint64_t overwritten = 0;
};

/// A bounded window of poses in stamp order (capacity fixed at construction, no allocation
/// afterwards).
class PoseHistory {
 public:
  explicit PoseHistory(const PoseHistoryConfig& config);

  /// Stores `pose` if it is newer than every pose held; otherwise drops it (counted) and
  /// returns false.
  bool push(const Pose& pose);

  /// The pose at `t`: interpolated between the two held poses that bracket t (exact on a held
  /// pose), extrapolated from the two oldest / newest within max_extrapolation, nullopt
  /// otherwise or when empty. A single held pose answers only within the margin of its stamp.
  std::optional<Pose> at(HostTime t) const;

  std::size_t size() const { return ring_.size(); }
  bool empty() const { return ring_.empty(); }
  /// the i-th oldest pose held; i < size()
  const Pose& operator[](std::size_t i) const { return ring_[i]; }

  const PoseHistoryCounters& counters() const { return counters_; }
  const PoseHistoryConfig& config() const { return config_; }

 private:
  PoseHistoryConfig config_;
  StampedRing<Pose> ring_;
  PoseHistoryCounters counters_;
};

}  // namespace posed
