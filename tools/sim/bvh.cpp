#include "tools/sim/bvh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace posed::sim {
namespace {

constexpr std::uint32_t kMaxLeafSize = 2;
constexpr int kMaxDepth = 60;
constexpr int kBins = 16;
/// SAH cost of one traversal step relative to one box test [-]
constexpr double kTraversalCost = 0.5;
constexpr double kInf = std::numeric_limits<double>::infinity();

double half_area(const Eigen::Vector3d& mn, const Eigen::Vector3d& mx) {
  const Eigen::Vector3d e = (mx - mn).cwiseMax(0.0);
  return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
}

/// Slab test of a ray against an AABB; returns the entry distance or +inf. Branch-free: a NaN
/// (0 * inf, a ray in the plane of a face) is dropped by the operand order of min/max, which
/// leaves the interval unchanged for that axis (a grazing ray).
inline double hit_aabb(const std::array<double, 3>& mn, const std::array<double, 3>& mx,
                       const Ray& r, double t_max) {
  double t0 = 0.0, t1 = t_max;
  for (std::size_t a = 0; a < 3; ++a) {
    const double ta = (mn[a] - r.o[a]) * r.inv_d[a];
    const double tb = (mx[a] - r.o[a]) * r.inv_d[a];
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  return t0 <= t1 ? t0 : kInf;
}

}  // namespace

Ray::Ray(const Eigen::Vector3d& origin_m, const Eigen::Vector3d& dir) {
  for (int a = 0; a < 3; ++a) {
    o[a] = origin_m[a];
    d[a] = dir[a];
    inv_d[a] = 1.0 / dir[a];
  }
}

Bvh::Bvh(const World& world) {
  const std::size_t n = world.boxes.size();
  box_min_.resize(n);
  box_max_.resize(n);
  centroid_.resize(n);
  boxes_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Box& b = world.boxes[i];
    // AABB of an oriented box: |R| · half extents.
    const Eigen::Vector3d r = b.R_map_box.cwiseAbs() * b.half_extent_m;
    box_min_[i] = b.center_m - r;
    box_max_[i] = b.center_m + r;
    centroid_[i] = b.center_m;
    PreparedBox& p = boxes_[i];
    for (int a = 0; a < 3; ++a) {
      p.center_m[static_cast<std::size_t>(a)] = b.center_m[a];
      p.half_m[static_cast<std::size_t>(a)] = b.half_extent_m[a];
      for (int c = 0; c < 3; ++c)
        p.R_box_map[static_cast<std::size_t>(3 * a + c)] = b.R_map_box(c, a);
    }
    const Eigen::Matrix3d& R = b.R_map_box;
    if (R.isIdentity(0.0)) {
      p.kind = PreparedBox::kAxisAligned;
    } else if (R(2, 2) == 1.0 && R(0, 2) == 0.0 && R(1, 2) == 0.0 && R(2, 0) == 0.0 &&
               R(2, 1) == 0.0) {
      p.kind = PreparedBox::kYawed;
    }
  }
  // A box whose bounds cover more than a quarter of all the other boxes' bounds (by surface
  // area) is global: the ground under a street, a tunnel or a room.
  Eigen::Vector3d wmn = Eigen::Vector3d::Constant(kInf), wmx = -wmn;
  std::vector<double> areas(n);
  for (std::size_t i = 0; i < n; ++i) areas[i] = half_area(box_min_[i], box_max_[i]);
  std::vector<std::size_t> by_area(n);
  std::iota(by_area.begin(), by_area.end(), std::size_t{0});
  std::stable_sort(by_area.begin(), by_area.end(),
                   [&](std::size_t a, std::size_t b) { return areas[a] < areas[b]; });
  std::vector<bool> global(n, false);
  for (const std::size_t i : by_area) {  // smallest first: the rest's bounds so far
    if (wmn.allFinite() && areas[i] > 4.0 * half_area(wmn, wmx)) {
      global[i] = true;
      continue;
    }
    wmn = wmn.cwiseMin(box_min_[i]);
    wmx = wmx.cwiseMax(box_max_[i]);
  }
  for (std::uint32_t i = 0; i < n; ++i) (global[i] ? global_ : order_).push_back(i);
  nodes_.reserve(2 * order_.size() + 1);
  if (!order_.empty()) build(0, static_cast<std::uint32_t>(order_.size()), 0);
}

