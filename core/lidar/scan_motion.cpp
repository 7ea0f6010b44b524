#include "core/lidar/scan_motion.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace posed::lidar {

Eigen::Isometry3d ScanMotion::at(HostTime t) const {
  if (stamps.empty()) return Eigen::Isometry3d::Identity();
  if (t <= stamps.front()) return T_end_t.front();
  if (t >= stamps.back()) return T_end_t.back();
  const auto it = std::upper_bound(stamps.begin(), stamps.end(), t);
  const auto i = static_cast<std::size_t>(it - stamps.begin());
  const Eigen::Isometry3d& a = T_end_t[i - 1];
  const Eigen::Isometry3d& b = T_end_t[i];
  const double s = static_cast<double>((t - stamps[i - 1]).ns) /
                   static_cast<double>((stamps[i] - stamps[i - 1]).ns);
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() =
      Eigen::Quaterniond(a.linear()).slerp(s, Eigen::Quaterniond(b.linear())).toRotationMatrix();
  out.translation() = a.translation() + s * (b.translation() - a.translation());
  return out;
}

void deskew(std::span<const LidarPoint> points, HostTime scan_start, const ScanMotion& motion,
            int columns, float min_range_m, float max_range_m, std::vector<ScanPoint>& out) {
  out.clear();
  if (points.empty()) return;
  const float column_per_rad = static_cast<float>(columns) / (2.0f * std::numbers::pi_v<float>);
  // Firings come in time order; the motion changes little over one firing cycle (55 µs), so the
  // transform is recomputed only when the offset moves on by more than `step`.
  constexpr std::int32_t kStepNs = 50'000;
  std::int32_t cached_offset = std::numeric_limits<std::int32_t>::min();
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();
  Eigen::Vector3f t = Eigen::Vector3f::Zero();
  const bool moving = !motion.stamps.empty();
  for (const LidarPoint& lp : points) {
    const Eigen::Vector3f raw(lp.x, lp.y, lp.z);
    const float range = raw.norm();
    if (!std::isfinite(range) || range < min_range_m || range > max_range_m) continue;
    if (moving && std::abs(lp.offset_ns - cached_offset) > kStepNs) {
      cached_offset = lp.offset_ns;
      const Eigen::Isometry3d T = motion.at(scan_start + Duration::from_ns(lp.offset_ns));
      R = T.linear().cast<float>();
      t = T.translation().cast<float>();
    }
    ScanPoint sp;
    sp.p = moving ? Eigen::Vector3f(R * raw + t) : raw;
    sp.range_m = range;
    sp.intensity = lp.intensity;
    sp.ring = lp.ring;
    sp.offset_ns = lp.offset_ns;
    // Azimuth of the firing, counter-clockwise from x (the ROS frame), into [0, columns).
    float azimuth = std::atan2(raw.y(), raw.x());
    if (azimuth < 0) azimuth += 2.0f * std::numbers::pi_v<float>;
    sp.column = static_cast<std::uint16_t>(
        std::min(columns - 1, static_cast<int>(azimuth * column_per_rad)));
    out.push_back(sp);
  }
}

}  // namespace posed::lidar
