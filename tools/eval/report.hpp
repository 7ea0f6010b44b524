#pragma once
// How an evaluation is shown: a table for people (every number with its unit) and JSON for
// machines (units in the key names: `_m`, `_deg`, `_s`).

#include <string>

#include "tools/eval/evaluation.hpp"
#include "tools/eval/trajectory.hpp"

namespace posed::eval {

std::string format_table(const Trajectory& gt, const Trajectory& est, const EvalResult& result);

std::string format_json(const Trajectory& gt, const Trajectory& est, const EvalResult& result);

}  // namespace posed::eval
