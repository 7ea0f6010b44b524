#include "core/lidar/scan_matcher.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "core/math/so3.hpp"

namespace posed::lidar {

Eigen::Isometry3d retract(const Eigen::Isometry3d& T, const Eigen::Matrix<double, 6, 1>& delta) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = T.linear() * so3::exp(delta.head<3>());
  // Re-orthonormalise: many small products drift off SO(3).
  out.linear() = Eigen::Quaterniond(out.linear()).normalized().toRotationMatrix();
  out.translation() = T.translation() + T.linear() * delta.tail<3>();
  return out;
}

double normal_equations(const std::vector<Correspondence>& correspondences,
                        const Eigen::Isometry3d& T, double cauchy_scale_m,
                        Eigen::Matrix<double, 6, 6>& H, Eigen::Matrix<double, 6, 1>& g,
                        std::size_t* inliers, double* inlier_sq_sum) {
  H.setZero();
  g.setZero();
  double cost = 0;
  std::size_t n_in = 0;
  double sq_in = 0;
  const Eigen::Matrix3d& R = T.linear();
  const double c2 = cauchy_scale_m * cauchy_scale_m;
  Eigen::Matrix<double, 3, 6> J_point;
  for (const Correspondence& c : correspondences) {
    const Eigen::Vector3d p_map = R * c.p_lidar + T.translation();
    // d(p_map)/d(rotation, translation) for T * Exp(delta).
    J_point.leftCols<3>() = -R * so3::skew(c.p_lidar);
    J_point.rightCols<3>() = R;
    double r2 = 0;
    if (c.is_plane) {
      const double r = c.direction.dot(p_map - c.anchor);
      r2 = r * r;
      const double w = 1.0 / (1.0 + r2 / c2);
      const Eigen::Matrix<double, 1, 6> J = c.direction.transpose() * J_point;
      H.noalias() += w * J.transpose() * J;
      g.noalias() += w * J.transpose() * r;
    } else {
      const Eigen::Vector3d e = p_map - c.anchor;
      const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - c.direction * c.direction.transpose();
      const Eigen::Vector3d r = P * e;
      r2 = r.squaredNorm();
      const double w = 1.0 / (1.0 + r2 / c2);
      const Eigen::Matrix<double, 3, 6> J = P * J_point;
      H.noalias() += w * J.transpose() * J;
      g.noalias() += w * J.transpose() * r;
    }
    cost += c2 * std::log1p(r2 / c2);
    if (r2 < 9 * c2) {
      ++n_in;
      sq_in += r2;
    }
  }
  if (inliers != nullptr) *inliers = n_in;
  if (inlier_sq_sum != nullptr) *inlier_sq_sum = sq_in;
  return cost;
}

void ScanMatcher::associate(const std::vector<Eigen::Vector3f>& edges_lidar,
                            const std::vector<Eigen::Vector3f>& planes_lidar,
                            const VoxelMap& edge_map, const VoxelMap& plane_map,
                            const Eigen::Isometry3d& T) {
  const Eigen::Isometry3f Tf = T.cast<float>();
  const int k = config_.neighbours;
  const auto max_d = static_cast<float>(config_.max_correspondence_m);

  // One part: a contiguous share of the edges and of the planes, into its own outputs (the
  // map is only read), so the parts may run at once.
  const auto search = [&](std::size_t part) {
    std::vector<Correspondence>& edges_out = part_edges_[part];
    std::vector<Correspondence>& planes_out = part_planes_[part];
    edges_out.clear();
    planes_out.clear();
    Eigen::Vector3f nn[16];
    // Mean and covariance of the neighbours: the line or plane they lie on.
    const auto fit = [&](int n, Eigen::Vector3d& mean,
                         Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>& es) {
      mean.setZero();
      for (int i = 0; i < n; ++i) mean += nn[i].cast<double>();
      mean /= n;
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d d = nn[i].cast<double>() - mean;
        cov.noalias() += d * d.transpose();
      }
      es.computeDirect(cov / n);  // eigenvalues ascending
    };
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
    const PartRange edges = part_range(edges_lidar.size(), part, kParts);
    for (std::size_t i = edges.begin; i < edges.end; ++i) {
      const Eigen::Vector3f& p = edges_lidar[i];
      if (edge_map.nearest(Tf * p, k, max_d, nn) < k) continue;
      Eigen::Vector3d mean;
      fit(k, mean, es);
      const Eigen::Vector3d l = es.eigenvalues();
      if (l(2) < config_.edge_min_linearity * std::max(l(1), 1e-9)) continue;  // not a line
      edges_out.push_back({p.cast<double>(), mean, es.eigenvectors().col(2), false});
    }
    const PartRange planes = part_range(planes_lidar.size(), part, kParts);
    for (std::size_t i = planes.begin; i < planes.end; ++i) {
      const Eigen::Vector3f& p = planes_lidar[i];
      if (plane_map.nearest(Tf * p, k, max_d, nn) < k) continue;
      Eigen::Vector3d mean;
      fit(k, mean, es);
      // Neighbours along one ring are nearly collinear: their "plane" could face anywhere.
      const Eigen::Vector3d l = es.eigenvalues();
      if (l(1) < config_.plane_min_spread_ratio * l(2)) continue;
      const Eigen::Vector3d normal = es.eigenvectors().col(0);
      bool flat = true;
      for (int j = 0; j < k && flat; ++j) {
        flat = std::abs(normal.dot(nn[j].cast<double>() - mean)) <= config_.plane_max_error_m;
      }
      if (!flat) continue;
      planes_out.push_back({p.cast<double>(), mean, normal, true});
    }
  };
  run_parts(splitter_, kParts, search);

  // Edges before planes, each in scan order: the order the sums in normal_equations() take.
  correspondences_.clear();
  correspondences_.reserve(edges_lidar.size() + planes_lidar.size());
  for (const auto& part : part_edges_)
    correspondences_.insert(correspondences_.end(), part.begin(), part.end());
  for (const auto& part : part_planes_)
    correspondences_.insert(correspondences_.end(), part.begin(), part.end());
}

