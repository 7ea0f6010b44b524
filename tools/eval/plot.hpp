#pragma once
// The PNG of an evaluation: posectl eval writes the associated positions and ATE errors to a
// temporary CSV and runs tools/plot-eval (python3 + matplotlib, Agg backend) on it. Plotting in
// Python keeps a plotting stack out of the C++ build; when python3 or matplotlib is missing
// the figures are still printed and the message says what to install.

#include <string>

#include "tools/eval/evaluation.hpp"

namespace posed::eval {

struct PlotOutcome {
  /// true when the PNG was written
  bool written = false;
  /// why not, with what to do about it (empty when written)
  std::string message;
};

/// The plot CSV: header `gt_x_m,gt_y_m,gt_z_m,est_x_m,est_y_m,est_z_m,ate_m`, one row per pair,
/// estimate positions aligned. Throws EvalError when the file cannot be written.
void write_plot_csv(const EvalResult& result, const std::string& path);

/// Where plot-eval is: $POSED_SOURCE_DIR/tools, then beside the executable
/// (<bin>/../share/posed, <bin>), then the source tree this was built from. Empty if nowhere.
std::string find_plot_script();

/// Writes `out_png` showing `result`; `label` names the comparison in the title (the RMSE and
/// the alignment are added). The Python interpreter is $POSED_PYTHON if set, else Debian's
/// /usr/bin/python3 (where python3-matplotlib installs), else python3 on PATH.
PlotOutcome plot_evaluation(const EvalResult& result, const std::string& out_png,
                            const std::string& label);

}  // namespace posed::eval
