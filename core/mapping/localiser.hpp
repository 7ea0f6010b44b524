#pragma once
// Localisation on a prior map (docs/mapping.md, Localisation): the odometry runs as always, and
// this finds map -> odom against a KeyframeMap a mapping run saved, without growing the map.
//
// Aligning (at start) and lost: every scan, the place is looked up. From an initial pose when one
// was given (config or rt/initialpose): the map keyframes near it are the target. Otherwise by
// descriptor (Scan Context over every map keyframe); a descriptor fix is taken only when the
// next attempt confirms it, because a repetitive place matches descriptors in many places.
// Localised: at every keyframe (by distance or turn) the scan is registered onto the map
// keyframes around where the current correction puts it; each verified registration is a fix that
// replaces map -> odom. Registrations that fail (a degenerate corridor, an open stretch) leave the
// correction as it was, carried by the odometry; after lost_after_m of travel without a fix the
// state is lost and the place is looked up again.
//
// Pure and single-threaded like the rest of core/; the daemon runs it on the mapping stage.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "core/mapping/keyframe_map.hpp"
#include "core/mapping/keyframe_selector.hpp"
#include "core/mapping/place_recognition.hpp"
#include "core/mapping/registration.hpp"
#include "core/time.hpp"

namespace posed::mapping {

struct LocalisationConfig {
  double keyframe_distance_m = 2.0;  ///< localised: a fix is attempted after moving this far [m]
  double keyframe_angle_rad = 0.35;  ///< or turning this much [rad]
  /// a scan's points farther than this (or than the map's clouds reach) are not used [m]
  double max_range_m = 60.0;
  int align_every_scans = 1;  ///< aligning or lost: a lookup every n-th scan [1]
  /// tracking and initial poses: map keyframes within this of the predicted pose are the target
  /// [m]
  double track_radius_m = 12.0;
  int track_keyframes = 10;                ///< at most this many of them, nearest first [1]
  double scan_context_max_distance = 0.4;  ///< descriptor lookups: at most this distance
  int ring_key_candidates = 10;            ///< nearest ring keys compared in full [1]
  /// a descriptor fix is taken when the next attempt's agrees within these [m], [rad]
  double confirm_translation_m = 0.5;
  double confirm_rotation_rad = 0.05;
  double lost_after_m = 25.0;  ///< travel without a fix after which the state is lost [m]
  RegistrationConfig registration;
  /// aligning or lost: a fix must pin every direction at least this much (registration's
  /// min_constraint while localised): a first fix has no earlier one to agree with [0..1]
  double first_fix_min_constraint = 0.05;
};

enum class LocalisationState : std::uint8_t { kAligning, kLocalised, kLost };
std::string_view state_name(LocalisationState state);

struct LocalisationFigures {
  std::uint64_t scans = 0;                  ///< scans shown [1]
  std::uint64_t lookups = 0;                ///< aligning / lost attempts [1]
  std::uint64_t track_attempts = 0;         ///< localised attempts [1]
  std::uint64_t fixes = 0;                  ///< verified registrations taken [1]
  std::uint64_t unconfirmed = 0;            ///< descriptor fixes the next attempt contradicted
  std::uint64_t off_map = 0;                ///< attempts with no map keyframe near [1]
  std::uint64_t times_lost = 0;             ///< localised -> lost [1]
  std::array<std::uint64_t, 6> rejected{};  ///< by RegistrationVerdict [1]
  double registration_time_s = 0;           ///< summed [s]
  std::optional<HostTime> first_scan;       ///< the first scan's stamp
  std::optional<HostTime> first_fix;        ///< the scan the first fix was taken at
  double last_fix_rms_m = 0;                ///< [m]
  double last_fix_overlap = 0;              ///< [0..1]
};

class Localiser {
 public:
  Localiser(KeyframeMap map, LocalisationConfig config);

  /// Where base_link is in the map now (RViz's 2D Pose Estimate, or config): the next lookup
  /// starts from it. Aligning or lost only; while localised a fix is tracked already, and a new
  /// initial pose puts the localiser back to aligning from it.
  void set_initial_pose(const Eigen::Isometry3d& T_map_base);

  /// One odometry pose and the deskewed scan at it (base_link), in stamp order.
  void add_scan(HostTime stamp, const Eigen::Isometry3d& T_odom_base,
                std::span<const Eigen::Vector3f> points_base);

  LocalisationState state() const { return state_; }
  /// The correction from the odometry frame onto the prior map (identity until the first fix).
  const Eigen::Isometry3d& T_map_odom() const { return T_map_odom_; }
  const LocalisationFigures& figures() const { return figures_; }
  const KeyframeMap& map() const { return map_; }

 private:
  struct Fix {
    Eigen::Isometry3d T_map_odom;
    RegistrationResult registration;
  };
  /// The map keyframes with a cloud within track_radius_m of `centre_map_m`, nearest first, at
  /// most `cap`, without `exclude`.
  std::vector<std::size_t> nearest_keyframes(const Eigen::Vector3d& centre_map_m, std::size_t cap,
                                             std::optional<std::size_t> exclude = {}) const;
  /// Registers the scan onto the map keyframes near `T_map_query_guess`; nullopt when none is
  /// near or the registration is refused.
  /// How far a scan is used: the configured range, at most the map clouds' own.
  double max_range_m() const { return std::min(config_.max_range_m, map_.max_range_m); }
  std::optional<Fix> fix_near(const DescribedScan& scan, const Eigen::Isometry3d& T_odom_query,
                              const Eigen::Isometry3d& T_map_query_guess);
  /// Registers the scan onto the map keyframe its descriptor matches best.
  std::optional<Fix> fix_by_descriptor(const DescribedScan& scan,
                                       const Eigen::Isometry3d& T_odom_query);
  std::optional<Fix> register_onto(const DescribedScan& scan, const Eigen::Isometry3d& T_odom_query,
                                   std::span<const std::size_t> keyframes,
                                   const Eigen::Isometry3d& T_first_query_guess);
  void take(const Fix& fix, HostTime stamp, const Eigen::Isometry3d& T_odom_base);
  void look_up(HostTime stamp, const Eigen::Isometry3d& T_odom_base, const DescribedScan& scan);

  KeyframeMap map_;
  LocalisationConfig config_;
  std::vector<Eigen::Matrix3d> map_levels_;  ///< each map keyframe's R_level_base
  KeyframeSelector selector_;
  LocalisationState state_ = LocalisationState::kAligning;
  Eigen::Isometry3d T_map_odom_ = Eigen::Isometry3d::Identity();
  std::optional<Eigen::Isometry3d> initial_T_map_base_;
  std::optional<Fix> pending_;  ///< a descriptor fix waiting for confirmation
  Eigen::Vector3d p_odom_last_fix_ = Eigen::Vector3d::Zero();
  double travelled_since_fix_m_ = 0;
  std::optional<Eigen::Vector3d> p_odom_previous_;
  LocalisationFigures figures_;
};

}  // namespace posed::mapping
