#include "tools/eval/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "tools/eval/rpe.hpp"

namespace posed::eval {
namespace {

std::string printf_string(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string printf_string(const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  char buf[512];
  const int n = std::vsnprintf(buf, sizeof buf, fmt, args);
  va_end(args);
  return std::string(buf, static_cast<std::size_t>(std::clamp(n, 0, 511)));
}

const char* format_name(TrajectoryFormat f) {
  return f == TrajectoryFormat::kKitti ? "KITTI" : "TUM";
}

const char* alignment_name(Alignment a) {
  switch (a) {
    case Alignment::kNone:
      return "none";
    case Alignment::kSE3:
      return "SE(3) Umeyama";
    case Alignment::kSim3:
      return "Sim(3) Umeyama (with scale)";
  }
  return "?";
}

std::string stats_row(const std::string& name, std::size_t count, const ErrorStats& s) {
  return printf_string("%-30s %6zu %11.6f %11.6f %11.6f %11.6f %11.6f %11.6f\n", name.c_str(),
                       count, s.rmse, s.mean, s.median, s.std, s.min, s.max);
}

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += printf_string("\\u%04x", static_cast<unsigned>(c));
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  return printf_string("%.10g", v);
}

std::string json_stats(const ErrorStats& s) {
  return "{\"count\": " + std::to_string(s.count) + ", \"rmse\": " + json_number(s.rmse) +
         ", \"mean\": " + json_number(s.mean) + ", \"median\": " + json_number(s.median) +
         ", \"std\": " + json_number(s.std) + ", \"min\": " + json_number(s.min) +
         ", \"max\": " + json_number(s.max) + "}";
}

std::string json_trajectory(const Trajectory& t) {
  return "{\"file\": " + json_string(t.source) + ", \"format\": \"" + to_string(t.format) +
         "\", \"poses\": " + std::to_string(t.size()) +
         ", \"has_orientation\": " + (t.has_orientation ? "true" : "false") + "}";
}

std::string json_rpe(const RpeResult& r, const char* delta_key, double delta) {
  std::string out = std::string("{\"") + delta_key + "\": " + json_number(delta);
  if (!r.skipped_reason.empty())
    return out + ", \"skipped\": " + json_string(r.skipped_reason) + "}";
  return out + ", \"pairs\": " + std::to_string(r.pairs) +
         ", \"translation_m\": " + json_stats(r.translation_m) +
         ", \"rotation_deg\": " + json_stats(r.rotation_deg) + "}";
}

}  // namespace

std::string format_table(const Trajectory& gt, const Trajectory& est, const EvalResult& r) {
  const Association& a = r.association;
  std::string out;
  out += printf_string("ground truth  %s (%s, %zu poses)\n", gt.source.c_str(),
                       format_name(gt.format), gt.size());
  out += printf_string("estimate      %s (%s, %zu poses)\n", est.source.c_str(),
                       format_name(est.format), est.size());
  if (a.by_index) {
    out += printf_string("association   %zu pairs, pose i with pose i (no stamps)\n", a.size());
  } else {
    out += printf_string(
        "association   %zu pairs, largest |dt| %.6f s; %zu poses beyond max-diff, %zu "
        "duplicate matches dropped\n",
        a.size(), a.max_abs_diff.seconds(), a.beyond_max_diff, a.duplicates_dropped);
  }
  const Eigen::Vector3d& t = r.T_gt_est.t_gt_est_m;
  out += printf_string(
      "alignment     %s: rotation %.6f deg, translation [%.6f %.6f %.6f] m, "
      "scale %.9f\n\n",
      alignment_name(r.alignment), rotation_angle_deg(r.T_gt_est.R_gt_est), t.x(), t.y(), t.z(),
      r.T_gt_est.scale);
  out += printf_string("%-30s %6s %11s %11s %11s %11s %11s %11s\n", "metric", "n", "rmse", "mean",
                       "median", "std", "min", "max");
  out += stats_row("ATE translation [m]", r.ate_m.count, r.ate_m);
  for (const RpeResult* rpe : {&r.rpe_by_distance, &r.rpe_by_time}) {
    if (!rpe->skipped_reason.empty()) {
      out += printf_string("%-30s skipped: %s\n", ("RPE " + rpe->delta_text).c_str(),
                           rpe->skipped_reason.c_str());
      continue;
    }
    out += stats_row("RPE " + rpe->delta_text + " translation [m]", rpe->pairs, rpe->translation_m);
    out += stats_row("RPE " + rpe->delta_text + " rotation [deg]", rpe->pairs, rpe->rotation_deg);
  }
  return out;
}

std::string format_json(const Trajectory& gt, const Trajectory& est, const EvalResult& r) {
  const Association& a = r.association;
  const Eigen::Matrix3d& R = r.T_gt_est.R_gt_est;
  const Eigen::Vector3d& t = r.T_gt_est.t_gt_est_m;
  std::string out = "{\n";
  out += "  \"gt\": " + json_trajectory(gt) + ",\n";
  out += "  \"est\": " + json_trajectory(est) + ",\n";
  out += "  \"association\": {\"pairs\": " + std::to_string(a.size()) +
         ", \"by_index\": " + (a.by_index ? "true" : "false") +
         ", \"max_abs_diff_s\": " + json_number(a.max_abs_diff.seconds()) +
         ", \"beyond_max_diff\": " + std::to_string(a.beyond_max_diff) +
         ", \"duplicates_dropped\": " + std::to_string(a.duplicates_dropped) + "},\n";
  out += "  \"alignment\": {\"mode\": \"" + std::string(to_string(r.alignment)) +
         "\", \"R_gt_est\": [";
  for (int i = 0; i < 3; ++i) {
    out += std::string(i ? ", " : "") + "[" + json_number(R(i, 0)) + ", " + json_number(R(i, 1)) +
           ", " + json_number(R(i, 2)) + "]";
  }
  out += "], \"t_gt_est_m\": [" + json_number(t.x()) + ", " + json_number(t.y()) + ", " +
         json_number(t.z()) + "], \"scale\": " + json_number(r.T_gt_est.scale) +
         ", \"rotation_deg\": " + json_number(rotation_angle_deg(R)) + "},\n";
  out += "  \"ate\": {\"translation_m\": " + json_stats(r.ate_m) + "},\n";
  out += "  \"rpe\": {\"by_distance\": " +
         json_rpe(r.rpe_by_distance, "delta_m", r.rpe_by_distance.delta) +
         ",\n          \"by_time\": " + json_rpe(r.rpe_by_time, "delta_s", r.rpe_by_time.delta) +
         "}\n";
  out += "}\n";
  return out;
}

}  // namespace posed::eval
