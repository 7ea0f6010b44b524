#include "core/lidar/voxel_map.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace posed::lidar {

VoxelMap::VoxelMap(const VoxelMapConfig& config)
    : config_(config),
      inv_voxel_(static_cast<float>(1.0 / config.voxel_m)),
      confirm_s_(static_cast<float>(config.confirm_after_s)),
      confirm_radius_m_(
          static_cast<float>(std::max(config.min_point_distance_m, 0.5 * config.voxel_m))) {
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

void VoxelMap::insert(const std::vector<Eigen::Vector3f>& points_map, std::int64_t stamp_ns) {
  if (!started_) {
    started_ = true;
    map_start_ns_ = stamp_ns;
  }
  const float now_s = static_cast<float>(static_cast<double>(stamp_ns - map_start_ns_) * 1e-9);
  // While the map is younger than the confirmation span every point is matched against: nothing
  // would start the map else. After that, only what scans found again that much later.
  young_ = confirm_s_ > 0 && now_s < confirm_s_;
  const float min_d2 =
      static_cast<float>(config_.min_point_distance_m * config_.min_point_distance_m);
  const float confirm_d2 = confirm_radius_m_ * confirm_radius_m_;
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
        if (confirm_s_ > 0) voxels_.back().first_seen_s.reserve(cap);
      }
    }
    Voxel& voxel = voxels_[it->second];
    std::vector<Eigen::Vector3f>& v = voxel.points;
    if (confirm_s_ <= 0 && v.size() >= cap) continue;  // full, and nothing to confirm
    bool near = false;
    std::size_t stale = v.size();  // a point never found again within the span: transient
    for (std::size_t i = 0; i < v.size(); ++i) {
      const float d2 = (v[i] - p).squaredNorm();
      if (confirm_s_ > 0) {
        float& first = voxel.first_seen_s[i];
        if (first >= 0 && d2 < confirm_d2 && now_s - first >= confirm_s_) {
          first = kConfirmed;  // the same surface, a span later: the world
        } else if (first >= 0 && now_s - first >= 2 * confirm_s_ && stale == v.size()) {
          stale = i;
        }
      }
      if (d2 < min_d2) {
        near = true;
        if (confirm_s_ <= 0) break;
      }
    }
    if (near) continue;
    if (v.size() >= cap) {
      if (stale == v.size()) continue;
      // A full voxel makes room by forgetting what something passing through left.
      v[stale] = p;
      voxel.first_seen_s[stale] = now_s;
      continue;
    }
    v.push_back(p);
    if (confirm_s_ > 0) voxel.first_seen_s.push_back(now_s);
    ++points_;
  }
}

namespace {

/// The 27 voxels around a query's, nearest class first (itself, the 6 sharing a face, the 12
/// sharing an edge, the 8 sharing a corner), so the k best are found early and farther voxels
/// can be skipped without being looked up.
struct Offset {
  int d[3];
};
constexpr std::array<Offset, 27> kByDistance = [] {
  std::array<Offset, 27> out{};
  std::size_t n = 0;
  for (int manhattan = 0; manhattan <= 3; ++manhattan) {
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const int m = (dx != 0) + (dy != 0) + (dz != 0);
          if (m == manhattan) out[n++] = Offset{{dx, dy, dz}};
        }
      }
    }
  }
  return out;
}();

}  // namespace

int VoxelMap::nearest(const Eigen::Vector3f& query, int k, float max_distance_m,
                      Eigen::Vector3f* out) const {
  // A sorted insertion into a tiny array (k <= ~8) beats a heap.
  float best_d2[16];
  const int kk = std::min(k, 16);
  int found = 0;
  const float max_d2 = max_distance_m * max_distance_m;
  const Eigen::Vector3i centre = voxel_of(query);
  // Squared distance from the query to the faces of its voxel, per axis: [lower, 0, upper]. A
  // neighbour voxel's points are at least the sum over its offset axes away, which skips the
  // voxels that cannot hold a better point (made a hair smaller than exact, so float rounding at
  // a voxel face never skips a point that would have been taken).
  const float voxel = static_cast<float>(config_.voxel_m);
  float face_d2[3][3];
  for (int a = 0; a < 3; ++a) {
    const float into = query[a] - static_cast<float>(centre[a]) * voxel;
    const float lower = std::max(0.f, into - 1e-4f), upper = std::max(0.f, voxel - into - 1e-4f);
    face_d2[a][0] = lower * lower;
    face_d2[a][1] = 0.f;
    face_d2[a][2] = upper * upper;
  }
  const bool all = confirm_s_ <= 0 || young_;  // every point is matched against
  for (const Offset& o : kByDistance) {
    const float box_d2 = face_d2[0][o.d[0] + 1] + face_d2[1][o.d[1] + 1] + face_d2[2][o.d[2] + 1];
    if (box_d2 > max_d2 || (found == kk && box_d2 >= best_d2[kk - 1])) continue;
    const auto it = index_.find(key_of(centre + Eigen::Vector3i(o.d[0], o.d[1], o.d[2])));
    if (it == index_.end()) continue;
    const Voxel& cell = voxels_[it->second];
    for (std::size_t i = 0; i < cell.points.size(); ++i) {
      const Eigen::Vector3f& p = cell.points[i];
      const float d2 = (p - query).squaredNorm();
      if (d2 > max_d2 || (found == kk && d2 >= best_d2[kk - 1])) continue;
      if (!all && cell.first_seen_s[i] != kConfirmed) continue;
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
      v.first_seen_s.clear();
      free_.push_back(it->second);
      it = index_.erase(it);
      ++removed;
    } else {
      ++it;
    }
  }
  return removed;
}

std::size_t VoxelMap::confirmed_points() const {
  if (confirm_s_ <= 0) return points_;
  std::size_t n = 0;
  for (const auto& [key, slot] : index_) {
    for (const float first : voxels_[slot].first_seen_s) n += first == kConfirmed;
  }
  return n;
}

void VoxelMap::collect(std::vector<Eigen::Vector3f>& out) const {
  for (const auto& [key, slot] : index_) {
    const Voxel& voxel = voxels_[slot];
    for (std::size_t i = 0; i < voxel.points.size(); ++i) {
      if (confirm_s_ <= 0 || voxel.first_seen_s[i] == kConfirmed) out.push_back(voxel.points[i]);
    }
  }
}

void VoxelMap::clear() {
  index_.clear();
  voxels_.clear();
  free_.clear();
  points_ = 0;
  started_ = false;
  young_ = false;
}

}  // namespace posed::lidar
