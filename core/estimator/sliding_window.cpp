#include "core/estimator/sliding_window.hpp"

#include <ceres/problem.h>
#include <ceres/sized_cost_function.h>
#include <ceres/solver.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "core/estimator/factors.hpp"
#include "core/estimator/pose_manifold.hpp"

namespace posed::estimator {
namespace {

using Vec15 = Eigen::Matrix<double, 15, 1>;
using Mat15 = Eigen::Matrix<double, 15, 15>;

const PoseManifold& pose_manifold() {
  static const PoseManifold manifold;
  return manifold;
}

/// A linear Gaussian prior on one state, r = J (x [-] x0) + r0, with x [-] x0 in the tangent space
/// [dp, dtheta, v, b_g, b_a]: the start-up prior, and what marginalisation leaves behind.
class StatePrior final : public ceres::SizedCostFunction<15, 7, 9> {
 public:
  StatePrior(const double* pose0, const double* sb0, const Mat15& J, const Vec15& r0)
      : J_(J), r0_(r0) {
    std::copy(pose0, pose0 + 7, pose0_);
    std::copy(sb0, sb0 + 9, sb0_);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    Vec15 dx;
    pose_manifold().Minus(parameters[0], pose0_, dx.data());
    for (int i = 0; i < 9; ++i) dx(6 + i) = parameters[1][i] - sb0_[i];
    Eigen::Map<Vec15> r(residuals);
    r = J_ * dx + r0_;
    if (jacobians == nullptr) return true;
    if (jacobians[0] != nullptr) {
      // d(x [-] x0)/dx ~ MinusJacobian at x (exact at x = x0; the prior is linear there anyway).
      Eigen::Matrix<double, 6, 7, Eigen::RowMajor> minus;
      pose_manifold().MinusJacobian(parameters[0], minus.data());
      Eigen::Map<Eigen::Matrix<double, 15, 7, Eigen::RowMajor>> J0(jacobians[0]);
      J0 = J_.leftCols<6>() * minus;
    }
    if (jacobians[1] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 15, 9, Eigen::RowMajor>> J1(jacobians[1]);
      J1 = J_.rightCols<9>();
    }
    return true;
  }

