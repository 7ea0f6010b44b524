#include "core/estimator/sliding_window.hpp"

#include <ceres/problem.h>
#include <ceres/solver.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "core/estimator/factors.hpp"
#include "core/estimator/linearisation.hpp"
#include "core/estimator/marginal_prior.hpp"
#include "core/estimator/pose_manifold.hpp"

namespace posed::estimator {
namespace {

PoseManifold& pose_manifold() {
  static PoseManifold manifold;
  return manifold;
}

void to_arrays(const imu::ImuState& s, double* pose, double* sb) {
  Eigen::Map<Eigen::Vector3d> p(pose), v(sb), bg(sb + 3), ba(sb + 6);
  Eigen::Map<Eigen::Quaterniond> q(pose + 3);
  p = s.p_map_imu_m;
  q = s.q_map_imu.normalized();
  v = s.v_map_mps;
  bg = s.bias.gyro_radps;
  ba = s.bias.accel_mps2;
}

/// H = Jᵀ J, b = Jᵀ r0 as a residual J, r0 (eigen-decomposition; modes below 1e-9 dropped).
void as_residual(const Eigen::MatrixXd& H, const Eigen::VectorXd& b, Eigen::MatrixXd& J,
                 Eigen::VectorXd& r0) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(H);
  const Eigen::VectorXd& lambda = es.eigenvalues();
  Eigen::VectorXd sqrt_l = Eigen::VectorXd::Zero(lambda.size());
  Eigen::VectorXd inv_sqrt_l = Eigen::VectorXd::Zero(lambda.size());
  for (Eigen::Index i = 0; i < lambda.size(); ++i) {
    if (lambda(i) > 1e-9) {
      sqrt_l(i) = std::sqrt(lambda(i));
      inv_sqrt_l(i) = 1.0 / sqrt_l(i);
    }
  }
  J = sqrt_l.asDiagonal() * es.eigenvectors().transpose();
  r0 = inv_sqrt_l.asDiagonal() * es.eigenvectors().transpose() * b;
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

std::optional<std::size_t> SlidingWindow::index_of(std::uint64_t id) const {
  if (states_.empty() || id < states_.front().id || id > states_.back().id) return std::nullopt;
  // Ids are consecutive within the window (a reset starts a new run of them).
  const std::size_t i = static_cast<std::size_t>(id - states_.front().id);
  if (i >= states_.size() || states_[i].id != id) return std::nullopt;
  return i;
}

Eigen::Vector3d SlidingWindow::gravity_map() const {
  return tilt_released_ ? tilted_gravity(config_.gravity_mps2, gravity_tilt_)
                        : Eigen::Vector3d(0, 0, -config_.gravity_mps2);
}

void SlidingWindow::add_gravity_tilt_prior() {
  // The tilt found so far (the map stays), held as well as the start-up alignment levels.
  std::vector<PriorBlock> tilt = {{2, std::vector<double>(gravity_tilt_, gravity_tilt_ + 2)}};
  const Eigen::MatrixXd J_tilt = Eigen::MatrixXd::Identity(2, 2) / config_.gravity_tilt_prior_rad;
  add_factor(FactorKind::kPrior,
             std::make_unique<MarginalPrior>(std::move(tilt), J_tilt, Eigen::VectorXd::Zero(2)),
             {{0, BlockRole::kGravityTilt}});
}

void SlidingWindow::release_gravity_tilt_when_observable() {
  if (!config_.estimate_gravity_tilt || tilt_released_ ||
      heading_span_rad() < config_.gravity_tilt_release_yaw_rad) {
    return;
  }
  // Until now no factor had the tilt (it was zero): the window was the plain one to the bit.
  tilt_released_ = true;
  add_gravity_tilt_prior();
}

void SlidingWindow::track_heading(const Eigen::Quaterniond& q_map_imu) {
  const Eigen::Vector3d x_map = q_map_imu * Eigen::Vector3d::UnitX();
  const double yaw = std::atan2(x_map.y(), x_map.x());
  // States are a scan apart: the heading turns far less than half a turn between them.
  heading_rad_ =
      heading_rad_ ? *heading_rad_ + std::remainder(yaw - *heading_rad_, 2.0 * M_PI) : yaw;
  if (!position_pinned_) return;
  heading_min_rad_ = std::min(heading_min_rad_.value_or(*heading_rad_), *heading_rad_);
  heading_max_rad_ = std::max(heading_max_rad_.value_or(*heading_rad_), *heading_rad_);
}

double* SlidingWindow::block(const BlockRef& ref) {
  if (ref.role == BlockRole::kGravityTilt) {
    return tilt_released_ ? gravity_tilt_ : nullptr;
  }
  const std::optional<std::size_t> i = index_of(ref.state_id);
  if (!i) return nullptr;
  State& s = states_[*i];
  return ref.role == BlockRole::kPose ? s.pose : s.speed_bias;
}

void SlidingWindow::reset(const imu::ImuState& state,
                          const Eigen::Matrix<double, 15, 1>& prior_sigma) {
  states_.clear();
  factors_.clear();
  State& s = states_.emplace_back();
  s.id = next_id_++;
  s.stamp = state.stamp;
  to_arrays(state, s.pose, s.speed_bias);
  std::vector<PriorBlock> blocks = {{7, std::vector<double>(s.pose, s.pose + 7)},
                                    {9, std::vector<double>(s.speed_bias, s.speed_bias + 9)}};
  const Eigen::MatrixXd J = prior_sigma.cwiseInverse().asDiagonal();
  add_factor(FactorKind::kPrior,
             std::make_unique<MarginalPrior>(std::move(blocks), J, Eigen::VectorXd::Zero(15)),
             {{s.id, BlockRole::kPose}, {s.id, BlockRole::kSpeedBias}});
  track_heading(state.q_map_imu);
  if (tilt_released_) add_gravity_tilt_prior();
  release_gravity_tilt_when_observable();
}

void SlidingWindow::add(const imu::ImuState& guess, const imu::Preintegration& pre,
                        const std::optional<LidarPose>& lidar) {
  const std::optional<std::uint64_t> previous =
      states_.empty() ? std::nullopt : std::optional<std::uint64_t>(states_.back().id);
  State& s = states_.emplace_back();
  s.id = next_id_++;
  s.stamp = guess.stamp;
  to_arrays(guess, s.pose, s.speed_bias);
  track_heading(guess.q_map_imu);
  release_gravity_tilt_when_observable();
  if (lidar) {
    add_factor(FactorKind::kLidarPose,
               std::make_unique<LidarPoseFactor>(lidar->T_map_lidar, config_.T_imu_lidar,
                                                 lidar->information),
               {{s.id, BlockRole::kPose}});
  }
  if (previous) {
    std::vector<BlockRef> refs = {{*previous, BlockRole::kPose},
                                  {*previous, BlockRole::kSpeedBias},
                                  {s.id, BlockRole::kPose},
                                  {s.id, BlockRole::kSpeedBias}};
    if (tilt_released_) refs.push_back({0, BlockRole::kGravityTilt});
    add_factor(FactorKind::kImu,
               std::make_unique<ImuFactor>(pre, config_.gravity_mps2, tilt_released_), refs);
  }
  while (static_cast<int>(states_.size()) > config_.size) marginalise_oldest();
}

bool SlidingWindow::add_factor(FactorKind kind, std::unique_ptr<ceres::CostFunction> cost,
                               const std::vector<BlockRef>& refs,
                               std::unique_ptr<ceres::LossFunction> loss) {
  if (refs.size() != cost->parameter_block_sizes().size()) return false;
  WindowFactor f;
  f.kind = kind;
  for (std::size_t k = 0; k < refs.size(); ++k) {
    double* b = block(refs[k]);
    const int expected = refs[k].role == BlockRole::kPose        ? 7
                         : refs[k].role == BlockRole::kSpeedBias ? 9
                                                                 : 2;
    if (b == nullptr || cost->parameter_block_sizes()[k] != expected) return false;
    f.blocks.push_back(b);
  }
  f.cost = std::move(cost);
  f.loss = std::move(loss);
  factors_.push_back(std::move(f));
  ++counters_.factors_added[static_cast<std::size_t>(kind)];
  return true;
}

bool SlidingWindow::solve() {
  if (states_.empty()) return true;
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.enable_fast_removal = false;
  ceres::Problem problem(po);
  for (State& s : states_) {
    problem.AddParameterBlock(s.pose, 7, &pose_manifold());
    problem.AddParameterBlock(s.speed_bias, 9);
  }
  if (tilt_released_) {
    problem.AddParameterBlock(gravity_tilt_, 2);
    ++counters_.solves_tilt_free;
  }
  for (WindowFactor& f : factors_) problem.AddResidualBlock(f.cost.get(), f.loss.get(), f.blocks);
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
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
  State& x0 = states_.front();
  const auto is_marginalised = [&](const double* b) { return b == x0.pose || b == x0.speed_bias; };
  // The factors on x0 leave the list; every other block they touch keeps their information.
  std::vector<WindowFactor> remaining, linearised;
  for (WindowFactor& f : factors_) {
    const bool touches = std::any_of(f.blocks.begin(), f.blocks.end(), is_marginalised);
    (touches ? linearised : remaining).push_back(std::move(f));
  }
  // Tangent layout: x0's 15 coordinates first, then the kept blocks in order of appearance.
  TangentLayout layout;
  layout.add(x0.pose, 7);
  layout.add(x0.speed_bias, 9);
  std::vector<double*> kept;
  std::vector<int> kept_sizes;
  for (const WindowFactor& f : linearised) {
    for (std::size_t k = 0; k < f.blocks.size(); ++k) {
      if (layout.find(f.blocks[k]) != nullptr) continue;
      layout.add(f.blocks[k], f.cost->parameter_block_sizes()[k]);
      kept.push_back(f.blocks[k]);
      kept_sizes.push_back(f.cost->parameter_block_sizes()[k]);
    }
  }
  const int n = layout.size, m = 15, k = n - m;
  if (k > 0) {
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
    for (const WindowFactor& f : linearised) accumulate(f, layout, H, &b);
    // Schur complement onto the kept blocks: H* = Hrr - Hrm Hmm^-1 Hmr, b* = br - Hrm Hmm^-1 bm.
    const Eigen::MatrixXd Hmm = 0.5 * (H.topLeftCorner(m, m) + H.topLeftCorner(m, m).transpose());
    const Eigen::MatrixXd Hrm = H.bottomLeftCorner(k, m);
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(Hmm + 1e-9 * Eigen::MatrixXd::Identity(m, m));
    Eigen::MatrixXd Hs = H.bottomRightCorner(k, k) - Hrm * ldlt.solve(Hrm.transpose());
    const Eigen::VectorXd bs = b.tail(k) - Hrm * ldlt.solve(b.head(m));
    Hs = 0.5 * (Hs + Hs.transpose());
    Eigen::MatrixXd J;
    Eigen::VectorXd r0;
    as_residual(Hs, bs, J, r0);
    std::vector<PriorBlock> blocks;
    for (std::size_t i = 0; i < kept.size(); ++i) {
      blocks.push_back({kept_sizes[i], std::vector<double>(kept[i], kept[i] + kept_sizes[i])});
    }
    WindowFactor prior;
    prior.kind = FactorKind::kPrior;
    prior.cost = std::make_unique<MarginalPrior>(std::move(blocks), J, r0);
    prior.blocks = kept;
    remaining.insert(remaining.begin(), std::move(prior));
  }
  factors_ = std::move(remaining);
  states_.pop_front();
  ++counters_.marginalised;
}

Eigen::Matrix<double, 6, 6> SlidingWindow::latest_pose_covariance() const {
  // The Gauss-Newton Hessian of the whole window in tangent space, then the newest pose's block
  // of its inverse. 10 states: a 150x150 solve, well under a millisecond.
  TangentLayout layout;
  for (const State& s : states_) {
    layout.add(s.pose, 7);
    layout.add(s.speed_bias, 9);
  }
  if (tilt_released_) layout.add(gravity_tilt_, 2);
  const int n = layout.size;
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
  for (const WindowFactor& f : factors_) accumulate(f, layout, H, nullptr);
  const Eigen::MatrixXd cov =
      (H + 1e-9 * Eigen::MatrixXd::Identity(n, n)).ldlt().solve(Eigen::MatrixXd::Identity(n, n));
  const int newest = layout.find(states_.back().pose)->offset;
  return cov.block<6, 6>(newest, newest);
}

std::array<std::size_t, kFactorKinds> SlidingWindow::factor_counts() const {
  std::array<std::size_t, kFactorKinds> counts{};
  for (const WindowFactor& f : factors_) ++counts[static_cast<std::size_t>(f.kind)];
  return counts;
}

void SlidingWindow::residual_norms(FactorKind kind, std::vector<double>& out) const {
  out.clear();
  for (const WindowFactor& f : factors_) {
    if (f.kind != kind) continue;
    Eigen::VectorXd r(f.cost->num_residuals());
    std::vector<const double*> params(f.blocks.begin(), f.blocks.end());
    if (f.cost->Evaluate(params.data(), r.data(), nullptr)) out.push_back(r.norm());
  }
}

}  // namespace posed::estimator
