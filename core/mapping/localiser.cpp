#include "core/mapping/localiser.hpp"

#include <algorithm>
#include <chrono>
#include <utility>

namespace posed::mapping {
namespace {

double angle_of(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

}  // namespace

std::string_view state_name(LocalisationState state) {
  switch (state) {
    case LocalisationState::kAligning:
      return "aligning";
    case LocalisationState::kLocalised:
      return "localised";
    case LocalisationState::kLost:
      return "lost";
  }
  return "unknown";
}

Localiser::Localiser(KeyframeMap map, LocalisationConfig config)
    : map_(std::move(map)),
      config_(std::move(config)),
      selector_(config_.keyframe_distance_m, config_.keyframe_angle_rad) {
  map_levels_.reserve(map_.keyframes.size());
  for (const MapKeyframe& kf : map_.keyframes) {
    map_levels_.push_back(levelling(kf.T_map_base.rotation()));
  }
}

void Localiser::set_initial_pose(const Eigen::Isometry3d& T_map_base) {
  initial_T_map_base_ = T_map_base;
  pending_.reset();
  if (state_ == LocalisationState::kLocalised) {
    state_ = LocalisationState::kAligning;
  }
}

void Localiser::add_scan(HostTime stamp, const Eigen::Isometry3d& T_odom_base,
                         std::span<const Eigen::Vector3f> points_base) {
  ++figures_.scans;
  if (!figures_.first_scan) {
    figures_.first_scan = stamp;
  }
  const Eigen::Vector3d p_odom = T_odom_base.translation();
  if (p_odom_previous_) {
    travelled_since_fix_m_ += (p_odom - *p_odom_previous_).norm();
  }
  p_odom_previous_ = p_odom;

  if (state_ == LocalisationState::kLocalised) {
    if (!selector_.take(T_odom_base)) {
      return;
    }
    const DescribedScan scan = describe_scan(points_base, T_odom_base.rotation(), map_.max_range_m,
                                             max_range_m(), map_.voxel_m, map_.scan_context);
    ++figures_.track_attempts;
    if (const std::optional<Fix> fix = fix_near(scan, T_odom_base, T_map_odom_ * T_odom_base)) {
      take(*fix, stamp, T_odom_base);
    } else if (travelled_since_fix_m_ > config_.lost_after_m) {
      state_ = LocalisationState::kLost;
      ++figures_.times_lost;
    }
    return;
  }
  const auto every = static_cast<std::uint64_t>(std::max(1, config_.align_every_scans));
  if ((figures_.scans - 1) % every != 0) {
    return;
  }
  look_up(stamp, T_odom_base,
          describe_scan(points_base, T_odom_base.rotation(), map_.max_range_m, max_range_m(),
                        map_.voxel_m, map_.scan_context));
}

void Localiser::look_up(HostTime stamp, const Eigen::Isometry3d& T_odom_base,
                        const DescribedScan& scan) {
  ++figures_.lookups;
  if (initial_T_map_base_) {
    // Where the user said: trusted without confirmation once the registration verifies it.
    if (const std::optional<Fix> fix = fix_near(scan, T_odom_base, *initial_T_map_base_)) {
      initial_T_map_base_.reset();
      take(*fix, stamp, T_odom_base);
      return;
    }
  }
  if (state_ == LocalisationState::kLost) {
    // The old correction may still be close: the odometry carried it.
    if (const std::optional<Fix> fix = fix_near(scan, T_odom_base, T_map_odom_ * T_odom_base)) {
      take(*fix, stamp, T_odom_base);
      return;
    }
  }
  const std::optional<Fix> fix = fix_by_descriptor(scan, T_odom_base);
  if (!fix) {
    return;
  }
  if (pending_) {
    const Eigen::Isometry3d diff = pending_->T_map_odom.inverse() * fix->T_map_odom;
    if (diff.translation().norm() <= config_.confirm_translation_m &&
        angle_of(diff.rotation()) <= config_.confirm_rotation_rad) {
      pending_.reset();
      take(*fix, stamp, T_odom_base);
      return;
    }
    ++figures_.unconfirmed;
  }
  pending_ = fix;
}

void Localiser::take(const Fix& fix, HostTime stamp, const Eigen::Isometry3d& T_odom_base) {
  T_map_odom_ = fix.T_map_odom;
  state_ = LocalisationState::kLocalised;
  pending_.reset();
  ++figures_.fixes;
  if (!figures_.first_fix) {
    figures_.first_fix = stamp;
  }
  figures_.last_fix_rms_m = fix.registration.rms_m;
  figures_.last_fix_overlap = fix.registration.overlap;
  travelled_since_fix_m_ = 0;
  // The next tracking attempt comes a keyframe spacing after this fix.
  selector_ = KeyframeSelector(config_.keyframe_distance_m, config_.keyframe_angle_rad);
  selector_.take(T_odom_base);
}

std::vector<std::size_t> Localiser::nearest_keyframes(const Eigen::Vector3d& centre_map_m,
                                                      std::size_t cap,
                                                      std::optional<std::size_t> exclude) const {
  std::vector<std::pair<double, std::size_t>> near;
  for (std::size_t i = 0; i < map_.keyframes.size(); ++i) {
    const double d = (map_.keyframes[i].T_map_base.translation() - centre_map_m).norm();
    // A keyframe without a cloud left its place to an older one (LoopClosureConfig's
    // mapped_keyframe_distance_m): nothing to register onto.
    if (i != exclude && d <= config_.track_radius_m && map_.keyframes[i].points_base.size() > 0) {
      near.emplace_back(d, i);
    }
  }
  const std::size_t n = std::min(near.size(), cap);
  std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(n), near.end());
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < n; ++k) out.push_back(near[k].second);
  return out;
}

