#include "core/mapping/place_recognition.hpp"

#include <cmath>

#include "core/mapping/registration.hpp"

namespace posed::mapping {

Eigen::Matrix3d levelling(const Eigen::Matrix3d& R_world_base) {
  const Eigen::Vector3d heading = R_world_base.col(0);
  const double yaw = std::atan2(heading.y(), heading.x());
  return Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_world_base;
}

DescribedScan describe_scan(std::span<const Eigen::Vector3f> points_base,
                            const Eigen::Matrix3d& R_world_base, double context_range_m,
                            double cloud_range_m, double voxel_m, const ScanContextConfig& config) {
  DescribedScan out;
  out.R_level_base = levelling(R_world_base);
  std::vector<Eigen::Vector3f> in_range;
  std::vector<Eigen::Vector3f> level;
  in_range.reserve(points_base.size());
  level.reserve(points_base.size());
  const Eigen::Matrix3f R_level_base = out.R_level_base.cast<float>();
  const auto context_range2 = static_cast<float>(context_range_m * context_range_m);
  const auto cloud_range2 = static_cast<float>(cloud_range_m * cloud_range_m);
  for (const Eigen::Vector3f& p : points_base) {
    if (!p.allFinite()) {
      continue;
    }
    const float range2 = p.squaredNorm();
    if (range2 <= cloud_range2) {
      in_range.push_back(p);
    }
    if (range2 <= context_range2) {
      level.push_back(R_level_base * p);
    }
  }
  out.context = make_scan_context(level, config);
  out.points_base = thin_cloud(in_range, voxel_m);
  return out;
}

}  // namespace posed::mapping
