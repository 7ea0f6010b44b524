// posectl bench lio: per-scan cost of the lidar-inertial estimator on one core, with the
// breakdown by step, on simulated VLP-32C scans (~55k points) and A9 samples of the default rig
// driving `street_night`, decoded by the real drivers. Also the trajectory error of that run.
// Then the same scans again with one helper thread for the lidar front end (threads.lidar_helpers,
// as posed runs by default): its cost per scan, and whether every pose came out the same (give the
// bench two CPUs for that run to mean anything; `taskset -c 0` shares one between the two).

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "core/estimator/lio_estimator.hpp"
#include "daemon/config/config_loader.hpp"
#include "daemon/pipeline/estimator_config.hpp"
#include "daemon/pipeline/lidar_helper.hpp"
#include "drivers/velodyne/scan_builder.hpp"
#include "tools/eval/umeyama.hpp"
#include "tools/posectl/bench.hpp"
#include "tools/sim/lidar_imu_run.hpp"
#include "tools/sim/rig_config.hpp"

namespace posed::posectl {
namespace {

using Clock = std::chrono::steady_clock;

/// Times every step of every scan.
class StepTimer final : public estimator::LioStepProbe {
 public:
  void begin(estimator::LioStep step) override { start_[index(step)] = Clock::now(); }
  void end(estimator::LioStep step) override {
    const std::size_t i = index(step);
    current_[i] += std::chrono::duration<double, std::milli>(Clock::now() - start_[i]).count();
    touched_ = true;
  }
  /// Closes the scan in progress (if any step ran): its per-step times join the records.
  void finish_scan() {
    if (!touched_) return;
    double total = 0;
    for (std::size_t i = 0; i < current_.size(); ++i) {
      per_step_[i].push_back(current_[i]);
      total += current_[i];
      current_[i] = 0;
    }
    totals_.push_back(total);
    touched_ = false;
  }
  const std::vector<double>& step(std::size_t i) const { return per_step_[i]; }
  const std::vector<double>& totals() const { return totals_; }

 private:
  static std::size_t index(estimator::LioStep s) { return static_cast<std::size_t>(s); }
  std::array<Clock::time_point, 6> start_{};
  std::array<double, 6> current_{};
  std::array<std::vector<double>, 6> per_step_;
  std::vector<double> totals_;
  bool touched_ = false;
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5)];
}

/// One pass of the simulated run through a fresh estimator; `splitter` (optional) for the match.
struct LioRun {
  StepTimer timer;
  std::vector<NavState> states;
  double points = 0;
};

void run_estimator(const config::PosedConfig& config, const sim::LidarImuRun& run,
                   WorkSplitter* splitter, LioRun& out) {
  estimator::LioEstimator lio(pipeline::lio_config(config));
  lio.set_probe(&out.timer);
  lio.set_splitter(splitter);
  PayloadPool pool(4,
                   drivers::velodyne::max_points_per_scan(config.lidar.rpm) * sizeof(LidarPoint));
  std::size_t next_scan = 0;
  for (const ImuSample& imu : run.imu) {
    while (next_scan < run.scans.size() && run.scans[next_scan].end < imu.stamp) {
      const sim::DecodedScan& s = run.scans[next_scan++];
      LidarScan scan;
      scan.start_stamp = s.start;
      scan.end_stamp = s.end;
      scan.points = pool.acquire();
      std::copy(s.points.begin(), s.points.end(), scan.points.as<LidarPoint>().begin());
      scan.point_count = static_cast<std::uint32_t>(s.points.size());
      out.points += static_cast<double>(s.points.size());
      lio.add_scan(std::move(scan), out.states);
      out.timer.finish_scan();
    }
    lio.add_imu(imu, out.states);  // releases the scan the IMU now covers
    out.timer.finish_scan();
  }
}