std::uint32_t Bvh::build(std::uint32_t begin, std::uint32_t end, int depth) {
  const auto index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back({});
  Eigen::Vector3d mn = Eigen::Vector3d::Constant(kInf), mx = -mn, cmn = mn, cmx = -mn;
  for (std::uint32_t i = begin; i < end; ++i) {
    const std::uint32_t b = order_[i];
    mn = mn.cwiseMin(box_min_[b]);
    mx = mx.cwiseMax(box_max_[b]);
    cmn = cmn.cwiseMin(centroid_[b]);
    cmx = cmx.cwiseMax(centroid_[b]);
  }
  for (int a = 0; a < 3; ++a) {
    nodes_[index].min_m[static_cast<std::size_t>(a)] = mn[a];
    nodes_[index].max_m[static_cast<std::size_t>(a)] = mx[a];
  }
  const std::uint32_t n = end - begin;
  const auto make_leaf = [&] {
    nodes_[index].first = begin;
    nodes_[index].count = n;
    return index;
  };
  if (n <= kMaxLeafSize || depth >= kMaxDepth) return make_leaf();

  // Binned SAH: for each axis, boxes by centroid into bins, every split between bins costed as
  // traversal + (area_left · n_left + area_right · n_right) / area.
  int best_axis = -1, best_split = 0;
  double best_cost = static_cast<double>(n);  // a leaf: test every box
  const double area = std::max(half_area(mn, mx), 1e-12);
  for (int axis = 0; axis < 3; ++axis) {
    const double lo = cmn[axis], extent = cmx[axis] - cmn[axis];
    if (!(extent > 0)) continue;
    std::array<std::uint32_t, kBins> count{};
    std::array<Eigen::Vector3d, kBins> bmin, bmax;
    bmin.fill(Eigen::Vector3d::Constant(kInf));
    bmax.fill(Eigen::Vector3d::Constant(-kInf));
    const auto bin_of = [&](std::uint32_t b) {
      return std::min(kBins - 1, static_cast<int>((centroid_[b][axis] - lo) / extent * kBins));
    };
    for (std::uint32_t i = begin; i < end; ++i) {
      const std::uint32_t b = order_[i];
      const auto k = static_cast<std::size_t>(bin_of(b));
      ++count[k];
      bmin[k] = bmin[k].cwiseMin(box_min_[b]);
      bmax[k] = bmax[k].cwiseMax(box_max_[b]);
    }
    // Right-to-left sweep of area · count, then left-to-right evaluation.
    std::array<double, kBins> right_cost{};
    Eigen::Vector3d rmn = Eigen::Vector3d::Constant(kInf), rmx = -rmn;
    std::uint32_t rn = 0;
    for (int k = kBins - 1; k > 0; --k) {
      rmn = rmn.cwiseMin(bmin[static_cast<std::size_t>(k)]);
      rmx = rmx.cwiseMax(bmax[static_cast<std::size_t>(k)]);
      rn += count[static_cast<std::size_t>(k)];
      right_cost[static_cast<std::size_t>(k)] = rn > 0 ? half_area(rmn, rmx) * rn : 0.0;
    }
    Eigen::Vector3d lmn = Eigen::Vector3d::Constant(kInf), lmx = -lmn;
    std::uint32_t ln = 0;
    for (int k = 0; k + 1 < kBins; ++k) {
      lmn = lmn.cwiseMin(bmin[static_cast<std::size_t>(k)]);
      lmx = lmx.cwiseMax(bmax[static_cast<std::size_t>(k)]);
      ln += count[static_cast<std::size_t>(k)];
      if (ln == 0 || ln == n) continue;
      const double cost =
          kTraversalCost +
          (half_area(lmn, lmx) * ln + right_cost[static_cast<std::size_t>(k + 1)]) / area;
      if (cost < best_cost) {
        best_cost = cost;
        best_axis = axis;
        best_split = k;
      }
    }
  }
  std::uint32_t mid;
  if (best_axis >= 0) {
    // Stable: the boxes keep their index order within each side, so the tree (and the
    // traversal order) depends on the world only.
    const int axis = best_axis;
    const double lo = cmn[axis], extent = cmx[axis] - cmn[axis];
    const auto it =
        std::stable_partition(order_.begin() + begin, order_.begin() + end, [&](std::uint32_t b) {
          return std::min(kBins - 1, static_cast<int>((centroid_[b][axis] - lo) / extent *
                                                      kBins)) <= best_split;
        });
    mid = static_cast<std::uint32_t>(it - order_.begin());
  } else if (n <= 8) {
    return make_leaf();  // splitting would cost more than testing these few boxes
  } else {
    // Coincident centroids: halve by index.
    mid = begin + n / 2;
  }
  const std::uint32_t left = build(begin, mid, depth + 1);
  const std::uint32_t right = build(mid, end, depth + 1);
  nodes_[index].first = left;
  nodes_[index].right = right;
  nodes_[index].count = 0;
  return index;
}

