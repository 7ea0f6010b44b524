#include "tools/sim/bvh.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <numeric>

namespace posed::sim {
namespace {

constexpr std::uint32_t kLeafSize = 4;
constexpr int kMaxDepth = 60;

/// Slab test of a ray against an AABB; returns the entry distance or +inf.
inline double hit_aabb(const Eigen::Vector3d& mn, const Eigen::Vector3d& mx,
                       const Eigen::Vector3d& o, const Eigen::Vector3d& inv_d, double t_max) {
  double t0 = 0.0, t1 = t_max;
  for (int a = 0; a < 3; ++a) {
    double ta = (mn[a] - o[a]) * inv_d[a];
    double tb = (mx[a] - o[a]) * inv_d[a];
    if (ta > tb) std::swap(ta, tb);
    // NaN (0 * inf on a face) compares false and leaves the interval unchanged: a grazing ray.
    if (ta > t0) t0 = ta;
    if (tb < t1) t1 = tb;
    if (t0 > t1) return std::numeric_limits<double>::infinity();
  }
  return t0;
}

}  // namespace

Bvh::Bvh(const World& world) : world_(&world) {
  const std::size_t n = world.boxes.size();
  box_min_.resize(n);
  box_max_.resize(n);
  centroid_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Box& b = world.boxes[i];
    // AABB of an oriented box: |R| · half extents.
    const Eigen::Vector3d r = b.R_map_box.cwiseAbs() * b.half_extent_m;
    box_min_[i] = b.center_m - r;
    box_max_[i] = b.center_m + r;
    centroid_[i] = b.center_m;
  }
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), 0u);
  nodes_.reserve(2 * n + 1);
  if (n > 0) build(0, static_cast<std::uint32_t>(n), 0);
}

std::uint32_t Bvh::build(std::uint32_t begin, std::uint32_t end, int depth) {
  const auto index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back({});
  Eigen::Vector3d mn = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d mx = -mn, cmn = mn, cmx = -mn;
  for (std::uint32_t i = begin; i < end; ++i) {
    const std::uint32_t b = order_[i];
    mn = mn.cwiseMin(box_min_[b]);
    mx = mx.cwiseMax(box_max_[b]);
    cmn = cmn.cwiseMin(centroid_[b]);
    cmx = cmx.cwiseMax(centroid_[b]);
  }
  nodes_[index].min_m = mn;
  nodes_[index].max_m = mx;
  if (end - begin <= kLeafSize || depth >= kMaxDepth) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  int axis = 0;
  (cmx - cmn).maxCoeff(&axis);
  const std::uint32_t mid = begin + (end - begin) / 2;
  // Ties broken by box index so the tree (and so the traversal order) is deterministic.
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                   [&](std::uint32_t a, std::uint32_t b) {
                     if (centroid_[a][axis] != centroid_[b][axis])
                       return centroid_[a][axis] < centroid_[b][axis];
                     return a < b;
                   });
  const std::uint32_t left = build(begin, mid, depth + 1);
  const std::uint32_t right = build(mid, end, depth + 1);
  nodes_[index].first = left;
  nodes_[index].right = right;
  nodes_[index].count = 0;
  return index;
}

std::optional<RayHit> Bvh::cast(const Eigen::Vector3d& origin_m, const Eigen::Vector3d& dir,
                                double t_max_m) const {
  if (nodes_.empty()) return std::nullopt;
  const Eigen::Vector3d inv_d = dir.cwiseInverse();
  std::optional<RayHit> best;
  double best_t = t_max_m;
  std::array<std::uint32_t, 2 * kMaxDepth + 4> stack{};
  std::size_t top = 0;
  if (hit_aabb(nodes_[0].min_m, nodes_[0].max_m, origin_m, inv_d, best_t) > best_t)
    return std::nullopt;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
        const std::uint32_t b = order_[i];
        if (auto h = intersect_box(world_->boxes[b], origin_m, dir, best_t)) {
          if (h->t_m < best_t || (h->t_m == best_t && best && b < best->box)) {
            best_t = h->t_m;
            h->box = b;
            best = h;
          }
        }
      }
      continue;
    }
    const std::uint32_t l = node.first, r = node.right;
    const double tl = hit_aabb(nodes_[l].min_m, nodes_[l].max_m, origin_m, inv_d, best_t);
    const double tr = hit_aabb(nodes_[r].min_m, nodes_[r].max_m, origin_m, inv_d, best_t);
    // Push the farther child first so the nearer one is visited first and shrinks best_t.
    if (tl <= tr) {
      if (tr <= best_t) stack[top++] = r;
      if (tl <= best_t) stack[top++] = l;
    } else {
      if (tl <= best_t) stack[top++] = l;
      if (tr <= best_t) stack[top++] = r;
    }
  }
  return best;
}

}  // namespace posed::sim