 private:
  double pose0_[7];
  double sb0_[9];
  Mat15 J_;
  Vec15 r0_;
};

void to_arrays(const imu::ImuState& s, double* pose, double* sb) {
  {
    Eigen::Map<Eigen::Vector3d> m(pose);
    m = s.p_map_imu_m;
  }
  {
    Eigen::Map<Eigen::Quaterniond> m(pose + 3);
    m = s.q_map_imu.normalized();
  }
  {
    Eigen::Map<Eigen::Vector3d> m(sb);
    m = s.v_map_mps;
  }
  {
    Eigen::Map<Eigen::Vector3d> m(sb + 3);
    m = s.bias.gyro_radps;
  }
  {
    Eigen::Map<Eigen::Vector3d> m(sb + 6);
    m = s.bias.accel_mps2;
  }
}

}  // namespace

SlidingWindow::SlidingWindow(const SlidingWindowConfig& config) : config_(config) {}
SlidingWindow::~SlidingWindow() = default;

imu::ImuState SlidingWindow::state(std::size_t i) const {
  const State& s = states_.at(i);
  imu::ImuState out;
  out.stamp = s.stamp;
  out.p_map_imu_m = Eigen::Map<const Eigen::Vector3d>(s.pose);
  out.q_map_imu = Eigen::Map<const Eigen::Quaterniond>(s.pose + 3);
  out.v_map_mps = Eigen::Map<const Eigen::Vector3d>(s.speed_bias);
  out.bias.gyro_radps = Eigen::Map<const Eigen::Vector3d>(s.speed_bias + 3);
  out.bias.accel_mps2 = Eigen::Map<const Eigen::Vector3d>(s.speed_bias + 6);
  return out;
}

void SlidingWindow::reset(const imu::ImuState& state, const Vec15& prior_sigma) {
  states_.clear();
  State& s = states_.emplace_back();
  s.stamp = state.stamp;
  to_arrays(state, s.pose, s.speed_bias);
  const Mat15 J = prior_sigma.cwiseInverse().asDiagonal();
  prior_ = std::make_unique<StatePrior>(s.pose, s.speed_bias, J, Vec15::Zero());
}

void SlidingWindow::add(const imu::ImuState& guess, const imu::Preintegration& pre,
                        const std::optional<LidarPose>& lidar) {
  State& s = states_.emplace_back();
  s.stamp = guess.stamp;
  to_arrays(guess, s.pose, s.speed_bias);
  s.imu = std::make_unique<ImuFactor>(pre, config_.gravity_mps2, config_.noise);
  if (lidar) {
    s.lidar = std::make_unique<LidarPoseFactor>(lidar->T_map_lidar, config_.T_imu_lidar,
                                                lidar->information);
  }
  while (static_cast<int>(states_.size()) > config_.size) marginalise_oldest();
}

bool SlidingWindow::solve() {
  if (states_.empty()) return true;
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.enable_fast_removal = false;
  ceres::Problem problem(po);
  auto* manifold = const_cast<PoseManifold*>(&pose_manifold());
  for (State& s : states_) {
    problem.AddParameterBlock(s.pose, 7, manifold);
    problem.AddParameterBlock(s.speed_bias, 9);
  }
  problem.AddResidualBlock(prior_.get(), nullptr, states_.front().pose, states_.front().speed_bias);
  for (std::size_t i = 0; i < states_.size(); ++i) {
    State& s = states_[i];
    if (s.lidar) problem.AddResidualBlock(s.lidar.get(), nullptr, s.pose);
    if (i > 0 && s.imu) {
      State& p = states_[i - 1];
      problem.AddResidualBlock(s.imu.get(), nullptr, p.pose, p.speed_bias, s.pose, s.speed_bias);
    }
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  so.max_num_iterations = config_.max_iterations;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  ++counters_.solves;
  counters_.iterations += static_cast<std::uint64_t>(summary.iterations.size());
  if (!summary.IsSolutionUsable()) {
    ++counters_.failed_solves;
    return false;
  }
  return true;
}

void SlidingWindow::marginalise_oldest() {
  if (states_.size() < 2) return;
  State& x0 = states_[0];
  State& x1 = states_[1];
  // Tangent coordinates: [x0 pose 6, x0 sb 9, x1 pose 6, x1 sb 9].
  Eigen::Matrix<double, 30, 30> H = Eigen::Matrix<double, 30, 30>::Zero();
  Eigen::Matrix<double, 30, 1> b = Eigen::Matrix<double, 30, 1>::Zero();
  Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus0, plus1;
  pose_manifold().PlusJacobian(x0.pose, plus0.data());
  pose_manifold().PlusJacobian(x1.pose, plus1.data());

  // Adds one residual block's JᵀJ and Jᵀr; `offsets` place each block's tangent columns.
  const auto accumulate = [&](ceres::CostFunction& cost, std::vector<double*> params,
                              std::vector<int> offsets) {
    const int m = cost.num_residuals();
    Eigen::VectorXd r(m);
    std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J_ambient;
    std::vector<double*> jac_ptrs;
    for (std::size_t k = 0; k < params.size(); ++k) {
      J_ambient.emplace_back(m, cost.parameter_block_sizes()[k]);
    }
    for (auto& J : J_ambient) jac_ptrs.push_back(J.data());
    cost.Evaluate(params.data(), r.data(), jac_ptrs.data());
    Eigen::MatrixXd J_tangent = Eigen::MatrixXd::Zero(m, 30);
    for (std::size_t k = 0; k < params.size(); ++k) {
      const int size = cost.parameter_block_sizes()[k];
      if (size == 7) {
        const auto& plus = params[k] == x0.pose ? plus0 : plus1;
        J_tangent.middleCols(offsets[k], 6) = J_ambient[k] * plus;
      } else {
        J_tangent.middleCols(offsets[k], size) = J_ambient[k];
      }
    }
    H += J_tangent.transpose() * J_tangent;
    b += J_tangent.transpose() * r;
  };
  accumulate(*prior_, {x0.pose, x0.speed_bias}, {0, 6});
  if (x0.lidar) accumulate(*x0.lidar, {x0.pose}, {0});
  if (x1.imu) accumulate(*x1.imu, {x0.pose, x0.speed_bias, x1.pose, x1.speed_bias}, {0, 6, 15, 21});

  // Schur complement onto x1: H* = Hrr - Hrm Hmm^-1 Hmr, b* = br - Hrm Hmm^-1 bm.
  const Mat15 Hmm = 0.5 * (H.topLeftCorner<15, 15>() + H.topLeftCorner<15, 15>().transpose());
  const Eigen::Matrix<double, 15, 15> Hrm = H.bottomLeftCorner<15, 15>();
  const Eigen::LDLT<Mat15> ldlt(Hmm + 1e-9 * Mat15::Identity());
  Mat15 Hs = H.bottomRightCorner<15, 15>() - Hrm * ldlt.solve(Hrm.transpose());
  const Vec15 bs = b.tail<15>() - Hrm * ldlt.solve(b.head<15>());
  Hs = 0.5 * (Hs + Hs.transpose());
  // As a residual: H* = Jᵀ J, b* = Jᵀ r0, from the eigen-decomposition (tiny modes dropped).
  Eigen::SelfAdjointEigenSolver<Mat15> es(Hs);
  const Vec15 lambda = es.eigenvalues();
  Vec15 sqrt_l = Vec15::Zero(), inv_sqrt_l = Vec15::Zero();
  for (int i = 0; i < 15; ++i) {
    if (lambda(i) > 1e-9) {
      sqrt_l(i) = std::sqrt(lambda(i));
      inv_sqrt_l(i) = 1.0 / sqrt_l(i);
    }
  }
  const Mat15 J = sqrt_l.asDiagonal() * es.eigenvectors().transpose();
  const Vec15 r0 = inv_sqrt_l.asDiagonal() * es.eigenvectors().transpose() * bs;
  prior_ = std::make_unique<StatePrior>(x1.pose, x1.speed_bias, J, r0);
  x1.imu.reset();  // its information is in the prior now
  states_.pop_front();
  ++counters_.marginalised;
}

Eigen::Matrix<double, 6, 6> SlidingWindow::latest_pose_covariance() const {
  // The Gauss-Newton Hessian of the whole window in tangent space, then the newest pose's block
  // of its inverse. 10 states: a 150x150 solve, well under a millisecond.
  const int n = static_cast<int>(states_.size()) * 15;
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
  std::vector<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> plus(states_.size());
  for (std::size_t i = 0; i < states_.size(); ++i) {
    pose_manifold().PlusJacobian(states_[i].pose, plus[i].data());
  }
  const auto add = [&](ceres::CostFunction& cost, const std::vector<std::size_t>& state_of_block,
                       std::vector<const double*> params) {
    const int m = cost.num_residuals();
    Eigen::VectorXd r(m);
    std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J_ambient;
    std::vector<double*> jac_ptrs;
    for (std::size_t k = 0; k < params.size(); ++k) {
      J_ambient.emplace_back(m, cost.parameter_block_sizes()[k]);
    }
    for (auto& Jk : J_ambient) jac_ptrs.push_back(Jk.data());
    cost.Evaluate(params.data(), r.data(), jac_ptrs.data());
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(m, n);
    for (std::size_t k = 0; k < params.size(); ++k) {
      const auto base = static_cast<Eigen::Index>(state_of_block[k] * 15);
      if (cost.parameter_block_sizes()[k] == 7) {
        J.middleCols(base, 6) = J_ambient[k] * plus[state_of_block[k]];
      } else {
        J.middleCols(base + 6, 9) = J_ambient[k];
      }
    }
    H += J.transpose() * J;
  };
  add(*prior_, {0, 0}, {states_[0].pose, states_[0].speed_bias});
  for (std::size_t i = 0; i < states_.size(); ++i) {
    const State& s = states_[i];
    if (s.lidar) add(*s.lidar, {i}, {s.pose});
    if (i > 0 && s.imu) {
      const State& p = states_[i - 1];
      add(*s.imu, {i - 1, i - 1, i, i}, {p.pose, p.speed_bias, s.pose, s.speed_bias});
    }
  }
  const Eigen::MatrixXd cov =
      (H + 1e-9 * Eigen::MatrixXd::Identity(n, n)).ldlt().solve(Eigen::MatrixXd::Identity(n, n));
  return cov.block<6, 6>(n - 15, n - 15);
}

}  // namespace posed::estimator
