#include "core/mapping/loop_closer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "core/mapping/place_recognition.hpp"
#include "core/math/se3.hpp"

namespace posed::mapping {
namespace {

double angle_of(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

double seconds_between(HostTime a, HostTime b) { return static_cast<double>(b.ns - a.ns) * 1e-9; }

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

}  // namespace

LoopCloser::LoopCloser(LoopClosureConfig config)
    : config_(std::move(config)),
      selector_(config_.keyframe_distance_m, config_.keyframe_angle_rad) {}

bool LoopCloser::add(HostTime stamp, const Eigen::Isometry3d& T_odom_base,
                     std::span<const Eigen::Vector3f> points_base, double degenerate_share) {
  if (!selector_.take(T_odom_base)) {
    return false;
  }
  add_keyframe(stamp, T_odom_base, points_base, degenerate_share);
  return true;
}

void LoopCloser::add_keyframe(HostTime stamp, const Eigen::Isometry3d& T_odom_base,
                              std::span<const Eigen::Vector3f> points_base,
                              double degenerate_share) {
  DescribedScan described =
      describe_scan(points_base, T_odom_base.rotation(), config_.keyframe_max_range_m,
                    config_.keyframe_max_range_m, config_.keyframe_voxel_m, config_.scan_context);
  Keyframe kf;
  kf.stamp = stamp;
  kf.T_odom_base = T_odom_base;
  kf.R_level_base = described.R_level_base;
  kf.points_base = CompactCloud(described.points_base);
  kf.context = std::move(described.context);
  figures_.stored_points += kf.points_base.size();
  figures_.stored_bytes += kf.points_base.bytes();

  // A new node where the current correction puts it, tied to the one before by the odometry.
  const std::size_t index = graph_.add_node(T_map_odom_ * T_odom_base);
  if (index > 0) {
    const Keyframe& last = keyframes_.back();
    PoseGraphEdge edge;
    edge.from = index - 1;
    edge.to = index;
    edge.T_from_to = last.T_odom_base.inverse() * T_odom_base;
    const double d = edge.T_from_to.translation().norm();
    const double share = std::clamp(degenerate_share, 0.0, 1.0);
    edge.sigma_translation_m = config_.odometry_sigma_translation_m +
                               (config_.odometry_sigma_translation_per_m +
                                share * config_.odometry_sigma_translation_degenerate_per_m) *
                                   d;
    edge.sigma_rotation_rad = config_.odometry_sigma_rotation_rad +
                              (config_.odometry_sigma_rotation_per_m +
                               share * config_.odometry_sigma_rotation_degenerate_per_m) *
                                  d;
    graph_.add_edge(edge);
    kf.edge_sigma_translation_m = edge.sigma_translation_m;
    kf.edge_sigma_rotation_rad = edge.sigma_rotation_rad;
  }
  keyframes_.push_back(std::move(kf));
  figures_.keyframes = keyframes_.size();
  if (config_.attempt_every_keyframes > 0 && index >= next_attempt_ &&
      index % static_cast<std::size_t>(config_.attempt_every_keyframes) == 0) {
    try_loop(index);
  }
  drop_cloud_if_mapped(index);
}

void LoopCloser::drop_cloud_if_mapped(std::size_t query) {
  if (config_.mapped_keyframe_distance_m <= 0 || loops_.empty() ||
      query - loops_.back().query > static_cast<std::size_t>(config_.mapped_trust_keyframes)) {
    return;
  }
  // Only keyframes old enough to be a loop count: the one before is always near.
  if (!nearest_with_cloud(graph_.node(query), old_enough(query),
                          config_.mapped_keyframe_distance_m)) {
    return;
  }
  // Its descriptor goes too: the older keyframe's describes the same place, and a match here
  // would have no cloud to register onto.
  Keyframe& kf = keyframes_[query];
  figures_.stored_points -= kf.points_base.size();
  figures_.stored_bytes -= kf.points_base.bytes();
  kf.points_base = CompactCloud();
  kf.context = ScanContext();
  ++figures_.mapped_keyframes;
}

std::optional<std::size_t> LoopCloser::nearest_with_cloud(const Eigen::Isometry3d& T_map,
                                                          std::size_t eligible,
                                                          double radius_m) const {
  std::optional<std::size_t> best;
  double best_distance = radius_m;
  for (std::size_t i = 0; i < eligible; ++i) {
    if (keyframes_[i].points_base.size() == 0) continue;
    const double d = (graph_.node(i).translation() - T_map.translation()).norm();
    if (d < best_distance) {
      best_distance = d;
      best = i;
    }
  }
  return best;
}

std::size_t LoopCloser::old_enough(std::size_t query) const {
  std::size_t n = 0;
  // Stamps rise with the index: the first keyframe too recent ends the old enough ones.
  while (n < query && seconds_between(keyframes_[n].stamp, keyframes_[query].stamp) >=
                          config_.min_separation_s) {
    ++n;
  }
  return n;
}

std::optional<LoopCloser::Candidate> LoopCloser::distance_candidate(std::size_t query,
                                                                    std::size_t eligible) const {
  const Eigen::Isometry3d T_map_query = graph_.node(query);
  const std::optional<std::size_t> i =
      nearest_with_cloud(T_map_query, eligible, config_.search_radius_m);
  if (!i) {
    return std::nullopt;
  }
  return Candidate{*i, false, graph_.node(*i).inverse() * T_map_query};
}

std::optional<LoopCloser::Candidate> LoopCloser::descriptor_candidate(std::size_t query,
                                                                      std::size_t eligible) const {
  const Keyframe& q = keyframes_[query];
  const std::optional<DescriptorMatch> match = best_descriptor_match(
      q.context, q.R_level_base, eligible,
      [this](std::size_t i) -> const ScanContext& { return keyframes_[i].context; },
      [this](std::size_t i) -> const Eigen::Matrix3d& { return keyframes_[i].R_level_base; },
      config_.ring_key_candidates, config_.scan_context_max_distance, config_.scan_context);
  if (!match) {
    return std::nullopt;
  }
  // (A keyframe without a cloud has no descriptor either: every match has a cloud.)
  return Candidate{match->index, true, match->T_match_query_guess};
}

std::vector<Eigen::Vector3f> LoopCloser::submap(std::size_t centre,
                                                std::size_t newest_allowed) const {
  const std::size_t k = static_cast<std::size_t>(std::max(0, config_.submap_keyframes));
  const std::size_t first = centre > k ? centre - k : 0;
  const std::size_t last = std::min(centre + k, newest_allowed);
  std::vector<std::size_t> members;
  for (std::size_t i = first; i <= last; ++i) {
    if (keyframes_[i].points_base.size() > 0) members.push_back(i);
  }
  // Keyframes in the window that left their cloud to an older one (a mapped place) are made up
  // for by the keyframes with clouds nearest the centre, so the submap covers as much as before.
  std::size_t missing = last - first + 1 - members.size();
  if (missing > 0) {
    const Eigen::Vector3d centre_m = graph_.node(centre).translation();
    std::vector<std::pair<double, std::size_t>> near;
    for (std::size_t i = 0; i <= newest_allowed; ++i) {
      if ((i >= first && i <= last) || keyframes_[i].points_base.size() == 0) continue;
      near.emplace_back((graph_.node(i).translation() - centre_m).norm(), i);
    }
    missing = std::min(missing, near.size());
    std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(missing),
                      near.end());
    for (std::size_t n = 0; n < missing; ++n) members.push_back(near[n].second);
  }
  const Eigen::Isometry3d T_centre_map = graph_.node(centre).inverse();
  std::vector<Eigen::Vector3f> points;
  for (const std::size_t i : members) {
    const Eigen::Isometry3f T_centre_i = (T_centre_map * graph_.node(i)).cast<float>();
    for (const Eigen::Vector3f& p : keyframes_[i].points_base) {
      points.push_back(T_centre_i * p);
    }
  }
  return points;
}

void LoopCloser::try_loop(std::size_t query) {
  ++figures_.attempts;
  const std::size_t eligible = old_enough(query);
  std::optional<Candidate> candidate = distance_candidate(query, eligible);
  if (candidate) {
    ++figures_.distance_candidates;
  } else {
    candidate = descriptor_candidate(query, eligible);
    if (!candidate) {
      return;
    }
    ++figures_.descriptor_candidates;
  }
  // The submap holds only keyframes old enough to be a loop, never the query's own neighbours.
  // (Every candidate is one of them, so there is at least one.)
  const std::vector<Eigen::Vector3f> target = submap(candidate->index, eligible - 1);
  const auto started = std::chrono::steady_clock::now();
  const RegistrationResult reg =
      register_clouds(keyframes_[query].points_base.points(), target,
                      candidate->T_candidate_query_guess, config_.registration);
  figures_.registration_time_s +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (!reg.accepted()) {
    ++figures_.rejected[static_cast<std::size_t>(reg.verdict)];
    return;
  }
  PoseGraphEdge edge;
  edge.from = candidate->index;
  edge.to = query;
  edge.T_from_to = reg.T_target_source;
  edge.sigma_translation_m = config_.loop_sigma_translation_m;
  edge.sigma_rotation_rad = config_.loop_sigma_rotation_rad;
  edge.robust_sigmas = config_.loop_robust_sigmas;
  edge.loop = true;
  const Eigen::Isometry3d T_map_query_loop = graph_.node(candidate->index) * reg.T_target_source;
  const Eigen::Isometry3d T_map_query = graph_.node(query);
  LoopRecord record;
  record.query = query;
  record.candidate = candidate->index;
  record.stamp = keyframes_[query].stamp;
  record.by_descriptor = candidate->by_descriptor;
  record.rms_m = reg.rms_m;
  record.overlap = reg.overlap;
  record.constraint = reg.constraint;
  record.correction_m = (T_map_query_loop.translation() - T_map_query.translation()).norm();
  record.correction_sigmas = correction_sigmas(candidate->index, query, reg.T_target_source);
  if (config_.loop_max_correction_sigmas > 0 &&
      record.correction_sigmas > config_.loop_max_correction_sigmas) {
    ++figures_.implausible;
    last_implausible_ = record;
    return;
  }

  if (!candidate->by_descriptor || record.correction_m <= config_.search_radius_m) {
    pending_.reset();
    accept(edge, record);
    return;
  }
  // A large correction from a descriptor alone: held until the next attempt agrees. Both put
  // the map frame in the same place when they agree: compare the corrections they imply.
  const Eigen::Isometry3d T_map_odom_loop =
      T_map_query_loop * keyframes_[query].T_odom_base.inverse();
  if (pending_) {
    const Eigen::Isometry3d T_map_odom_pending =
        pending_->T_map_query * keyframes_[pending_->query].T_odom_base.inverse();
    const Eigen::Isometry3d diff = T_map_odom_pending.inverse() * T_map_odom_loop;
    if (diff.translation().norm() <= config_.confirm_translation_m &&
        angle_of(diff.rotation()) <= config_.confirm_rotation_rad) {
      const Pending confirmed = *pending_;
      pending_.reset();
      accept(confirmed.edge, confirmed.record);
      accept(edge, record);
      return;
    }
    ++figures_.unconfirmed;
  }
  pending_ = Pending{query, T_map_query_loop, edge, record};
}

double LoopCloser::correction_sigmas(std::size_t candidate, std::size_t query,
                                     const Eigen::Isometry3d& T_candidate_query) const {
  // The covariance of a right perturbation [rotation, translation] of T_candidate_i, carried
  // along the odometry edges: each moves the perturbation so far into its own end's frame and
  // adds its own.
  Matrix6d covariance = Matrix6d::Zero();
  for (std::size_t i = candidate + 1; i <= query; ++i) {
    const Keyframe& kf = keyframes_[i];
    const Eigen::Isometry3d T_i_previous = kf.T_odom_base.inverse() * keyframes_[i - 1].T_odom_base;
    const Matrix6d ad = se3::adjoint(T_i_previous);
    covariance = ad * covariance * ad.transpose();
    covariance.diagonal().head<3>().array() +=
        kf.edge_sigma_rotation_rad * kf.edge_sigma_rotation_rad;
    covariance.diagonal().tail<3>().array() +=
        kf.edge_sigma_translation_m * kf.edge_sigma_translation_m;
  }
  covariance.diagonal().head<3>().array() +=
      config_.loop_sigma_rotation_rad * config_.loop_sigma_rotation_rad;
  covariance.diagonal().tail<3>().array() +=
      config_.loop_sigma_translation_m * config_.loop_sigma_translation_m;
  const Eigen::Isometry3d T_graph = graph_.node(candidate).inverse() * graph_.node(query);
  const Eigen::Isometry3d delta = T_graph.inverse() * T_candidate_query;
  Vector6d error;
  error.head<3>() = so3::log(Eigen::Matrix3d(delta.rotation()));
  error.tail<3>() = delta.translation();
  return std::sqrt(std::max(0.0, error.dot(covariance.ldlt().solve(error))));
}

void LoopCloser::accept(const PoseGraphEdge& edge, const LoopRecord& record) {
  graph_.add_edge(edge);
  next_attempt_ =
      keyframes_.size() + static_cast<std::size_t>(std::max(0, config_.cooldown_keyframes));
  loops_.push_back(record);
  figures_.loops = loops_.size();
  const PoseGraphSolve solve = graph_.optimise();
  ++figures_.optimisations;
  figures_.last_optimisation_s = solve.solve_time_s;
  update_correction();
}

KeyframeMap LoopCloser::snapshot() const {
  KeyframeMap map;
  map.voxel_m = config_.keyframe_voxel_m;
  map.max_range_m = config_.keyframe_max_range_m;
  map.scan_context = config_.scan_context;
  map.keyframes.reserve(keyframes_.size());
  for (std::size_t i = 0; i < keyframes_.size(); ++i) {
    const Keyframe& kf = keyframes_[i];
    map.keyframes.push_back({kf.stamp.ns, graph_.node(i), kf.points_base, kf.context});
  }
  map.edges = graph_.edges();
  return map;
}

void LoopCloser::update_correction() {
  const Keyframe& last = keyframes_.back();
  T_map_odom_ = graph_.node(keyframes_.size() - 1) * last.T_odom_base.inverse();
}

}  // namespace posed::mapping
