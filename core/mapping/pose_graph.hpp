#pragma once
// The keyframe pose graph the mapping layer optimises off the real-time path: one pose per
// keyframe, odometry edges between neighbours, loop edges from verified registrations. Ceres
// over posed's pose blocks ([p, q], right-perturbed, estimator/pose_manifold.hpp); the first pose
// is held fixed, which fixes the map frame where the odometry began.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstddef>
#include <vector>

namespace posed::mapping {

struct PoseGraphEdge {
  std::size_t from = 0;
  std::size_t to = 0;
  Eigen::Isometry3d T_from_to = Eigen::Isometry3d::Identity();  ///< measured relative pose
  double sigma_translation_m = 0.1;                             ///< per axis, in `from`'s frame [m]
  double sigma_rotation_rad = 0.01;                             ///< per axis [rad]
  /// a Cauchy loss at this many sigmas: one wrong loop cannot pull the whole graph [sigma]; 0:
  /// plain least squares (odometry)
  double robust_sigmas = 0.0;
  bool loop = false;  ///< a loop edge (counted apart; odometry edges join neighbours)
};

struct PoseGraphSolve {
  bool converged = false;
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double solve_time_s = 0.0;  ///< the solver's own wall time [s]
};

class PoseGraph {
 public:
  /// Adds a node at pose `T_map_node` (the initial value); returns its index.
  std::size_t add_node(const Eigen::Isometry3d& T_map_node);
  void add_edge(const PoseGraphEdge& edge);

  /// Optimises every node but the first.
  PoseGraphSolve optimise(int max_iterations = 50);

  std::size_t size() const { return nodes_.size(); }
  Eigen::Isometry3d node(std::size_t i) const;
  void set_node(std::size_t i, const Eigen::Isometry3d& T_map_node);
  const std::vector<PoseGraphEdge>& edges() const { return edges_; }

  /// The residual of `edge` at the current nodes, whitened [sigma]: translation then rotation.
  Eigen::Matrix<double, 6, 1> whitened_residual(const PoseGraphEdge& edge) const;

 private:
  // [p_x p_y p_z q_x q_y q_z q_w]: PoseManifold's block layout.
  std::vector<std::array<double, 7>> nodes_;
  std::vector<PoseGraphEdge> edges_;
};

}  // namespace posed::mapping
