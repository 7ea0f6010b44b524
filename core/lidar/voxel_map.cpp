#include "core/lidar/voxel_map.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace posed::lidar {

VoxelMap::VoxelMap(const VoxelMapConfig& config)
    : config_(config),
      inv_voxel_(static_cast<float>(1.0 / config.voxel_m)),
      cap_(static_cast<std::size_t>(std::max(config.max_points_per_voxel, 1))),
      confirm_s_(static_cast<float>(config.confirm_after_s)),
      confirm_radius_m_(
          static_cast<float>(std::max(config.min_point_distance_m, 0.5 * config.voxel_m))) {}

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

std::uint32_t VoxelMap::slot_for(std::uint64_t key) {
  auto [slot, inserted] = index_.try_emplace(key);
  if (!inserted) return *slot;
  if (!free_.empty()) {
    *slot = free_.back();
    free_.pop_back();
  } else {
    *slot = static_cast<std::uint32_t>(slot_key_.size());
    slot_key_.push_back(key);
    slot_count_.push_back(0);
    pool_.resize(pool_.size() + cap_);
    if (confirm_s_ > 0) first_seen_s_.resize(pool_.size());
  }
  slot_key_[*slot] = key;
  return *slot;
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
  for (const Eigen::Vector3f& p : points_map) {
    const std::uint32_t slot = slot_for(key_of(voxel_of(p)));
    std::uint32_t& count = slot_count_[slot];
    if (confirm_s_ <= 0 && count >= cap_) continue;  // full, and nothing to confirm
    Eigen::Vector3f* v = pool_.data() + slot * cap_;
    float* first_seen = confirm_s_ > 0 ? first_seen_s_.data() + slot * cap_ : nullptr;
    bool near = false;
    std::size_t stale = count;  // a point never found again within the span: transient
    for (std::size_t i = 0; i < count; ++i) {
      const float d2 = (v[i] - p).squaredNorm();
      if (first_seen != nullptr) {
        float& first = first_seen[i];
        if (first >= 0 && d2 < confirm_d2 && now_s - first >= confirm_s_) {
          first = kConfirmed;  // the same surface, a span later: the world
        } else if (first >= 0 && now_s - first >= 2 * confirm_s_ && stale == count) {
          stale = i;
        }
      }
      if (d2 < min_d2) {
        near = true;
        if (first_seen == nullptr) break;
      }
    }
    if (near) continue;
    if (count >= cap_) {
      if (stale == count) continue;
      // A full voxel makes room by forgetting what something passing through left.
      v[stale] = p;
      first_seen[stale] = now_s;
      continue;
    }
    v[count] = p;
    if (first_seen != nullptr) first_seen[count] = now_s;
    ++count;
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
    const std::uint32_t slot =
        index_.find(key_of(centre + Eigen::Vector3i(o.d[0], o.d[1], o.d[2])));
    if (slot == VoxelIndex::kNoSlot) continue;
    const Eigen::Vector3f* points = pool_.data() + slot * cap_;
    const float* first_seen = all ? nullptr : first_seen_s_.data() + slot * cap_;
    const std::uint32_t count = slot_count_[slot];
    for (std::uint32_t i = 0; i < count; ++i) {
      const Eigen::Vector3f& p = points[i];
      const float d2 = (p - query).squaredNorm();
      if (d2 > max_d2 || (found == kk && d2 >= best_d2[kk - 1])) continue;
      if (first_seen != nullptr && first_seen[i] != kConfirmed) continue;
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
  for (std::uint32_t slot = 0; slot < slot_key_.size(); ++slot) {
    if (slot_key_[slot] == VoxelIndex::kEmptyKey || slot_count_[slot] == 0) continue;
    if ((pool_[slot * cap_] - centre).squaredNorm() <= r2) continue;
    points_ -= slot_count_[slot];
    slot_count_[slot] = 0;
    index_.erase(slot_key_[slot]);
    slot_key_[slot] = VoxelIndex::kEmptyKey;
    free_.push_back(slot);
    ++removed;
  }
  return removed;
}

std::size_t VoxelMap::confirmed_points() const {
  if (confirm_s_ <= 0) return points_;
  std::size_t n = 0;
  for (std::size_t slot = 0; slot < slot_count_.size(); ++slot) {
    const float* first_seen = first_seen_s_.data() + slot * cap_;
    for (std::uint32_t i = 0; i < slot_count_[slot]; ++i) n += first_seen[i] == kConfirmed;
  }
  return n;
}

void VoxelMap::collect(std::vector<Eigen::Vector3f>& out) const {
  for (std::size_t slot = 0; slot < slot_count_.size(); ++slot) {
    for (std::uint32_t i = 0; i < slot_count_[slot]; ++i) {
      const std::size_t at = slot * cap_ + i;
      if (confirm_s_ <= 0 || first_seen_s_[at] == kConfirmed) out.push_back(pool_[at]);
    }
  }
}

void VoxelMap::clear() {
  index_.clear();
  slot_key_.clear();
  slot_count_.clear();
  pool_.clear();
  first_seen_s_.clear();
  free_.clear();
  points_ = 0;
  started_ = false;
  young_ = false;
}

}  // namespace posed::lidar
