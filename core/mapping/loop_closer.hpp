#pragma once
// The mapping layer's keyframe graph (DESIGN.md, Data flow: mapping → tf map→odom). Odometry
// poses and their deskewed scans go in; every metre (or turn) one becomes a keyframe: its pose,
// a thinned copy of its cloud and a Scan Context. At keyframes it looks for a loop: a keyframe
// older than min_separation_s near the current estimate (by distance), or, when drift is too
// large for that, one whose Scan Context matches (by descriptor; such a loop is accepted only
// when the next attempt confirms the same correction, because a repetitive place matches
// descriptors everywhere). Each candidate is verified by registration (registration.hpp) onto a
// submap around it; a verified one becomes a loop edge and the graph is optimised. What comes out
// is map → odom: the correction that moves the odometry frame onto the optimised map, so odometry
// itself stays continuous (REP-105).
//
// Pure and single-threaded like the rest of core/: the daemon runs it on a stage of its own,
// off the real-time path (a registration costs tens of milliseconds, an optimisation more).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/mapping/keyframe_map.hpp"
#include "core/mapping/keyframe_selector.hpp"
#include "core/mapping/pose_graph.hpp"
#include "core/mapping/registration.hpp"
#include "core/mapping/scan_context.hpp"
#include "core/time.hpp"

