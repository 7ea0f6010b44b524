#include "core/fusion/frame_motion.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "core/math/so3.hpp"

namespace posed::fusion {
namespace {

using Mat26 = Eigen::Matrix<double, 2, 6>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

/// A 3-D point of one frame and its observation in the other.
struct Observation {
  Eigen::Vector3d X;  ///< in the frame that gave the depth [m]
  Eigen::Vector2d u;  ///< normalised coordinates in the other frame [-]
  bool forward;       ///< X in a, observed in b
  /// L with LᵀL the observation's information relative to pixel_sigma (aperture_max_ratio);
  /// identity: isotropic
  Eigen::Matrix2d L = Eigen::Matrix2d::Identity();
};

/// The whitening of an observation seen through patches of shapes `a` and `b` (each 1 along its
/// best direction), each direction's sigma at most `max_ratio` times the best.
Eigen::Matrix2d aperture_whitening(const Eigen::Matrix2d& a, const Eigen::Matrix2d& b,
                                   double max_ratio) {
  const auto covariance = [max_ratio](const Eigen::Matrix2d& shape) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(0.5 * (shape + shape.transpose()));
    const Eigen::Vector2d floored =
        es.eigenvalues().cwiseMax(1.0 / (max_ratio * max_ratio)).cwiseMin(1.0);
    return Eigen::Matrix2d(es.eigenvectors() * floored.cwiseInverse().asDiagonal() *
                           es.eigenvectors().transpose());
  };
  // The flow is the difference of two tracked positions: their covariances add. Two corners
  // give 2 I, which the factor 2 takes back to the isotropic weight.
  const Eigen::Matrix2d W = 2.0 * (covariance(a) + covariance(b)).inverse();
  return Eigen::Matrix2d(Eigen::LLT<Eigen::Matrix2d>(W).matrixU());
}

/// Residual π(X') - u of one observation under T_a_b = (R, p), and its Jacobian in the right
/// perturbation (φ, ρ). False when the point is not in front of the observing camera.
bool residual(const Observation& o, const Eigen::Matrix3d& R, const Eigen::Vector3d& p,
              double min_depth_m, Eigen::Vector2d& r, Mat26& J) {
  Eigen::Vector3d X;
  Eigen::Matrix<double, 3, 6> dX;
  if (o.forward) {  // X_b = Rᵀ (X_a - p): d/dφ = [X_b]x, d/dρ = -I
    X = R.transpose() * (o.X - p);
    dX.leftCols<3>() = so3::skew(X);
    dX.rightCols<3>() = -Eigen::Matrix3d::Identity();
  } else {  // X_a = R X_b + p: d/dφ = -R [X_b]x, d/dρ = R
    X = R * o.X + p;
    dX.leftCols<3>() = -R * so3::skew(o.X);
    dX.rightCols<3>() = R;
  }
  if (X.z() < min_depth_m) return false;
  const double iz = 1.0 / X.z();
  r = Eigen::Vector2d(X.x() * iz, X.y() * iz) - o.u;
  Eigen::Matrix<double, 2, 3> Jpi;
  Jpi << iz, 0, -X.x() * iz * iz, 0, iz, -X.y() * iz * iz;
  J = Jpi * dX;
  return true;
}

/// r and J in the observation's own metric (Observation::L); untouched when isotropic.
void whiten(const Observation& o, Eigen::Vector2d& r, Mat26& J) {
  if (o.L.isIdentity(0)) return;
  r = o.L * r;
  J = o.L * J;
}

}  // namespace

