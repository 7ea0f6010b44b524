#include "tools/eval/trajectory_io.hpp"

#include <Eigen/Geometry>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "tools/eval/eval_error.hpp"

namespace posed::eval {

const char* to_string(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kAuto:
      return "auto";
    case TrajectoryFormat::kTum:
      return "tum";
    case TrajectoryFormat::kKitti:
      return "kitti";
  }
  return "?";
}

namespace {

constexpr std::size_t kTumFields = 8;
constexpr std::size_t kKittiFields = 12;

std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t i = 0;
  auto is_sep = [](char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r'; };
  while (i < line.size()) {
    while (i < line.size() && is_sep(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_sep(line[i])) ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

bool parse_double(std::string_view text, double& value) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return ec == std::errc{} && end == text.data() + text.size() && std::isfinite(value);
}

[[noreturn]] void fail(const std::string& name, std::size_t line, const std::string& what) {
  throw EvalError(name + ":" + std::to_string(line) + ": " + what);
}

std::string field_count_text(TrajectoryFormat format) {
  return format == TrajectoryFormat::kTum
             ? "8 fields (TUM: stamp x y z qx qy qz qw)"
             : "12 fields (KITTI: r11 r12 r13 tx r21 r22 r23 ty r31 r32 r33 tz)";
}

}  // namespace

bool parse_stamp(std::string_view text, TrajectoryTime& stamp) {
  if (text.empty()) return false;
  const bool exponent = text.find_first_of("eE") != std::string_view::npos;
  if (!exponent) {
    // Exact decimal: a double holds a 10-digit UNIX second to only ~0.2 µs, and the association
    // tolerance is compared in ns, so integer arithmetic keeps ties where the file put them.
    bool negative = false;
    std::string_view s = text;
    if (s.front() == '-' || s.front() == '+') {
      negative = s.front() == '-';
      s.remove_prefix(1);
    }
    const std::size_t dot = s.find('.');
    const std::string_view whole = s.substr(0, dot);
    const std::string_view frac = dot == std::string_view::npos ? "" : s.substr(dot + 1);
    if (whole.empty() && frac.empty()) return false;
    // beyond ±9.2e9 s the ns count would overflow int64
    if (whole.size() > 10) return false;
    std::int64_t seconds = 0;
    for (char c : whole) {
      if (c < '0' || c > '9') return false;
      seconds = seconds * 10 + (c - '0');
    }
    if (seconds > 9'000'000'000) return false;
    std::int64_t ns = 0;
    std::int64_t scale = 100'000'000;
    bool round_up = false;
    for (std::size_t k = 0; k < frac.size(); ++k) {
      const char c = frac[k];
      if (c < '0' || c > '9') return false;
      if (k < 9) {
        ns += (c - '0') * scale;
        scale /= 10;
      } else if (k == 9) {
        round_up = c >= '5';
      }
    }
    std::int64_t total = seconds * 1'000'000'000 + ns + (round_up ? 1 : 0);
    stamp = TrajectoryTime::from_ns(negative ? -total : total);
    return true;
  }
  double seconds = 0.0;
  if (!parse_double(text, seconds) || std::fabs(seconds) > 9.2e9) return false;
  stamp = TrajectoryTime::from_ns(Duration::from_seconds(seconds).ns);
  return true;
}

Trajectory parse_trajectory(std::string_view text, const std::string& name,
                            TrajectoryFormat format) {
  Trajectory traj;
  traj.source = name;
  traj.format = format;
  bool orientation_decided = false;
  std::size_t line_no = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t eol = text.find('\n', pos);
    if (eol == std::string_view::npos) eol = text.size();
    const std::string_view line = text.substr(pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    const std::vector<std::string_view> fields = split_fields(line);
    if (fields.empty() || fields.front().front() == '#') continue;

    if (traj.format == TrajectoryFormat::kAuto) {
      if (fields.size() == kTumFields) {
        traj.format = TrajectoryFormat::kTum;
      } else if (fields.size() == kKittiFields) {
        traj.format = TrajectoryFormat::kKitti;
      } else {
        fail(name, line_no,
             "cannot tell the format: expected 8 fields (TUM: stamp x y z qx qy qz qw) or 12 "
             "(KITTI: 3x4 [R|t] row-major), found " +
                 std::to_string(fields.size()));
      }
    }
    const std::size_t expected = traj.format == TrajectoryFormat::kTum ? kTumFields : kKittiFields;
    if (fields.size() != expected) {
      fail(
          name, line_no,
          "expected " + field_count_text(traj.format) + ", found " + std::to_string(fields.size()));
    }

    double v[kKittiFields] = {};
    const std::size_t first_number = traj.format == TrajectoryFormat::kTum ? 1 : 0;
    for (std::size_t k = first_number; k < fields.size(); ++k) {
      if (!parse_double(fields[k], v[k])) {
        fail(name, line_no,
             "field " + std::to_string(k + 1) + " '" + std::string(fields[k]) +
                 "' is not a finite number");
      }
    }

    if (traj.format == TrajectoryFormat::kTum) {
      TrajectoryTime stamp;
      if (!parse_stamp(fields[0], stamp)) {
        fail(name, line_no, "stamp '" + std::string(fields[0]) + "' is not a number [s]");
      }
      if (!traj.stamps.empty() && stamp <= traj.stamps.back()) {
        fail(name, line_no,
             "stamp " + std::string(fields[0]) +
                 " s is not after the previous one: TUM stamps must increase");
      }
      const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
      const double q_norm = q.norm();
      const bool has_q = q_norm > 0.0;
      if (!orientation_decided) {
        traj.has_orientation = has_q;
        orientation_decided = true;
      } else if (has_q != traj.has_orientation) {
        fail(name, line_no,
             has_q ? "quaternion given, but earlier lines are positions only (qx qy qz qw = 0)"
                   : "quaternion is zero, but earlier lines have orientations");
      }
      traj.stamps.push_back(stamp);
      traj.p_world_m.emplace_back(v[1], v[2], v[3]);
      traj.R_world_body.push_back(has_q ? Eigen::Matrix3d(q.normalized().toRotationMatrix())
                                        : Eigen::Matrix3d::Identity());
    } else {
      Eigen::Matrix3d R;
      R << v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10];
      traj.R_world_body.push_back(R);
      traj.p_world_m.emplace_back(v[3], v[7], v[11]);
    }
  }
  if (traj.size() == 0) {
    throw EvalError(name + ": no poses (only blank or '#' comment lines)");
  }
  return traj;
}

Trajectory read_trajectory(const std::string& path, TrajectoryFormat format) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw EvalError(path + ": cannot open: " + std::strerror(errno));
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw EvalError(path + ": read error");
  return parse_trajectory(text.str(), path, format);
}

}  // namespace posed::eval