namespace posed::mapping {

struct LoopClosureConfig {
  double keyframe_distance_m = 1.0;     ///< a new keyframe after moving this far [m]
  double keyframe_angle_rad = 0.35;     ///< or turning this much [rad]
  double keyframe_voxel_m = 0.3;        ///< a keyframe's cloud is kept at this resolution [m]
  double keyframe_max_range_m = 120.0;  ///< points farther are not kept [m]
  /// A keyframe this near an older one that keeps its cloud keeps only its pose and edges (no
  /// cloud, no descriptor) once its loop attempt is done, while a loop accepted within the last
  /// mapped_trust_keyframes keyframes vouches that the graph has this place where the older
  /// keyframe is: the place is mapped, and a patrol round it would otherwise grow the map by its
  /// clouds every lap (docs/mapping.md, Memory). 0: every keyframe keeps its cloud [m]
  double mapped_keyframe_distance_m = 1.5;
  int mapped_trust_keyframes = 30;  ///< [1]
  /// loops are looked for at every n-th keyframe: registration is the expensive part [1]
  int attempt_every_keyframes = 2;
  /// after a loop is accepted, none is looked for over this many keyframes: a revisit would
  /// otherwise close one every attempt, each a registration and an optimisation that move the
  /// map by millimetres [1]
  int cooldown_keyframes = 10;
  /// a candidate must be at least this much older than the query: a loop, not a neighbour [s]
  double min_separation_s = 30.0;
  double search_radius_m = 8.0;  ///< distance candidates: within this of the estimate [m]
  int submap_keyframes = 5;      ///< keyframes either side of the candidate in its submap [1]
  ScanContextConfig scan_context;
  double scan_context_max_distance = 0.25;  ///< descriptor candidates: at most this distance
  int ring_key_candidates = 8;              ///< nearest ring keys compared in full [1]
  /// a descriptor loop whose correction moves the query more than search_radius_m waits for the
  /// next attempt to agree within these [m], [rad]
  double confirm_translation_m = 1.0;
  double confirm_rotation_rad = 0.05;
  RegistrationConfig registration;
  // Edge weights. Odometry: sigma = base + per-metre x distance between the keyframes.
  double odometry_sigma_translation_m = 0.01;
  double odometry_sigma_translation_per_m = 0.01;
  double odometry_sigma_rotation_rad = 0.001;
  double odometry_sigma_rotation_per_m = 0.001;
  /// added per metre when the estimator called the scans between two keyframes degenerate
  /// (scaled by their share): lidar odometry drifts where geometry is poor (an open stretch), so a
  /// loop's correction belongs there rather than spread over the whole lap [m/m], [rad/m]
  double odometry_sigma_translation_degenerate_per_m = 0.0;
  double odometry_sigma_rotation_degenerate_per_m = 0.0;
  double loop_sigma_translation_m = 0.05;
  double loop_sigma_rotation_rad = 0.01;
  /// A verified loop whose correction lies further than this from where the graph puts the
  /// query, in sigmas of the odometry edges chained from the candidate to the query (plus the
  /// loop edge's own), is refused as implausible: another place that looks like this one fits
  /// its registration as well as the true one does, but it asks the odometry for a drift its
  /// model rules out (campus seed 47: a descriptor match 74 m away, both keyframes' scans fitting
  /// at 0.06 m, asked for a 40 deg turn: 12.6 sigma; a true loop after the odometry had run
  /// off by 85 m on seed 48: 5.3 sigma). 0: no such test [sigma]
  double loop_max_correction_sigmas = 8.0;
  /// Cauchy scale on loop edges [sigma]; 0: none. Off by default: a true loop after long drift
  /// starts hundreds of sigmas off and a robust loss would discard it as an outlier; the
  /// registration's tests and the descriptor confirmation are what keep wrong loops out.
  double loop_robust_sigmas = 0.0;
};

/// One accepted loop, for the status, the summary and the tests.
struct LoopRecord {
  std::size_t query = 0;      ///< keyframe index [1]
  std::size_t candidate = 0;  ///< keyframe index [1]
  HostTime stamp;             ///< the query keyframe's stamp
  bool by_descriptor = false;
  double rms_m = 0;         ///< registration inlier RMS [m]
  double overlap = 0;       ///< registration overlap [0..1]
  double constraint = 0;    ///< weakest direction's information share [0..1]
  double correction_m = 0;  ///< how far the loop moved the query from the graph's estimate [m]
  /// that correction in sigmas of the odometry chained from the candidate (loop_closer.hpp,
  /// loop_max_correction_sigmas) [sigma]
  double correction_sigmas = 0;
};

struct LoopClosureFigures {
  std::uint64_t keyframes = 0;
  std::uint64_t attempts = 0;               ///< keyframes a loop was looked for at [1]
  std::uint64_t distance_candidates = 0;    ///< [1]
  std::uint64_t descriptor_candidates = 0;  ///< [1]
  std::uint64_t loops = 0;                  ///< accepted [1]
  std::uint64_t unconfirmed = 0;            ///< descriptor loops the next attempt contradicted
  /// verified loops refused for a correction the odometry cannot have drifted by [1]
  std::uint64_t implausible = 0;
  std::array<std::uint64_t, 6> rejected{};  ///< by RegistrationVerdict [1]
  std::uint64_t optimisations = 0;          ///< [1]
  double last_optimisation_s = 0;           ///< [s]
  double registration_time_s = 0;           ///< summed [s]
  std::size_t stored_points = 0;            ///< keyframe cloud points held [1]
  std::size_t stored_bytes = 0;             ///< what those points take [B]
  /// keyframes that dropped their cloud and descriptor: an older keyframe had the place mapped [1]
  std::uint64_t mapped_keyframes = 0;
};

class LoopCloser {
 public:
  explicit LoopCloser(LoopClosureConfig config);

  /// One odometry pose and the scan at it (`points_base`: the deskewed scan in base_link at
  /// `stamp`). Returns true when it became a keyframe (KeyframeSelector with the config's
  /// distance and angle). Poses must come in stamp order.
  bool add(HostTime stamp, const Eigen::Isometry3d& T_odom_base,
           std::span<const Eigen::Vector3f> points_base, double degenerate_share = 0.0);
  /// A pose a KeyframeSelector with the config's distance and angle already chose (the daemon
  /// selects on the fusion thread and copies only those scans): becomes a keyframe.
  /// `degenerate_share`: of the scans since the last keyframe, those whose match the estimator
  /// found degenerate [0..1]; it widens the odometry edge from the last keyframe.
  void add_keyframe(HostTime stamp, const Eigen::Isometry3d& T_odom_base,
                    std::span<const Eigen::Vector3f> points_base, double degenerate_share = 0.0);