ScanMatchResult ScanMatcher::match(const std::vector<Eigen::Vector3f>& edges_lidar,
                                   const std::vector<Eigen::Vector3f>& planes_lidar,
                                   const VoxelMap& edge_map, const VoxelMap& plane_map,
                                   const Eigen::Isometry3d& T_map_lidar_predicted) {
  ScanMatchResult result;
  result.T_map_lidar = T_map_lidar_predicted;
  Eigen::Isometry3d T = T_map_lidar_predicted;
  // The kept subspace: columns of V where keep is 1 (see the header).
  Eigen::Matrix<double, 6, 6> V = Eigen::Matrix<double, 6, 6>::Identity();
  Eigen::Matrix<double, 6, 1> keep = Eigen::Matrix<double, 6, 1>::Ones();
  Eigen::Matrix<double, 6, 6> H;
  Eigen::Matrix<double, 6, 1> g;

  // Gauss-Newton restricted to the kept subspace: delta = -B (Bᵀ H B)^-1 Bᵀ g, B = V keep
  // (identity on the dropped coordinates keeps the reduced matrix invertible). False when the
  // scan lost its correspondences.
  const auto solve = [&](int max_iterations, bool judge_degeneracy) {
    for (int it = 0; it < max_iterations; ++it) {
      associate(edges_lidar, planes_lidar, edge_map, plane_map, T);
      if (static_cast<int>(correspondences_.size()) < config_.min_correspondences) return false;
      normal_equations(correspondences_, T, config_.cauchy_scale_m, H, g);
      if (judge_degeneracy && it == 0) {
        // Degeneracy is judged once, at the prediction (Zhang et al.): the subspace kept is
        // fixed for the whole solve, so degenerate directions stay at the prediction.
        const Degeneracy d = analyse_degeneracy(H, config_);
        result.eigenvalues = d.eigenvalues;
        result.eigenvectors = d.eigenvectors;
        result.degenerate_directions = d.degenerate_directions;
        V = d.eigenvectors;
        if (config_.handle_degeneracy) keep = d.keep;
      }
      const Eigen::Matrix<double, 6, 6> B = V * keep.asDiagonal();
      const Eigen::Matrix<double, 6, 6> reduced =
          B.transpose() * H * B +
          (Eigen::Matrix<double, 6, 1>::Ones() - keep).asDiagonal().toDenseMatrix() +
          1e-9 * Eigen::Matrix<double, 6, 6>::Identity();
      const Eigen::Matrix<double, 6, 1> delta = -B * reduced.ldlt().solve(B.transpose() * g);
      T = retract(T, delta);
      ++result.iterations;
      if (delta.head<3>().norm() < config_.convergence_rotation_rad &&
          delta.tail<3>().norm() < config_.convergence_translation_m) {
        break;
      }
    }
    return true;
  };
  if (!solve(config_.max_iterations, true)) return result;
  result.T_map_lidar = T;
  result.T_map_lidar_measured = T;

  std::size_t inliers = 0;
  double sq = 0;
  normal_equations(correspondences_, T, config_.cauchy_scale_m, H, g, &inliers, &sq);
  result.edge_correspondences = 0;
  for (const Correspondence& c : correspondences_)
    result.edge_correspondences += c.is_plane ? 0 : 1;
  result.plane_correspondences = correspondences_.size() - result.edge_correspondences;
  result.residual_rms_m = inliers > 0 ? std::sqrt(sq / static_cast<double>(inliers)) : 0.0;
  const double inv_sigma2 = 1.0 / (config_.residual_sigma_m * config_.residual_sigma_m);
  const Eigen::Vector3d rotation_floor(config_.tilt_sigma_floor_rad, config_.tilt_sigma_floor_rad,
                                       config_.yaw_sigma_floor_rad);
  if (keep.minCoeff() > 0.5) {
    result.information =
        information_with_floor(H * inv_sigma2, Eigen::Matrix<double, 6, 6>::Identity(),
                               rotation_floor, config_.translation_sigma_floor_m);
    result.ok = true;
    return result;
  }
  // Degenerate: what the scan says along the weak directions, as a measurement for the back end
  // with its own (small) information, widened further: a corridor's lamps or far end do pin the
  // axis a little, but aliasing makes that little unreliable. Solved from the remapped pose.
  const Eigen::Matrix<double, 6, 6> P_kept = V * keep.asDiagonal() * V.transpose();
  const Eigen::Matrix<double, 6, 6> P_weak = Eigen::Matrix<double, 6, 6>::Identity() - P_kept;
  keep.setOnes();
  if (solve(config_.max_iterations, false)) {
    normal_equations(correspondences_, T, config_.cauchy_scale_m, H, g);
    result.T_map_lidar_measured = T;
  }
  result.information = information_with_floor(P_kept * H * P_kept * inv_sigma2, P_kept,
                                              rotation_floor, config_.translation_sigma_floor_m) +
                       config_.degenerate_information_scale * P_weak * H * P_weak * inv_sigma2;
  result.ok = true;
  return result;
}

