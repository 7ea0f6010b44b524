#pragma once
// The whole evaluation of one estimate against ground truth: associate, align (Umeyama on the
// associated positions), then ATE and RPE. What `posectl eval` prints, as data.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/time.hpp"
#include "tools/eval/association.hpp"
#include "tools/eval/error_stats.hpp"
#include "tools/eval/trajectory.hpp"
#include "tools/eval/umeyama.hpp"

namespace posed::eval {

enum class Alignment {
  kNone,  ///< compare in the files' frames as they are
  kSE3,   ///< rotation + translation (evo -a)
  kSim3,  ///< rotation + translation + scale (evo -as), for monocular estimates
};

/// "none", "se3", "sim3"
const char* to_string(Alignment alignment);

struct EvalOptions {
  AssociationOptions association;
  Alignment alignment = Alignment::kSE3;
  /// RPE pair spacing by travelled ground-truth path; 0 disables [m]
  double rpe_delta_m = 100.0;
  /// RPE pair spacing by time (needs stamps); 0 disables [ns]
  Duration rpe_delta = Duration::from_s(1);
};

/// One RPE variant (by distance or by time).
struct RpeResult {
  /// the pair spacing: [m] by distance, [s] by time
  double delta = 0.0;
  /// "100 m" or "1 s": the delta with its unit, for display
  std::string delta_text;
  /// empty when computed; otherwise why not (no stamps, no orientation, too few pairs)
  std::string skipped_reason;
  /// pairs evaluated [1] (also translation_m.count)
  std::size_t pairs = 0;
  /// translation part of the relative error [m]
  ErrorStats translation_m;
  /// rotation angle of the relative error [deg]
  ErrorStats rotation_deg;
};

struct EvalResult {
  Association association;
  /// estimate -> ground-truth world; identity for Alignment::kNone
  Sim3 T_gt_est;
  Alignment alignment = Alignment::kSE3;
  /// associated ground-truth positions, in pair order [m]
  std::vector<Eigen::Vector3d> p_gt_m;
  /// associated estimate positions after alignment, in pair order [m]
  std::vector<Eigen::Vector3d> p_est_aligned_m;
  /// ATE per pair [m]
  std::vector<double> ate_errors_m;
  /// ATE summary [m]
  ErrorStats ate_m;
  RpeResult rpe_by_distance;
  RpeResult rpe_by_time;
};

/// Throws EvalError on fewer than 3 associated poses, a degenerate alignment, or trajectories
/// that cannot be associated (see associate()).
EvalResult evaluate(const Trajectory& gt, const Trajectory& est, const EvalOptions& options = {});

}  // namespace posed::eval
