#pragma once
// Reading TUM and KITTI trajectory files. Lines starting with '#' and blank lines are skipped;
// fields are separated by spaces, tabs or commas. Every problem is an EvalError naming
// file:line and what was expected, e.g.
//   "est.txt:12: expected 8 fields (TUM: stamp x y z qx qy qz qw), found 7".

#include <string>
#include <string_view>

#include "tools/eval/trajectory.hpp"

namespace posed::eval {

/// Reads `path`. With kAuto the first pose line decides: 8 fields is TUM, 12 is KITTI. Throws
/// EvalError when the file cannot be opened, a line is malformed, stamps do not increase, or
/// the file holds no pose.
Trajectory read_trajectory(const std::string& path,
                           TrajectoryFormat format = TrajectoryFormat::kAuto);

/// Same, from text already in memory; `name` stands for the file in messages.
Trajectory parse_trajectory(std::string_view text, const std::string& name,
                            TrajectoryFormat format = TrajectoryFormat::kAuto);

/// Parses a decimal stamp in seconds ("1305031102.160407", "-0.5", "1.3e9") to ns. Decimal
/// notation is converted exactly (digits beyond ns are rounded); exponent notation goes
/// through double. False when `text` is not a number.
bool parse_stamp(std::string_view text, TrajectoryTime& stamp);

}  // namespace posed::eval