  const LoopClosureConfig& config() const { return config_; }
  /// The correction from the odometry frame onto the optimised map.
  const Eigen::Isometry3d& T_map_odom() const { return T_map_odom_; }
  /// Keyframe i's optimised pose (base_link in map).
  Eigen::Isometry3d T_map_keyframe(std::size_t i) const { return graph_.node(i); }
  std::size_t keyframe_count() const { return keyframes_.size(); }
  HostTime keyframe_stamp(std::size_t i) const { return keyframes_.at(i).stamp; }
  /// Keyframe i's cloud; empty when the place was mapped already (mapped_keyframe_distance_m),
  /// and then its descriptor is empty too.
  const CompactCloud& keyframe_points(std::size_t i) const { return keyframes_.at(i).points_base; }

  const LoopClosureFigures& figures() const { return figures_; }
  const std::vector<LoopRecord>& loops() const { return loops_; }
  /// The last loop refused as implausible (loop_max_correction_sigmas), for the log.
  const std::optional<LoopRecord>& last_implausible() const { return last_implausible_; }
  const PoseGraph& graph() const { return graph_; }
  /// The map as it stands: every keyframe at its optimised pose, with its cloud and descriptor,
  /// and the graph's edges (stamp_ns: the keyframes' HostTime; a writer may restamp them).
  KeyframeMap snapshot() const;

 private:
  struct Keyframe {
    HostTime stamp;
    Eigen::Isometry3d T_odom_base;
    Eigen::Matrix3d R_level_base;  ///< removes roll and pitch: the Scan Context's frame
    CompactCloud points_base;
    ScanContext context;
    /// sigmas of the odometry edge from the keyframe before (none for the first) [m], [rad]
    double edge_sigma_translation_m = 0;
    double edge_sigma_rotation_rad = 0;
  };
  struct Candidate {
    std::size_t index = 0;
    bool by_descriptor = false;
    Eigen::Isometry3d T_candidate_query_guess = Eigen::Isometry3d::Identity();
  };
  struct Pending {
    std::size_t query = 0;
    Eigen::Isometry3d T_map_query;  ///< where the unconfirmed loop puts the query
    PoseGraphEdge edge;
    LoopRecord record;
  };

  void try_loop(std::size_t query);
  /// How many keyframes, from the first, are at least min_separation_s older than `query`: the
  /// ones a loop may join.
  std::size_t old_enough(std::size_t query) const;
  /// `eligible`: old_enough(query).
  std::optional<Candidate> distance_candidate(std::size_t query, std::size_t eligible) const;
  std::optional<Candidate> descriptor_candidate(std::size_t query, std::size_t eligible) const;
  /// The nearest keyframe among [0, eligible) to `T_map` that keeps its cloud, within `radius_m`.
  std::optional<std::size_t> nearest_with_cloud(const Eigen::Isometry3d& T_map,
                                                std::size_t eligible, double radius_m) const;
  std::vector<Eigen::Vector3f> submap(std::size_t centre, std::size_t newest_allowed) const;
  /// Drops `query`'s cloud and descriptor when an older keyframe has its place mapped and a recent
  /// loop vouches for the graph there.
  void drop_cloud_if_mapped(std::size_t query);
  /// How far `T_candidate_query` (a registration) lies from the graph's relative pose of the
  /// two keyframes, in sigmas of the odometry edges between them and the loop edge [sigma].
  double correction_sigmas(std::size_t candidate, std::size_t query,
                           const Eigen::Isometry3d& T_candidate_query) const;
  void accept(const PoseGraphEdge& edge, const LoopRecord& record);
  void update_correction();

  LoopClosureConfig config_;
  KeyframeSelector selector_;
  std::vector<Keyframe> keyframes_;
  PoseGraph graph_;
  Eigen::Isometry3d T_map_odom_ = Eigen::Isometry3d::Identity();
  std::optional<Pending> pending_;
  std::size_t next_attempt_ = 0;  ///< no attempt before this keyframe index (cooldown)
  LoopClosureFigures figures_;
  std::vector<LoopRecord> loops_;
  std::optional<LoopRecord> last_implausible_;
};

}  // namespace posed::mapping
