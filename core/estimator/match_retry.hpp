#pragma once
// What to make of a scan matched again from the lidar's own constant-velocity guess, after the
// match from the IMU's prediction failed (too few correspondences) or landed implausibly far
// from it. The retry exists for a faulty or saturated IMU: then the lidar alone still knows, and
// the window restarts from it. But a failed first match is not always the IMU's fault:
// - In a turn close to a plain wall the scan can have too few correspondences at the IMU's
//   prediction and enough a few decimetres away. If the retry ends near the IMU's prediction,
//   the IMU was right: the retry is the scan's match, and the window goes on.
// - A degenerate retry (a corridor, a roadway) is the constant-velocity guess itself along its
//   weak directions, so it cannot contradict the IMU there: restarting from it threw away what
//   the window (and the cameras in it) knew. On the simulated corridor, seed 60, one such restart
//   in a turn took the estimate 19 m off (ATE 4.51 m; 1.17 m without it).
// Only a retry that pins every direction and ends far from the IMU's prediction makes the IMU
// suspect.

#include <cstdint>

namespace posed::estimator {

enum class MatchRetryVerdict : std::uint8_t {
  kReject,      ///< the scan is not used
  kUse,         ///< the retry is the scan's match; the IMU's preintegration joins the window
  kImuSuspect,  ///< the IMU contradicts the lidar: restart the window from the retry
};

/// `near_lidar_guess`: the retry is plausible against the constant-velocity guess it started
/// from; `near_imu_prediction`: against the IMU's prediction; `degenerate_directions`: the
/// retry's.
constexpr MatchRetryVerdict judge_match_retry(bool near_lidar_guess, bool near_imu_prediction,
                                              int degenerate_directions) {
  if (!near_lidar_guess) return MatchRetryVerdict::kReject;
  if (near_imu_prediction) return MatchRetryVerdict::kUse;
  return degenerate_directions == 0 ? MatchRetryVerdict::kImuSuspect : MatchRetryVerdict::kReject;
}

}  // namespace posed::estimator