std::optional<Localiser::Fix> Localiser::fix_near(const DescribedScan& scan,
                                                  const Eigen::Isometry3d& T_odom_query,
                                                  const Eigen::Isometry3d& T_map_query_guess) {
  const std::vector<std::size_t> keyframes =
      nearest_keyframes(T_map_query_guess.translation(),
                        static_cast<std::size_t>(std::max(0, config_.track_keyframes)));
  if (keyframes.empty()) {
    ++figures_.off_map;
    return std::nullopt;
  }
  const Eigen::Isometry3d T_first_query_guess =
      map_.keyframes[keyframes.front()].T_map_base.inverse() * T_map_query_guess;
  return register_onto(scan, T_odom_query, keyframes, T_first_query_guess);
}

std::optional<Localiser::Fix> Localiser::fix_by_descriptor(const DescribedScan& scan,
                                                           const Eigen::Isometry3d& T_odom_query) {
  const std::optional<DescriptorMatch> match = best_descriptor_match(
      scan.context, scan.R_level_base, map_.keyframes.size(),
      [this](std::size_t i) -> const ScanContext& { return map_.keyframes[i].context; },
      [this](std::size_t i) -> const Eigen::Matrix3d& { return map_levels_[i]; },
      config_.ring_key_candidates, config_.scan_context_max_distance, map_.scan_context);
  if (!match) {
    return std::nullopt;
  }
  // The matched keyframe first (the registration's frame), then its neighbours in the map.
  std::vector<std::size_t> keyframes{match->index};
  for (const std::size_t i : nearest_keyframes(
           map_.keyframes[match->index].T_map_base.translation(),
           static_cast<std::size_t>(std::max(0, config_.track_keyframes - 1)), match->index)) {
    keyframes.push_back(i);
  }
  return register_onto(scan, T_odom_query, keyframes, match->T_match_query_guess);
}

std::optional<Localiser::Fix> Localiser::register_onto(
    const DescribedScan& scan, const Eigen::Isometry3d& T_odom_query,
    std::span<const std::size_t> keyframes, const Eigen::Isometry3d& T_first_query_guess) {
  const MapKeyframe& first = map_.keyframes[keyframes.front()];
  const Eigen::Isometry3d T_first_map = first.T_map_base.inverse();
  // The target is cut as the query is: a map keyframe's far points, seen from another place
  // than the query's, add more of the map's own error than they pin.
  const auto range2 = static_cast<float>(max_range_m() * max_range_m());
  std::vector<Eigen::Vector3f> target;
  for (const std::size_t i : keyframes) {
    const Eigen::Isometry3f T_first_i = (T_first_map * map_.keyframes[i].T_map_base).cast<float>();
    for (const Eigen::Vector3f& p : map_.keyframes[i].points_base) {
      if (p.squaredNorm() <= range2) {
        target.push_back(T_first_i * p);
      }
    }
  }
  // A first fix has no earlier one to agree with, so it must pin every direction harder.
  RegistrationConfig registration = config_.registration;
  if (state_ != LocalisationState::kLocalised) {
    registration.min_constraint =
        std::max(registration.min_constraint, config_.first_fix_min_constraint);
  }
  const auto started = std::chrono::steady_clock::now();
  const RegistrationResult reg =
      register_clouds(scan.points_base, target, T_first_query_guess, registration);
  figures_.registration_time_s +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (!reg.accepted()) {
    ++figures_.rejected[static_cast<std::size_t>(reg.verdict)];
    return std::nullopt;
  }
  return Fix{first.T_map_base * reg.T_target_source * T_odom_query.inverse(), reg};
}

}  // namespace posed::mapping