FrameMotion estimate_frame_motion(std::span<const FrameFeature> a, std::span<const FrameFeature> b,
                                  const Eigen::Isometry3d& T_a_b_guess,
                                  const FrameMotionConfig& config) {
  FrameMotion out;
  std::vector<Observation> obs;
  const auto usable = [&](double d) { return std::isfinite(d) && d >= config.min_depth_m; };
  for (std::size_t i = 0, j = 0; i < a.size() && j < b.size();) {
    if (a[i].id < b[j].id) {
      ++i;
    } else if (b[j].id < a[i].id) {
      ++j;
    } else {
      const Eigen::Matrix2d L =
          config.aperture_max_ratio > 1
              ? aperture_whitening(a[i].patch_shape, b[j].patch_shape, config.aperture_max_ratio)
              : Eigen::Matrix2d::Identity();
      if (usable(a[i].depth_m)) {
        obs.push_back({a[i].depth_m * a[i].normalised.homogeneous(), b[j].normalised, true, L});
      }
      if (usable(b[j].depth_m)) {
        obs.push_back({b[j].depth_m * b[j].normalised.homogeneous(), a[i].normalised, false, L});
      }
      ++i;
      ++j;
    }
  }
  out.observations = static_cast<int>(obs.size());
  if (out.observations < config.min_inliers) return out;

  const double info = 1.0 / (config.pixel_sigma * config.pixel_sigma);
  Eigen::Matrix3d R = T_a_b_guess.linear();
  Eigen::Vector3d p = T_a_b_guess.translation();
  std::vector<std::uint8_t> inlier(obs.size(), 1);
  Mat6 H = Mat6::Zero();
  Eigen::Vector2d r;
  Mat26 J;
  // Observations that hold still where the guess moves them (still_flow_sigma).
  std::vector<std::uint8_t> still(obs.size(), 0);
  if (config.still_flow_sigma > 0) {
    const double min_flow = config.still_flow_sigma * config.pixel_sigma;
    for (std::size_t k = 0; k < obs.size(); ++k) {
      if (!residual(obs[k], R, p, config.min_depth_m, r, J)) continue;
      // Where the feature was in the frame that gave its depth, and how far the guess moves it.
      const Eigen::Vector2d before = obs[k].X.head<2>() / obs[k].X.z();
      const Eigen::Vector2d predicted = r + obs[k].u;
      if ((predicted - before).norm() > min_flow && (obs[k].u - before).norm() < r.norm()) {
        still[k] = 1;
        ++out.still;
      }
    }
  }
  if (2 * out.still > static_cast<int>(obs.size())) {
    // Most of the features hold still where the guess moves them: the guess is what is wrong (a
    // speed gone twice the truth), and leaving them out would keep it wrong.
    std::fill(still.begin(), still.end(), std::uint8_t{0});
    out.still = 0;
  }
  if (config.guess_gate > 0) {
    int kept = 0;
    for (std::size_t k = 0; k < obs.size(); ++k) {
      inlier[k] = residual(obs[k], R, p, config.min_depth_m, r, J) && r.norm() <= config.guess_gate;
      kept += inlier[k];
    }
    const bool few = kept < config.min_inliers || 2 * kept < static_cast<int>(obs.size());
    if (few && !config.gate_falls_back && kept < config.min_inliers) {
      out.status = FrameMotionStatus::kTooFewInliers;
      return out;
    }
    if (few && config.gate_falls_back) std::fill(inlier.begin(), inlier.end(), std::uint8_t{1});
  }
  for (std::size_t k = 0; k < obs.size(); ++k) {
    if (still[k] != 0) inlier[k] = 0;
  }
  for (int round = 0; round < 2; ++round) {
    for (int it = 0; it < config.iterations; ++it) {
      H.setZero();
      Vec6 g = Vec6::Zero();
      for (std::size_t k = 0; k < obs.size(); ++k) {
        if (inlier[k] == 0 || !residual(obs[k], R, p, config.min_depth_m, r, J)) continue;
        whiten(obs[k], r, J);
        const double e = r.norm() / config.pixel_sigma;
        const double w = e <= config.huber_sigma ? 1.0 : config.huber_sigma / e;
        H += w * info * J.transpose() * J;
        g += w * info * J.transpose() * r;
      }
      Vec6 dx = Vec6::Zero();
      if (config.fix_rotation) {
        dx.tail<3>() = -H.bottomRightCorner<3, 3>().ldlt().solve(g.tail<3>());
      } else {
        dx = -H.ldlt().solve(g);
      }
      if (!dx.allFinite()) break;
      p += R * dx.tail<3>();
      R = R * so3::exp(dx.head<3>());
      if (dx.norm() < 1e-9) break;
    }
    if (round == 0) {
      for (std::size_t k = 0; k < obs.size(); ++k) {
        if (!residual(obs[k], R, p, config.min_depth_m, r, J) ||
            (whiten(obs[k], r, J), r.norm() > config.outlier_sigma * config.pixel_sigma)) {
          inlier[k] = 0;
        }
      }
    }
  }
  // The Hessian and statistics of the inliers at the solution, without the Huber weights.
  H.setZero();
  double sum_sq = 0;
  for (std::size_t k = 0; k < obs.size(); ++k) {
    if (inlier[k] == 0 || !residual(obs[k], R, p, config.min_depth_m, r, J)) continue;
    whiten(obs[k], r, J);
    H += info * J.transpose() * J;
    sum_sq += r.squaredNorm() * info;
    ++out.inliers;
  }
  Eigen::Quaterniond q(R);
  out.T_a_b.linear() = q.normalized().toRotationMatrix();
  out.T_a_b.translation() = p;
  if (out.inliers < config.min_inliers) {
    out.status = FrameMotionStatus::kTooFewInliers;
    return out;
  }
  out.rms_sigma = std::sqrt(sum_sq / (2.0 * out.inliers));
  if (config.fix_rotation) {
    const Eigen::Matrix3d Ht = H.bottomRightCorner<3, 3>();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(0.5 * (Ht + Ht.transpose()));
    if (es.eigenvalues().minCoeff() <= 1e-9 * es.eigenvalues().maxCoeff()) {
      out.status = FrameMotionStatus::kIllConditioned;
      return out;
    }
    out.covariance.setZero();
    out.covariance.bottomRightCorner<3, 3>() = es.eigenvectors() *
                                               es.eigenvalues().cwiseInverse().asDiagonal() *
                                               es.eigenvectors().transpose();
  } else {
    const Eigen::SelfAdjointEigenSolver<Mat6> es(0.5 * (H + H.transpose()));
    if (es.eigenvalues().minCoeff() <= 1e-9 * es.eigenvalues().maxCoeff()) {
      out.status = FrameMotionStatus::kIllConditioned;
      return out;
    }
    out.covariance = es.eigenvectors() * es.eigenvalues().cwiseInverse().asDiagonal() *
                     es.eigenvectors().transpose();
  }
  out.status = FrameMotionStatus::kOk;
  return out;
}

}  // namespace posed::fusion
