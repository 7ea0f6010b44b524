#include "core/mapping/loop_closer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/math/so3.hpp"

namespace posed::mapping {
namespace {

/// The rotation that removes `R`'s roll and pitch and keeps its yaw out too: a levelled frame
/// whose x is the body's heading projected onto the horizontal. R_level_base = Rz(yaw)^T R.
Eigen::Matrix3d levelling(const Eigen::Matrix3d& R_odom_base) {
  const Eigen::Vector3d heading = R_odom_base.col(0);
  const double yaw = std::atan2(heading.y(), heading.x());
  return Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_odom_base;
}

double angle_of(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

double seconds_between(HostTime a, HostTime b) { return static_cast<double>(b.ns - a.ns) * 1e-9; }

}  // namespace

LoopCloser::LoopCloser(LoopClosureConfig config)
    : config_(std::move(config)),
      selector_(config_.keyframe_distance_m, config_.keyframe_angle_rad) {}

bool LoopCloser::add(HostTime stamp, const Eigen::Isometry3d& T_odom_base,
                     std::span<const Eigen::Vector3f> points_base) {
  if (!selector_.take(T_odom_base)) {
    return false;
  }
  add_keyframe(stamp, T_odom_base, points_base);
  return true;
}

void LoopCloser::add_keyframe(HostTime stamp, const Eigen::Isometry3d& T_odom_base,
                              std::span<const Eigen::Vector3f> points_base) {
  Keyframe kf;
  kf.stamp = stamp;
  kf.T_odom_base = T_odom_base;
  kf.R_level_base = levelling(T_odom_base.rotation());
  std::vector<Eigen::Vector3f> in_range;
  std::vector<Eigen::Vector3f> level;
  in_range.reserve(points_base.size());
  level.reserve(points_base.size());
  const Eigen::Matrix3f R_level_base = kf.R_level_base.cast<float>();
  const auto max_range2 =
      static_cast<float>(config_.keyframe_max_range_m * config_.keyframe_max_range_m);
  for (const Eigen::Vector3f& p : points_base) {
    if (!p.allFinite() || p.squaredNorm() > max_range2) {
      continue;
    }
    in_range.push_back(p);
    level.push_back(R_level_base * p);
  }
  kf.context = make_scan_context(level, config_.scan_context);
  kf.points_base = thin_cloud(in_range, config_.keyframe_voxel_m);
  figures_.stored_points += kf.points_base.size();

  // A new node where the current correction puts it, tied to the one before by the odometry.
  const std::size_t index = graph_.add_node(T_map_odom_ * T_odom_base);
  if (index > 0) {
    const Keyframe& last = keyframes_.back();
    PoseGraphEdge edge;
    edge.from = index - 1;
    edge.to = index;
    edge.T_from_to = last.T_odom_base.inverse() * T_odom_base;
    const double d = edge.T_from_to.translation().norm();
    edge.sigma_translation_m =
        config_.odometry_sigma_translation_m + config_.odometry_sigma_translation_per_m * d;
    edge.sigma_rotation_rad =
        config_.odometry_sigma_rotation_rad + config_.odometry_sigma_rotation_per_m * d;
    graph_.add_edge(edge);
  }
  keyframes_.push_back(std::move(kf));
  figures_.keyframes = keyframes_.size();
  if (config_.attempt_every_keyframes > 0 && index >= next_attempt_ &&
      index % static_cast<std::size_t>(config_.attempt_every_keyframes) == 0) {
    try_loop(index);
  }
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
  std::optional<Candidate> best;
  double best_distance = config_.search_radius_m;
  for (std::size_t i = 0; i < eligible; ++i) {
    const Eigen::Isometry3d T_map_i = graph_.node(i);
    const double d = (T_map_i.translation() - T_map_query.translation()).norm();
    if (d < best_distance) {
      best_distance = d;
      best = Candidate{i, false, T_map_i.inverse() * T_map_query};
    }
  }
  return best;
}

std::optional<LoopCloser::Candidate> LoopCloser::descriptor_candidate(std::size_t query,
                                                                      std::size_t eligible) const {
  const Keyframe& q = keyframes_[query];
  // Nearest ring keys (heading-invariant) among the keyframes old enough, then Scan Context
  // distances over those few.
  std::vector<std::pair<float, std::size_t>> by_ring_key;
  for (std::size_t i = 0; i < eligible; ++i) {
    by_ring_key.emplace_back((keyframes_[i].context.ring_key - q.context.ring_key).squaredNorm(),
                             i);
  }
  const auto n = std::min<std::size_t>(by_ring_key.size(),
                                       static_cast<std::size_t>(config_.ring_key_candidates));
  std::partial_sort(by_ring_key.begin(), by_ring_key.begin() + static_cast<std::ptrdiff_t>(n),
                    by_ring_key.end());
  std::optional<Candidate> best;
  double best_distance = config_.scan_context_max_distance;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = by_ring_key[k].second;
    const ScanContextMatch match =
        match_scan_contexts(q.context, keyframes_[i].context, config_.scan_context);
    if (match.distance < best_distance) {
      best_distance = match.distance;
      // In the levelled frames the query sits at the candidate turned by the match's yaw; the
      // places are the same, so no translation.
      const Eigen::Matrix3d R_level_c_level_q =
          Eigen::AngleAxisd(match.yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      Eigen::Isometry3d guess = Eigen::Isometry3d::Identity();
      guess.linear() = keyframes_[i].R_level_base.transpose() * R_level_c_level_q * q.R_level_base;
      best = Candidate{i, true, guess};
    }
  }
  return best;
}

std::vector<Eigen::Vector3f> LoopCloser::submap(std::size_t centre,
                                                std::size_t newest_allowed) const {
  const std::size_t k = static_cast<std::size_t>(std::max(0, config_.submap_keyframes));
  const std::size_t first = centre > k ? centre - k : 0;
  const std::size_t last = std::min(centre + k, newest_allowed);
  const Eigen::Isometry3d T_centre_map = graph_.node(centre).inverse();
  std::vector<Eigen::Vector3f> points;
  for (std::size_t i = first; i <= last; ++i) {
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
      register_clouds(keyframes_[query].points_base, target, candidate->T_candidate_query_guess,
                      config_.registration);
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

void LoopCloser::update_correction() {
  const Keyframe& last = keyframes_.back();
  T_map_odom_ = graph_.node(keyframes_.size() - 1) * last.T_odom_base.inverse();
}

}  // namespace posed::mapping
