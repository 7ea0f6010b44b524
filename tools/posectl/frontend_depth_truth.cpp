#include "tools/posectl/frontend_depth_truth.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "daemon/pipeline/estimator_config.hpp"
#include "drivers/recording/mcap_reader.hpp"
#include "tools/sim/bvh.hpp"
#include "tools/sim/scenarios.hpp"
#include "tools/sim/simulator.hpp"

namespace posed::posectl {

struct FrontendDepthTruth::World {
  sim::Scenario scenario;
  std::unique_ptr<sim::Bvh> bvh;
  std::int64_t host_epoch_ns = 0;
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
  /// thermal mode's camera: the thermal camera's origin with the visible camera's axes (its
  /// features are rays of the thermal image registered to the visible grid at infinity)
  Eigen::Isometry3d T_base_thermal_origin = Eigen::Isometry3d::Identity();
};

namespace {

bool parse(const std::map<std::string, std::string>& entries, const std::string& key, double& out) {
  const auto it = entries.find(key);
  if (it == entries.end()) return false;
  char* end = nullptr;
  out = std::strtod(it->second.c_str(), &end);
  return end != it->second.c_str();
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace

FrontendDepthTruth::~FrontendDepthTruth() = default;

std::unique_ptr<FrontendDepthTruth> FrontendDepthTruth::for_recording(
    const std::string& path, const config::PosedConfig& config, std::string& why) {
  drivers::recording::McapReader reader;
  if (!reader.open(path, why)) return nullptr;
  // Metadata records are read on the way through the data; posectl sim writes its record at the
  // start of the file, before the first message.
  drivers::recording::McapMessage first;
  reader.next(first);
  const std::map<std::string, std::string>* entries = nullptr;
  for (const auto& record : reader.metadata()) {
    if (record.name == sim::kSimMetadataName) entries = &record.entries;
  }
  if (entries == nullptr) {
    why = "not a simulated recording (no " + std::string(sim::kSimMetadataName) + " record)";
    return nullptr;
  }
  double seed = 0, duration_s = 0, epoch_ns = 0, gravity = 0;
  const auto scenario = entries->find("scenario");
  if (scenario == entries->end() || !parse(*entries, "seed", seed) ||
      !parse(*entries, "duration_s", duration_s) || !parse(*entries, "host_epoch_ns", epoch_ns) ||
      !parse(*entries, "gravity_mps2", gravity)) {
    why = "the " + std::string(sim::kSimMetadataName) + " record is incomplete";
    return nullptr;
  }
  // Another drive through the seed's world when the recording names one.
  std::optional<std::uint64_t> drive_seed;
  if (double d = 0; parse(*entries, "drive_seed", d)) {
    drive_seed = static_cast<std::uint64_t>(d);
  }
  std::optional<sim::Scenario> built = sim::make_scenario(
      scenario->second, static_cast<std::uint64_t>(seed), drive_seed, duration_s, gravity, why);
  if (!built) return nullptr;
  auto truth = std::unique_ptr<FrontendDepthTruth>(new FrontendDepthTruth());
  truth->world_ = std::make_unique<World>();
  truth->world_->scenario = std::move(*built);
  truth->world_->bvh = std::make_unique<sim::Bvh>(truth->world_->scenario.world);
  truth->world_->host_epoch_ns = static_cast<std::int64_t>(epoch_ns);
  truth->world_->T_base_cam = pipeline::to_isometry(config.extrinsics.T_imu_cam);
  truth->focal_px_ = config.visible_camera.fx;
  truth->world_->T_base_thermal_origin =
      truth->world_->T_base_cam *
      Eigen::Translation3d(pipeline::to_isometry(config.extrinsics.T_cam_thermal).translation());
  char text[128];
  std::snprintf(text, sizeof text, "%s seed %.0f, %.1f s", scenario->second.c_str(), seed,
                duration_s);
  truth->description_ = text;
  return truth;
}

void FrontendDepthTruth::on_frame(const vision::FrontendFrame& frame,
                                  const vision::VisualFrontend&) {
  const auto m = static_cast<std::size_t>(frame.mode);
  // The frame's stamp is its exposure on the recording's host clock: true time plus the epoch.
  const double t_s = static_cast<double>(frame.stamp.ns - world_->host_epoch_ns) * 1e-9;
  const sim::TrajectorySample s = world_->scenario.trajectory.at(t_s);
  const Eigen::Isometry3d T_map_cam =
      Eigen::Translation3d(s.p_map_base_m) * s.q_map_base *
      (frame.mode == vision::FrontendMode::kThermal ? world_->T_base_thermal_origin
                                                    : world_->T_base_cam);
  const Eigen::Isometry3d T_cam_map = T_map_cam.inverse();
  std::unordered_map<std::uint64_t, LastSeen> seen_now;
  seen_now.reserve(frame.features.size());
  for (const vision::FrontendFeature& f : frame.features) {
    const Eigen::Vector3d d_cam = Eigen::Vector3d(f.normalised.x(), f.normalised.y(), 1.0);
    const Eigen::Vector3d dir = (T_map_cam.linear() * d_cam).normalized();
    const std::optional<sim::RayHit> hit = world_->bvh->cast(T_map_cam.translation(), dir, 200.0);
    if (const auto last = last_seen_[m].find(f.id); last != last_seen_[m].end()) {
      add_track_step(m, f, last->second, T_cam_map);
    }
    if (!hit) {
      missed_[m] += std::isnan(f.depth_m) ? 0 : 1;
      continue;
    }
    const Eigen::Vector3d p_map = T_map_cam.translation() + hit->t_m * dir;
    seen_now.emplace(f.id, LastSeen{f.normalised, p_map});
    if (std::isnan(f.depth_m)) continue;
    const double z_true = (T_cam_map * p_map).z();
    const double error = std::abs(f.depth_m - z_true);
    abs_errors_m_[m].push_back(error);
    relative_errors_[m].push_back(error / z_true);
    signed_relative_errors_[m].push_back((f.depth_m - z_true) / z_true);
  }
  last_seen_[m] = std::move(seen_now);
}

void FrontendDepthTruth::add_track_step(std::size_t m, const vision::FrontendFeature& f,
                                        const LastSeen& last, const Eigen::Isometry3d& T_cam_map) {
  const Eigen::Vector3d p_cam = T_cam_map * last.p_map_m;
  if (p_cam.z() <= 1e-3) return;  // behind the camera now: nothing to judge
  const Eigen::Vector2d n_true = p_cam.head<2>() / p_cam.z();
  const Eigen::Vector2d true_flow_px = (n_true - last.normalised) * focal_px_;
  const double true_flow = true_flow_px.norm();
  if (true_flow < kMinTrueFlowPx) return;
  const Eigen::Vector2d seen_flow_px = (f.normalised - last.normalised) * focal_px_;
  const double error_px = (seen_flow_px - true_flow_px).norm();
  const double along = seen_flow_px.dot(true_flow_px) / (true_flow * true_flow);
  track_steps_[m].push_back({static_cast<float>(error_px),
                             error_px <= std::max(1.0, 0.2 * true_flow), along < 0.3, f.verified});
}

TrackTruthStats FrontendDepthTruth::track_stats(vision::FrontendMode mode) const {
  const std::vector<TrackStep>& steps = track_steps_[static_cast<std::size_t>(mode)];
  TrackTruthStats s;
  s.steps = steps.size();
  if (steps.empty()) return s;
  std::vector<double> errors;
  errors.reserve(steps.size());
  std::uint64_t with_world = 0, still = 0, v_with_world = 0, v_still = 0;
  for (const TrackStep& step : steps) {
    errors.push_back(step.error_px);
    with_world += step.with_world ? 1 : 0;
    still += step.held_still ? 1 : 0;
    if (!step.verified) continue;
    ++s.verified_steps;
    v_with_world += step.with_world ? 1 : 0;
    v_still += step.held_still ? 1 : 0;
  }
  const auto share = [](std::uint64_t k, std::uint64_t n) {
    return n == 0 ? 0.0 : static_cast<double>(k) / static_cast<double>(n);
  };
  s.median_error_px = quantile(std::move(errors), 0.5);
  s.with_world = share(with_world, s.steps);
  s.held_still = share(still, s.steps);
  s.verified_with_world = share(v_with_world, s.verified_steps);
  s.verified_held_still = share(v_still, s.verified_steps);
  return s;
}

DepthErrorStats FrontendDepthTruth::stats(vision::FrontendMode mode) const {
  const auto m = static_cast<std::size_t>(mode);
  DepthErrorStats s;
  s.missed = missed_[m];
  s.features = abs_errors_m_[m].size() + s.missed;
  s.median_abs_m = quantile(abs_errors_m_[m], 0.5);
  s.p90_abs_m = quantile(abs_errors_m_[m], 0.9);
  s.median_relative = quantile(relative_errors_[m], 0.5);
  s.median_signed_relative = quantile(signed_relative_errors_[m], 0.5);
  const auto within = std::count_if(relative_errors_[m].begin(), relative_errors_[m].end(),
                                    [](double r) { return r <= 0.10; });
  s.within_10_percent =
      relative_errors_[m].empty()
          ? 0.0
          : static_cast<double>(within) / static_cast<double>(relative_errors_[m].size());
  return s;
}

}  // namespace posed::posectl