std::optional<RayHit> Bvh::hit_box(std::uint32_t box, const Ray& r, double t_max_m) const {
  const PreparedBox& p = boxes_[box];
  // The ray in the box frame. Axis-aligned boxes keep the ray's direction (and its
  // reciprocal); yawed ones keep the vertical axis.
  std::array<double, 3> o{}, d{}, inv{};
  const double px = r.o[0] - p.center_m[0], py = r.o[1] - p.center_m[1],
               pz = r.o[2] - p.center_m[2];
  const auto& R = p.R_box_map;
  switch (p.kind) {
    case PreparedBox::kAxisAligned:
      o = {px, py, pz};
      d = r.d;
      inv = r.inv_d;
      break;
    case PreparedBox::kYawed:
      o = {R[0] * px + R[1] * py, R[3] * px + R[4] * py, pz};
      d = {R[0] * r.d[0] + R[1] * r.d[1], R[3] * r.d[0] + R[4] * r.d[1], r.d[2]};
      inv = {1.0 / d[0], 1.0 / d[1], r.inv_d[2]};
      break;
    case PreparedBox::kOriented:
      for (std::size_t a = 0; a < 3; ++a) {
        o[a] = R[3 * a] * px + R[3 * a + 1] * py + R[3 * a + 2] * pz;
        d[a] = R[3 * a] * r.d[0] + R[3 * a + 1] * r.d[1] + R[3 * a + 2] * r.d[2];
        inv[a] = 1.0 / d[a];
      }
      break;
  }
  std::optional<RayHit> hit = slab_hit(o, d, inv, p.half_m, t_max_m);
  if (hit) hit->box = box;
  return hit;
}

std::optional<RayHit> Bvh::cast(const Eigen::Vector3d& origin_m, const Eigen::Vector3d& dir,
                                double t_max_m) const {
  return cast(Ray(origin_m, dir), t_max_m);
}

std::optional<RayHit> Bvh::cast(const Ray& r, double t_max_m) const {
  std::optional<RayHit> best;
  double best_t = t_max_m;
  const auto consider = [&](std::uint32_t b) {
    if (auto h = hit_box(b, r, best_t)) {
      if (h->t_m < best_t || (h->t_m == best_t && best && b < best->box)) {
        best_t = h->t_m;
        best = h;
      }
    }
  };
  for (const std::uint32_t b : global_) consider(b);
  if (nodes_.empty()) return best;
  std::array<std::uint32_t, 2 * kMaxDepth + 4> stack;  // NOLINT: filled before read
  std::size_t top = 0;
  if (hit_aabb(nodes_[0].min_m, nodes_[0].max_m, r, best_t) > best_t) return best;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) consider(order_[i]);
      continue;
    }
    const std::uint32_t l = node.first, rt = node.right;
    const double tl = hit_aabb(nodes_[l].min_m, nodes_[l].max_m, r, best_t);
    const double tr = hit_aabb(nodes_[rt].min_m, nodes_[rt].max_m, r, best_t);
    // Push the farther child first so the nearer one is visited first and shrinks best_t.
    if (tl <= tr) {
      if (tr <= best_t) stack[top++] = rt;
      if (tl <= best_t) stack[top++] = l;
    } else {
      if (tl <= best_t) stack[top++] = l;
      if (tr <= best_t) stack[top++] = rt;
    }
  }
  return best;
}

}  // namespace posed::sim
