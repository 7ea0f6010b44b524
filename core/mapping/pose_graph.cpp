#include "core/mapping/pose_graph.hpp"

#include <ceres/ceres.h>

#include <stdexcept>
#include <string>

#include "core/estimator/pose_manifold.hpp"

namespace posed::mapping {
namespace {

/// r = [p_ab - p_ab_meas; 2 vec(q_ab_meas^-1 q_ab)] / sigma with (p_ab, q_ab) = T_a^-1 T_b.
/// 2 vec(dq) is Log(dq) to first order: rotation in `to`'s frame, translation in `from`'s.
struct RelativePoseResidual {
  Eigen::Vector3d p_ab_measured;
  Eigen::Quaterniond q_ab_measured;
  double inv_sigma_translation;
  double inv_sigma_rotation;

  template <typename T>
  bool operator()(const T* a, const T* b, T* residual) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p_a(a), p_b(b);
    const Eigen::Map<const Eigen::Quaternion<T>> q_a(a + 3), q_b(b + 3);
    const Eigen::Quaternion<T> q_a_inverse = q_a.conjugate();
    const Eigen::Matrix<T, 3, 1> p_ab = q_a_inverse * (p_b - p_a);
    const Eigen::Quaternion<T> q_ab = q_a_inverse * q_b;
    Eigen::Quaternion<T> dq = q_ab_measured.conjugate().template cast<T>() * q_ab;
    // The shorter way round: q and -q are one rotation.
    const T sign = dq.w() < T(0) ? T(-1) : T(1);
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(residual);
    r.template head<3>() = (p_ab - p_ab_measured.template cast<T>()) * T(inv_sigma_translation);
    r.template tail<3>() = T(2) * sign * dq.vec() * T(inv_sigma_rotation);
    return true;
  }
};

std::array<double, 7> to_block(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.rotation());
  return {
      T.translation().x(), T.translation().y(), T.translation().z(), q.x(), q.y(), q.z(), q.w()};
}

Eigen::Isometry3d from_block(const std::array<double, 7>& b) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(b[6], b[3], b[4], b[5]).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(b[0], b[1], b[2]);
  return T;
}

RelativePoseResidual make_residual(const PoseGraphEdge& e) {
  return {e.T_from_to.translation(), Eigen::Quaterniond(e.T_from_to.rotation()).normalized(),
          1.0 / e.sigma_translation_m, 1.0 / e.sigma_rotation_rad};
}

}  // namespace

std::size_t PoseGraph::add_node(const Eigen::Isometry3d& T_map_node) {
  nodes_.push_back(to_block(T_map_node));
  return nodes_.size() - 1;
}

void PoseGraph::add_edge(const PoseGraphEdge& edge) {
  if (edge.from >= nodes_.size() || edge.to >= nodes_.size() || edge.from == edge.to) {
    throw std::invalid_argument("pose graph edge " + std::to_string(edge.from) + " -> " +
                                std::to_string(edge.to) + " names a missing node (" +
                                std::to_string(nodes_.size()) + " nodes)");
  }
  if (!(edge.sigma_translation_m > 0.0) || !(edge.sigma_rotation_rad > 0.0)) {
    throw std::invalid_argument("pose graph edge sigmas must be positive");
  }
  edges_.push_back(edge);
}

Eigen::Isometry3d PoseGraph::node(std::size_t i) const { return from_block(nodes_.at(i)); }

void PoseGraph::set_node(std::size_t i, const Eigen::Isometry3d& T_map_node) {
  nodes_.at(i) = to_block(T_map_node);
}

Eigen::Matrix<double, 6, 1> PoseGraph::whitened_residual(const PoseGraphEdge& edge) const {
  Eigen::Matrix<double, 6, 1> r;
  make_residual(edge)(nodes_.at(edge.from).data(), nodes_.at(edge.to).data(), r.data());
  return r;
}

PoseGraphSolve PoseGraph::optimise(int max_iterations) {
  PoseGraphSolve out;
  if (nodes_.size() < 2 || edges_.empty()) {
    out.converged = true;
    return out;
  }
  ceres::Problem::Options problem_options;
  // The manifold is shared by every block; the problem must not delete it once per block.
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  estimator::PoseManifold manifold;
  for (auto& block : nodes_) {
    problem.AddParameterBlock(block.data(), 7, &manifold);
  }
  problem.SetParameterBlockConstant(nodes_.front().data());
  for (const PoseGraphEdge& e : edges_) {
    auto* cost = new ceres::AutoDiffCostFunction<RelativePoseResidual, 6, 7, 7>(
        new RelativePoseResidual(make_residual(e)));
    ceres::LossFunction* loss =
        e.robust_sigmas > 0.0 ? new ceres::CauchyLoss(e.robust_sigmas) : nullptr;
    problem.AddResidualBlock(cost, loss, nodes_[e.from].data(), nodes_[e.to].data());
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = max_iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.iterations = static_cast<int>(summary.iterations.size());
  out.initial_cost = summary.initial_cost;
  out.final_cost = summary.final_cost;
  out.solve_time_s = summary.total_time_in_seconds;
  for (auto& block : nodes_) {
    Eigen::Map<Eigen::Quaterniond> q(block.data() + 3);
    q.normalize();
  }
  return out;
}

}  // namespace posed::mapping
