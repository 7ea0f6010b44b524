#include "core/lidar/voxel_map.hpp"

#include <algorithm>
#include <cmath>

namespace posed::lidar {

VoxelMap::VoxelMap(const VoxelMapConfig& config)
    : config_(config), inv_voxel_(static_cast<float>(1.0 / config.voxel_m)) {
  index_.reserve(1 << 16);
}

Eigen::Vector3i VoxelMap::voxel_of(const Eigen::Vector3f& p) const {
  return {static_cast<int>(std::floor(p.x() * inv_voxel_)),
          static_cast<int>(std::floor(p.y() * inv_voxel_)),
          static_cast<int>(std::floor(p.z() * inv_voxel_))};
}

std::uint64_t VoxelMap::key_of(const Eigen::Vector3i& v) const {
  const auto axis = [](int c) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(c) + (1 << 20)) & 0x1FFFFF;
  };
  return (axis(v.x()) << 42) | (axis(v.y()) << 21) | axis(v.z());
}

void VoxelMap::insert(const std::vector<Eigen::Vector3f>& points_map) {
  const float min_d2 =
      static_cast<float>(config_.min_point_distance_m * config_.min_point_distance_m);
  const auto cap = static_cast<std::size_t>(config_.max_points_per_voxel);
  for (const Eigen::Vector3f& p : points_map) {
    const std::uint64_t key = key_of(voxel_of(p));
    auto [it, inserted] = index_.try_emplace(key, 0u);
    if (inserted) {
      if (!free_.empty()) {
        it->second = free_.back();
        free_.pop_back();
      } else {
        it->second = static_cast<std::uint32_t>(voxels_.size());
        voxels_.emplace_back();
        voxels_.back().points.reserve(cap);
      }
    }
    std::vector<Eigen::Vector3f>& v = voxels_[it->second].points;
    if (v.size() >= cap) continue;
    bool near = false;
    for (const Eigen::Vector3f& q : v) {
      if ((q - p).squaredNorm() < min_d2) {
        near = true;
        break;
      }
    }
    if (near) continue;
    v.push_back(p);
    ++points_;
  }
}

int VoxelMap::nearest(const Eigen::Vector3f& query, int k, float max_distance_m,
                      Eigen::Vector3f* out) const {
  // A sorted insertion into a tiny array (k <= ~8) beats a heap.
  float best_d2[16];
  const int kk = std::min(k, 16);
  int found = 0;
  const float max_d2 = max_distance_m * max_distance_m;
  const Eigen::Vector3i centre = voxel_of(query);
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dz = -1; dz <= 1; ++dz) {
        const auto it = index_.find(key_of(centre + Eigen::Vector3i(dx, dy, dz)));
        if (it == index_.end()) continue;
        for (const Eigen::Vector3f& p : voxels_[it->second].points) {
          const float d2 = (p - query).squaredNorm();
          if (d2 > max_d2 || (found == kk && d2 >= best_d2[kk - 1])) continue;
          int pos = found < kk ? found++ : kk - 1;
          while (pos > 0 && best_d2[pos - 1] > d2) {
            best_d2[pos] = best_d2[pos - 1];
            out[pos] = out[pos - 1];
            --pos;
          }
          best_d2[pos] = d2;
          out[pos] = p;
        }
      }
    }
  }
  return found;
}

std::size_t VoxelMap::remove_far_from(const Eigen::Vector3f& centre, double radius_m) {
  const float r2 = static_cast<float>(radius_m * radius_m);
  std::size_t removed = 0;
  for (auto it = index_.begin(); it != index_.end();) {
    Voxel& v = voxels_[it->second];
    if (!v.points.empty() && (v.points.front() - centre).squaredNorm() > r2) {
      points_ -= v.points.size();
      v.points.clear();
      free_.push_back(it->second);
      it = index_.erase(it);
      ++removed;
    } else {
      ++it;
    }
  }
  return removed;
}

void VoxelMap::collect(std::vector<Eigen::Vector3f>& out) const {
  for (const auto& [key, slot] : index_) {
    const auto& pts = voxels_[slot].points;
    out.insert(out.end(), pts.begin(), pts.end());
  }
}

void VoxelMap::clear() {
  index_.clear();
  voxels_.clear();
  free_.clear();
  points_ = 0;
}

}  // namespace posed::lidar
