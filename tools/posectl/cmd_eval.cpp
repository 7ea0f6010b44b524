// posectl eval --gt GT --est EST: how far an estimated trajectory is from ground truth, the
// figures evo reports (ATE after Umeyama alignment, RPE by distance and by time), as a table
// with units or as JSON, optionally with a top-view PNG coloured by error.
// Exit codes: 0 ok, 2 bad arguments or data (missing file, malformed line, too few associated
// poses, degenerate alignment).

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

#include "tools/eval/eval_error.hpp"
#include "tools/eval/evaluation.hpp"
#include "tools/eval/plot.hpp"
#include "tools/eval/report.hpp"
#include "tools/eval/trajectory_io.hpp"
#include "tools/posectl/commands.hpp"

namespace posed::posectl {

int run_eval(int argc, char** argv) {
  CLI::App app{
      "Compares an estimated trajectory with ground truth: ATE (translation, after alignment) "
      "and RPE (by travelled distance and by time), the way evo computes them.\n"
      "Formats: TUM (`stamp x y z qx qy qz qw`, stamps in s) and KITTI (3x4 [R|t] per line, "
      "no stamps: pose i pairs with pose i), detected per file from the field count.",
      "posectl eval"};
  std::string gt_path, est_path, plot_path;
  eval::TrajectoryFormat format = eval::TrajectoryFormat::kAuto;
  eval::Alignment alignment = eval::Alignment::kSE3;
  double max_diff_s = 0.01;
  double offset_s = 0.0;
  double rpe_delta_m = 100.0;
  double rpe_delta_s = 1.0;
  bool json = false;

  app.add_option("--gt", gt_path, "ground-truth trajectory file")->required();
  app.add_option("--est", est_path, "estimated trajectory file")->required();
  app.add_option("--format", format, "file format of both files: auto, tum, kitti")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, eval::TrajectoryFormat>{{"auto", eval::TrajectoryFormat::kAuto},
                                                        {"tum", eval::TrajectoryFormat::kTum},
                                                        {"kitti", eval::TrajectoryFormat::kKitti}},
          CLI::ignore_case))
      ->default_str("auto");
  app.add_option("--align", alignment,
                 "se3: rotation+translation (Umeyama), sim3: also scale (monocular), none")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, eval::Alignment>{{"se3", eval::Alignment::kSE3},
                                                 {"sim3", eval::Alignment::kSim3},
                                                 {"none", eval::Alignment::kNone}},
          CLI::ignore_case))
      ->default_str("se3");
  app.add_option("--max-diff", max_diff_s,
                 "largest stamp difference accepted when associating poses [s]")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--offset", offset_s, "added to every estimate stamp before associating [s]")
      ->capture_default_str();
  app.add_option("--rpe-delta-m", rpe_delta_m,
                 "RPE pair spacing by travelled ground-truth path, 0 to skip [m]")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--rpe-delta-s", rpe_delta_s, "RPE pair spacing by time, 0 to skip [s]")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--plot", plot_path,
                 "write a top-view PNG (estimate coloured by ATE, ground truth) to this file");
  app.add_flag("--json", json, "print JSON instead of the table");
  CLI11_PARSE(app, argc, argv);

  try {
    const eval::Trajectory gt = eval::read_trajectory(gt_path, format);
    const eval::Trajectory est = eval::read_trajectory(est_path, format);
    eval::EvalOptions options;
    options.association.max_diff = Duration::from_seconds(max_diff_s);
    options.association.est_offset = Duration::from_seconds(offset_s);
    options.alignment = alignment;
    options.rpe_delta_m = rpe_delta_m;
    options.rpe_delta = Duration::from_seconds(rpe_delta_s);
    const eval::EvalResult result = eval::evaluate(gt, est, options);

    const std::string text =
        json ? eval::format_json(gt, est, result) : eval::format_table(gt, est, result);
    std::fputs(text.c_str(), stdout);
    std::fflush(stdout);

    if (!plot_path.empty()) {
      namespace fs = std::filesystem;
      const std::string label =
          fs::path(est_path).filename().string() + " vs " + fs::path(gt_path).filename().string();
      const eval::PlotOutcome plot = eval::plot_evaluation(result, plot_path, label);
      if (plot.written) {
        std::fprintf(stderr, "posectl eval: wrote %s\n", plot_path.c_str());
      } else {
        // The figures above stand on their own; a missing plot is worth a warning, not a
        // failed evaluation.
        std::fprintf(stderr, "posectl eval: warning: plot not written: %s\n", plot.message.c_str());
      }
    }
    return 0;
  } catch (const eval::EvalError& e) {
    std::fprintf(stderr, "posectl eval: error: %s\n", e.what());
    return 2;
  }
}

}  // namespace posed::posectl
