#include "core/lidar/map_cloud.hpp"

#include <algorithm>
#include <cmath>

namespace posed::lidar {
namespace {

/// 21 bits per axis, offset so negative indices pack: ±1048576 voxels (±105 km at 0.1 m).
std::uint64_t pack(const Eigen::Vector3d& p, double inv_voxel) {
  constexpr std::int64_t kOffset = 1 << 20;
  constexpr std::int64_t kMask = (1 << 21) - 1;
  std::uint64_t key = 0;
  for (int i = 0; i < 3; ++i) {
    const auto v = static_cast<std::int64_t>(std::floor(p[i] * inv_voxel)) + kOffset;
    key = (key << 21) | static_cast<std::uint64_t>(std::clamp<std::int64_t>(v, 0, kMask));
  }
  return key;
}

}  // namespace

MapCloud::MapCloud(double voxel_m) : voxel_m_(voxel_m > 0 ? voxel_m : 0.1) {}

void MapCloud::add(std::span<const ScanPoint> points_lidar, const Eigen::Isometry3d& T_map_lidar) {
  const double inv = 1.0 / voxel_m_;
  for (const ScanPoint& sp : points_lidar) {
    const Eigen::Vector3d p = T_map_lidar * sp.p.cast<double>();
    if (!p.allFinite()) continue;
    Accum& a = voxels_[pack(p, inv)];
    a.sum += p;
    ++a.count;
  }
}

void MapCloud::collect(std::vector<Eigen::Vector3f>& out) const {
  std::vector<std::uint64_t> keys;
  keys.reserve(voxels_.size());
  for (const auto& [key, accum] : voxels_) keys.push_back(key);
  std::sort(keys.begin(), keys.end());
  out.reserve(out.size() + keys.size());
  for (const std::uint64_t key : keys) {
    const Accum& a = voxels_.at(key);
    out.push_back((a.sum / static_cast<double>(a.count)).cast<float>());
  }
}

}  // namespace posed::lidar
