#pragma once
// A bounding volume hierarchy over the world's boxes: median split on the longest axis of the
// centroid bounds, leaves of at most 4 boxes, iterative near-child-first traversal. Built once
// per world; queries are const and allocation-free, so one BVH serves every sensor.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "tools/sim/world.hpp"

namespace posed::sim {

class Bvh {
 public:
  Bvh() = default;
  /// Builds over `world.boxes`; the world must outlive the BVH and not change.
  explicit Bvh(const World& world);

  /// Nearest hit of the ray `origin_m + t·dir` (dir unit) with t in (0, t_max_m].
  std::optional<RayHit> cast(const Eigen::Vector3d& origin_m, const Eigen::Vector3d& dir,
                             double t_max_m) const;

  /// nodes in the tree (for tests and the summary)
  std::size_t node_count() const { return nodes_.size(); }

 private:
  struct Node {
    Eigen::Vector3d min_m = Eigen::Vector3d::Zero(), max_m = Eigen::Vector3d::Zero();
    /// leaf: first index into order_; inner: index of the left child
    std::uint32_t first = 0;
    /// inner: index of the right child
    std::uint32_t right = 0;
    /// boxes in a leaf; 0 = inner node
    std::uint32_t count = 0;
  };

  std::uint32_t build(std::uint32_t begin, std::uint32_t end, int depth);

  const World* world_ = nullptr;
  std::vector<Node> nodes_;
  std::vector<std::uint32_t> order_;
  std::vector<Eigen::Vector3d> box_min_, box_max_, centroid_;
};

}  // namespace posed::sim
