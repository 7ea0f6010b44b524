#include "tools/eval/evaluation.hpp"

#include <cstdio>

#include "tools/eval/ate.hpp"
#include "tools/eval/eval_error.hpp"
#include "tools/eval/rpe.hpp"

namespace posed::eval {

const char* to_string(Alignment alignment) {
  switch (alignment) {
    case Alignment::kNone:
      return "none";
    case Alignment::kSE3:
      return "se3";
    case Alignment::kSim3:
      return "sim3";
  }
  return "?";
}

namespace {

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

RpeResult skipped(double delta, std::string delta_text, std::string reason) {
  RpeResult r;
  r.delta = delta;
  r.delta_text = std::move(delta_text);
  r.skipped_reason = std::move(reason);
  return r;
}

RpeResult run_rpe(double delta, std::string delta_text, const std::vector<IndexPair>& pairs,
                  const std::vector<RigidPose>& gt, const std::vector<RigidPose>& est) {
  RpeResult r;
  r.delta = delta;
  r.delta_text = std::move(delta_text);
  if (pairs.empty()) {
    r.skipped_reason = "no pair of poses is " + r.delta_text + " apart";
    return r;
  }
  const RpeErrors errors = relative_pose_errors(gt, est, pairs);
  r.pairs = pairs.size();
  r.translation_m = summarize(errors.translation_m);
  r.rotation_deg = summarize(errors.rotation_deg);
  return r;
}

}  // namespace

EvalResult evaluate(const Trajectory& gt, const Trajectory& est, const EvalOptions& options) {
  EvalResult result;
  result.alignment = options.alignment;
  result.association = associate(gt, est, options.association);
  const Association& a = result.association;
  if (a.size() < 3) {
    std::string hint =
        a.by_index ? ""
                   : " (max-diff " + number_text(options.association.max_diff.seconds()) +
                         " s, offset " + number_text(options.association.est_offset.seconds()) +
                         " s: are the stamps on the same clock?)";
    throw EvalError("only " + std::to_string(a.size()) + " associated poses between " + gt.source +
                    " and " + est.source + ", need at least 3" + hint);
  }

  std::vector<Eigen::Vector3d> p_est_m(a.size());
  result.p_gt_m.resize(a.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    result.p_gt_m[k] = gt.p_world_m[a.gt_index[k]];
    p_est_m[k] = est.p_world_m[a.est_index[k]];
  }
  if (options.alignment != Alignment::kNone) {
    result.T_gt_est = umeyama(p_est_m, result.p_gt_m, options.alignment == Alignment::kSim3);
  }
  result.p_est_aligned_m.resize(a.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    result.p_est_aligned_m[k] = result.T_gt_est.apply(p_est_m[k]);
  }
  result.ate_errors_m = ate_translation_errors_m(result.p_gt_m, result.p_est_aligned_m);
  result.ate_m = summarize(result.ate_errors_m);

  // RPE on the associated, aligned poses; the scale of a Sim(3) alignment applies to the
  // estimate's translations, as evo's -as does.
  std::vector<RigidPose> gt_poses(a.size()), est_poses(a.size());
  std::vector<TrajectoryTime> gt_stamps;
  for (std::size_t k = 0; k < a.size(); ++k) {
    gt_poses[k] = RigidPose{gt.R_world_body[a.gt_index[k]], result.p_gt_m[k]};
    est_poses[k] = RigidPose{result.T_gt_est.R_gt_est * est.R_world_body[a.est_index[k]],
                             result.p_est_aligned_m[k]};
    if (gt.has_stamps()) gt_stamps.push_back(gt.stamps[a.gt_index[k]]);
  }
  const std::string distance_text = number_text(options.rpe_delta_m) + " m";
  const std::string time_text = number_text(options.rpe_delta.seconds()) + " s";
  const std::string no_orientation =
      !gt.has_orientation    ? gt.source + " has positions only (zero quaternions)"
      : !est.has_orientation ? est.source + " has positions only (zero quaternions)"
                             : "";

  const double delta_m = options.rpe_delta_m;
  if (delta_m <= 0.0) {
    result.rpe_by_distance = skipped(delta_m, distance_text, "disabled");
  } else if (!no_orientation.empty()) {
    result.rpe_by_distance = skipped(delta_m, distance_text, no_orientation);
  } else {
    result.rpe_by_distance = run_rpe(
        delta_m, distance_text, pairs_by_path_length(result.p_gt_m, delta_m), gt_poses, est_poses);
  }

  const double delta_s = options.rpe_delta.seconds();
  if (options.rpe_delta.ns <= 0) {
    result.rpe_by_time = skipped(delta_s, time_text, "disabled");
  } else if (gt_stamps.empty()) {
    result.rpe_by_time =
        skipped(delta_s, time_text, "no stamps (" + std::string(to_string(gt.format)) + ")");
  } else if (!no_orientation.empty()) {
    result.rpe_by_time = skipped(delta_s, time_text, no_orientation);
  } else {
    result.rpe_by_time = run_rpe(delta_s, time_text, pairs_by_time(gt_stamps, options.rpe_delta),
                                 gt_poses, est_poses);
  }
  return result;
}

}  // namespace posed::eval
