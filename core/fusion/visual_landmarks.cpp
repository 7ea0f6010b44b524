#include "core/fusion/visual_landmarks.hpp"

#include <cmath>
#include <memory>
#include <optional>

#include "core/estimator/factors.hpp"

namespace posed::fusion {
int VisualLandmarks::add(estimator::SlidingWindow& window, std::size_t observer,
                         estimator::FactorKind kind, const std::vector<FrameFeature>& features,
                         const Eigen::Isometry3d& T_body_cam, double sqrt_information) {
  using estimator::BlockRole;
  const std::uint64_t observer_id = window.id(observer);
  const Eigen::Isometry3d T_map_j = imu::T_map_imu(window.state(observer));
  // Landmarks whose anchor has left the window go: their factors were marginalised with it.
  std::erase_if(landmarks_, [&](const auto& entry) {
    return !window.index_of(entry.second.anchor_id).has_value();
  });
  int added = 0;
  for (const FrameFeature& f : features) {
    if (config_.max_observations > 0 && added >= config_.max_observations) break;
    auto it = landmarks_.find(f.id);
    if (it == landmarks_.end()) {
      if (!std::isfinite(f.depth_m) || f.depth_m < config_.min_depth_m ||
          f.depth_m > config_.max_depth_m) {
        continue;
      }
      Landmark l;
      l.anchor_id = observer_id;
      l.anchor_normalised = f.normalised;
      l.X_anchor =
          T_body_cam * (f.depth_m * Eigen::Vector3d(f.normalised.x(), f.normalised.y(), 1));
      landmarks_.emplace(f.id, l);
      ++figures_.anchored;
      continue;
    }
    Landmark& l = it->second;
    if (l.outlier || l.anchor_id == observer_id) continue;
    const std::optional<std::size_t> a = window.index_of(l.anchor_id);
    if (!a) continue;
    auto factor = std::make_unique<estimator::LandmarkFactor>(l.X_anchor, T_body_cam, f.normalised,
                                                              sqrt_information);
    const Eigen::Vector3d P_c = factor->point_in_camera(imu::T_map_imu(window.state(*a)), T_map_j);
    if (P_c.z() <= config_.min_depth_m) {
      ++figures_.gated;
      continue;
    }
    const Eigen::Vector2d predicted = P_c.head<2>() / P_c.z();
    const double miss_px = (predicted - f.normalised).norm() * config_.focal_px;
    const double predicted_flow_px = (predicted - l.anchor_normalised).norm() * config_.focal_px;
    if (config_.still_flow_px > 0 && predicted_flow_px > config_.still_flow_px &&
        (f.normalised - l.anchor_normalised).norm() * config_.focal_px < miss_px) {
      l.outlier = true;
      ++figures_.still;
      continue;
    }
    if (miss_px > config_.gate_px) {
      ++figures_.gated;
      continue;
    }
    if (!window.add_factor(kind, std::move(factor),
                           {{l.anchor_id, BlockRole::kPose}, {observer_id, BlockRole::kPose}},
                           std::make_unique<ceres::HuberLoss>(config_.huber_sigma))) {
      continue;
    }
    l.last_id = observer_id;
    l.T_body_cam_last = T_body_cam;
    l.observed_last = f.normalised;
    l.sqrt_information_last = sqrt_information;
    ++added;
  }
  figures_.factors += static_cast<std::uint64_t>(added);
  figures_.last_factors = added;
  last_observer_id_ = observer_id;
  figures_.tracked = landmarks_.size();
  return added;
}

void VisualLandmarks::after_solve(const estimator::SlidingWindow& window) {
  const std::optional<std::size_t> j = window.index_of(last_observer_id_);
  if (!j) return;
  const Eigen::Isometry3d T_map_j = imu::T_map_imu(window.state(*j));
  for (auto& [id, l] : landmarks_) {
    if (l.outlier || l.last_id != last_observer_id_) continue;
    const std::optional<std::size_t> a = window.index_of(l.anchor_id);
    if (!a) continue;
    const estimator::LandmarkFactor factor(l.X_anchor, l.T_body_cam_last, l.observed_last,
                                           l.sqrt_information_last);
    const Eigen::Vector3d P_c = factor.point_in_camera(imu::T_map_imu(window.state(*a)), T_map_j);
    const double whitened =
        P_c.z() > 0 ? (P_c.head<2>() / P_c.z() - l.observed_last).norm() * l.sqrt_information_last
                    : 1e9;
    if (whitened > config_.outlier_sigma) {
      l.outlier = true;
      ++figures_.outliers;
    }
  }
}

}  // namespace posed::fusion
