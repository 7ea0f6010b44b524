#pragma once
// A bounding volume hierarchy over the world's boxes, the one ray caster every sensor uses
// (lidar firings, camera grid rays): built once per world with the surface area heuristic
// (binned on box centroids), leaves of at most 2 boxes, iterative near-child-first traversal.
// Boxes as large as the world itself (the ground slab) stay out of the tree: inside it they
// would inflate every node on their path; tested first, they also shorten every ray that
// meets the ground before the tree is entered. Queries are const and allocation-free.
//
// Exact hits use each box in a prepared form: its rotation transposed, and whether it is
// axis-aligned (walls, the ground: the ray's own reciprocal direction serves) or only yawed
// (buildings, cars: the vertical slab needs no transform). The result is the one intersect_box()
// gives (tested against it on every scenario), found with far fewer box tests.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "tools/sim/world.hpp"

namespace posed::sim {

/// A ray with what every box and node test needs, computed once.
struct Ray {
  Ray(const Eigen::Vector3d& origin_m, const Eigen::Vector3d& dir);
  std::array<double, 3> o;      ///< origin [m]
  std::array<double, 3> d;      ///< unit direction
  std::array<double, 3> inv_d;  ///< 1 / d per axis (±inf for 0)
};

class Bvh {
 public:
  Bvh() = default;
  /// Builds over `world.boxes`; the world must outlive the BVH and not change.
  explicit Bvh(const World& world);

  /// Nearest hit of the ray `origin_m + t·dir` (dir unit) with t in (0, t_max_m]; among equally
  /// near boxes the lowest index.
  std::optional<RayHit> cast(const Eigen::Vector3d& origin_m, const Eigen::Vector3d& dir,
                             double t_max_m) const;
  std::optional<RayHit> cast(const Ray& ray, double t_max_m) const;
  /// The hit of one box, as intersect_box(world.boxes[box], ...) gives it.
  std::optional<RayHit> hit_box(std::uint32_t box, const Ray& ray, double t_max_m) const;

  /// nodes in the tree (for tests and the summary)
  std::size_t node_count() const { return nodes_.size(); }

 private:
  struct Node {
    std::array<double, 3> min_m{}, max_m{};
    /// leaf: first index into order_; inner: index of the left child (the right one follows
    /// its whole subtree: stored in `right`)
    std::uint32_t first = 0;
    std::uint32_t right = 0;
    /// boxes in a leaf; 0 = inner node
    std::uint32_t count = 0;
  };
  /// A box ready for ray tests: box frame = rows of R_box_map applied to (p - centre).
  struct PreparedBox {
    std::array<double, 3> center_m{}, half_m{};
    std::array<double, 9> R_box_map{};  // row-major
    enum Kind : std::uint8_t { kAxisAligned, kYawed, kOriented } kind = kOriented;
  };

  std::uint32_t build(std::uint32_t begin, std::uint32_t end, int depth);

  std::vector<Node> nodes_;
  std::vector<std::uint32_t> order_;
  /// boxes tested for every ray, before the tree
  std::vector<std::uint32_t> global_;
  std::vector<PreparedBox> boxes_;
  std::vector<Eigen::Vector3d> box_min_, box_max_, centroid_;
};

}  // namespace posed::sim