/// ATE RMSE of the optimised poses after the best rigid alignment [m].
double ate_rmse(const std::vector<NavState>& states, const sim::LidarImuRun& run) {
  std::vector<Eigen::Vector3d> p_est, p_gt;
  for (const NavState& s : states) {
    if (!s.optimised) continue;
    p_est.push_back(s.p_map_base_m);
    p_gt.push_back(run.T_map_base(s.stamp).translation());
  }
  const eval::Sim3 aligned = eval::umeyama(p_est, p_gt, false);
  double sq = 0;
  for (std::size_t i = 0; i < p_est.size(); ++i) {
    sq += (aligned.apply(p_est[i]) - p_gt[i]).squaredNorm();
  }
  return std::sqrt(sq / static_cast<double>(p_est.size()));
}

bool same_poses(const std::vector<NavState>& a, const std::vector<NavState>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].stamp != b[i].stamp || a[i].p_map_base_m != b[i].p_map_base_m ||
        a[i].q_map_base.coeffs() != b[i].q_map_base.coeffs()) {
      return false;
    }
  }
  return true;
}

}  // namespace

int bench_lio() {
  const config::PosedConfig config = config::default_config();  // the M2DGR rig
  sim::SimOptions options;
  options.scenario = "street_night";
  options.duration_s = 40.0;
  options.seed = 3;
  std::fprintf(stderr, "posectl bench lio: simulating %s for %.0f s (lidar + IMU)...\n",
               options.scenario.c_str(), options.duration_s);
  sim::LidarImuRun run;
  std::string error;
  if (!sim::simulate_lidar_imu(sim::rig_from_config(config), options, run, error)) {
    std::fprintf(stderr, "posectl bench lio: %s\n", error.c_str());
    return 1;
  }
  std::fprintf(stderr, "posectl bench lio: %zu scans through the estimator...\n", run.scans.size());
  LioRun alone;
  run_estimator(config, run, nullptr, alone);

  const std::vector<double>& totals = alone.timer.totals();
  report("lio", "scans", static_cast<double>(totals.size()), "count");
  report("lio", "points_per_scan_mean",
         alone.points / std::max<double>(1.0, static_cast<double>(run.scans.size())), "points");
  for (std::size_t i = 0; i < estimator::kLioStepNames.size(); ++i) {
    const std::string name(estimator::kLioStepNames[i]);
    report("lio", name + "_median", percentile(alone.timer.step(i), 0.5), "ms");
    report("lio", name + "_p99", percentile(alone.timer.step(i), 0.99), "ms");
  }
  report("lio", "per_scan_median", percentile(totals, 0.5), "ms");
  report("lio", "per_scan_p99", percentile(totals, 0.99), "ms");
  report("lio", "per_scan_max", percentile(totals, 1.0), "ms");
  report("lio", "ate_rmse", ate_rmse(alone.states, run), "m");

  std::fprintf(stderr,
               "posectl bench lio: again with a helper thread for the lidar front end...\n");
  LioRun helped;
  {
    pipeline::LidarHelper helper(config::ThreadSection{}, 1);
    run_estimator(config, run, &helper, helped);
    const pipeline::LidarHelperCounters c = helper.counters();
    report("lio", "helper_share_of_parts",
           c.parts > 0 ? static_cast<double>(c.helper_parts) / static_cast<double>(c.parts) : 0,
           "ratio");
  }
  for (const estimator::LioStep step :
       {estimator::LioStep::kDeskew, estimator::LioStep::kFeatures, estimator::LioStep::kMatch}) {
    const auto i = static_cast<std::size_t>(step);
    const std::string name(estimator::kLioStepNames[i]);
    report("lio", "helper_" + name + "_median", percentile(helped.timer.step(i), 0.5), "ms");
    report("lio", "helper_" + name + "_p99", percentile(helped.timer.step(i), 0.99), "ms");
  }
  report("lio", "helper_per_scan_median", percentile(helped.timer.totals(), 0.5), "ms");
  report("lio", "helper_per_scan_p99", percentile(helped.timer.totals(), 0.99), "ms");
  report("lio", "helper_ate_rmse", ate_rmse(helped.states, run), "m");
  report("lio", "helper_poses_identical", same_poses(alone.states, helped.states) ? 1 : 0, "bool");
  return 0;
}

}  // namespace posed::posectl