Eigen::Matrix<double, 6, 6> information_with_floor(const Eigen::Matrix<double, 6, 6>& information,
                                                   const Eigen::Matrix<double, 6, 6>& P,
                                                   const Eigen::Vector3d& rotation_floor_rad,
                                                   double translation_floor_m) {
  // Covariance in the constrained subspace plus the floors, back to information, degenerate
  // directions projected out again (they stay at zero information).
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  const Mat6 unconstrained = Mat6::Identity() - P;
  const Mat6 cov = (information + unconstrained).ldlt().solve(Mat6::Identity()) - unconstrained;
  Eigen::Matrix<double, 6, 1> floor2;
  floor2 << rotation_floor_rad.cwiseProduct(rotation_floor_rad),
      Eigen::Vector3d::Constant(translation_floor_m * translation_floor_m);
  const Mat6 floored = P * (cov + Mat6(floor2.asDiagonal())) * P + unconstrained;
  return P * floored.ldlt().solve(Mat6::Identity()) * P;
}

Degeneracy analyse_degeneracy(const Eigen::Matrix<double, 6, 6>& H,
                              const ScanMatcherConfig& config) {
  // What each block constrains once the other is free: the Schur complements.
  const Eigen::Matrix3d eps = 1e-9 * Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d Hrr = H.topLeftCorner<3, 3>(), Htt = H.bottomRightCorner<3, 3>();
  const Eigen::Matrix3d Hrt = H.topRightCorner<3, 3>();
  const Eigen::Matrix3d S_rot = Hrr - Hrt * (Htt + eps).ldlt().solve(Hrt.transpose());
  const Eigen::Matrix3d S_trans = Htt - Hrt.transpose() * (Hrr + eps).ldlt().solve(Hrt);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> er(S_rot), et(S_trans);
  Degeneracy d;
  d.eigenvalues << er.eigenvalues(), et.eigenvalues();
  d.eigenvectors.setZero();
  d.eigenvectors.topLeftCorner<3, 3>() = er.eigenvectors();
  d.eigenvectors.bottomRightCorner<3, 3>() = et.eigenvectors();
  for (int i = 0; i < 6; ++i) {
    const double threshold =
        i < 3 ? config.degeneracy_rotation_threshold_m2 : config.degeneracy_translation_threshold;
    const bool degenerate = d.eigenvalues(i) < threshold;
    d.keep(i) = degenerate ? 0.0 : 1.0;
    d.degenerate_directions += degenerate ? 1 : 0;
  }
  return d;
}

}  // namespace posed::lidar
