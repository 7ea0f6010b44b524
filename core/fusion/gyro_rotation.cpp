#include "core/fusion/gyro_rotation.hpp"

#include <utility>

#include "core/math/so3.hpp"

namespace posed::fusion {

std::optional<Eigen::Matrix3d> gyro_rotation(const ImuBuffer& imu, HostTime t0, HostTime t1,
                                             const Eigen::Vector3d& gyro_bias_radps,
                                             std::vector<ImuSample>& scratch) {
  const bool backwards = t1 < t0;
  const HostTime a = backwards ? t1 : t0;
  const HostTime b = backwards ? t0 : t1;
  if (imu.empty() || a < imu.oldest_stamp() || b > imu.newest_stamp()) return std::nullopt;
  const std::optional<ImuSample> at_a = imu.interpolate(a);
  const std::optional<ImuSample> at_b = imu.interpolate(b);
  if (!at_a || !at_b) return std::nullopt;
  imu.samples_between(a, b, scratch);
  // The integration nodes: a, the samples strictly inside (a, b), b.
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  HostTime prev_t = a;
  Eigen::Vector3d prev_w = at_a->angular_velocity_radps;
  const auto step = [&](HostTime t, const Eigen::Vector3d& w) {
    const double dt = (t - prev_t).seconds();
    if (dt > 0) R = R * so3::exp((0.5 * (prev_w + w) - gyro_bias_radps) * dt);
    prev_t = t;
    prev_w = w;
  };
  for (const ImuSample& s : scratch) {
    if (s.stamp > a && s.stamp < b) step(s.stamp, s.angular_velocity_radps);
  }
  step(b, at_b->angular_velocity_radps);
  // R is R_ba_bb; the caller asked for R_b0_b1.
  return backwards ? Eigen::Matrix3d(R.transpose()) : R;
}

}  // namespace posed::fusion
