#pragma once
// A fusion core with cameras: the camera front end runs beside the lidar-inertial (or IMU-only)
// core it wraps, fed by that core's states and matched scans. With a lidar-inertial core and
// camera factors configured, the front end's frames also go to the camera back end
// (CameraFactors), which hands the window a between factor per camera stream and state: the
// cameras are then in the estimate. Without a lidar (an IMU-only core) the front end only reports
// (a visual-inertial window without scan states is not built).
//
// Where the front end runs: every call into it is a task on a TaskLane, in measurement order.
// With the cameras in the window the lane may be a thread of its own (the daemon's CameraLane):
// the frames between scans k-1 and k need only state k-1, so they are processed while the lidar
// front end deskews and matches scan k, and the window step for state k waits for them (the
// lane is drained before the window asks for the camera motions). The scan match asks whether a
// camera is active before that join, so it uses the answer as of the previous window step, on
// any lane: the estimate is the same whether the lane is a thread or the caller.

#include <memory>
#include <string>
#include <vector>

#include "core/estimator/fusion_core.hpp"
#include "core/estimator/lio_estimator.hpp"
#include "core/fusion/camera_factors.hpp"
#include "core/fusion/camera_front_end.hpp"
#include "core/fusion/task_lane.hpp"

namespace posed::fusion {

class CameraAidedCore final : public FusionCore,
                              private FrontendObserver,
                              private estimator::WindowAiding {
 public:
  /// `window_owner`: the lidar-inertial core inside `inner` (the same object) whose window the
  /// camera factors join, or null; `factors` says which streams enter it (none: front end only).
  /// `lane`: where the front end runs when the cameras are in the window (it must outlive this
  /// core); null, or cameras not in the window: on the caller's thread.
  CameraAidedCore(std::unique_ptr<FusionCore> inner, const CameraFrontEndConfig& cameras,
                  const CameraFactorsConfig& factors, estimator::LioEstimator* window_owner,
                  TaskLane* lane = nullptr);
  ~CameraAidedCore() override;

  void add_imu(const ImuSample& sample, std::vector<NavState>& states) override;
  void add_scan(LidarScan scan, std::vector<NavState>& states) override;
  void add_image(CameraStream stream, Image image, std::vector<NavState>& states) override;
  EstimatorMode mode() const override { return inner_->mode(); }
  std::string_view description() const override { return description_; }
  /// With the front end on a lane of its own, the camera figures as of the last window step
  /// (or flush()).
  FusionFigures figures() const override;
  void flush() override { sync(); }
  void export_map(MapExport& out) const override { inner_->export_map(out); }
  void local_map(std::vector<Eigen::Vector3f>& points_map_m) const override {
    inner_->local_map(points_map_m);
  }
  bool latest_matched_scan(MatchedScan& out) const override {
    return inner_->latest_matched_scan(out);
  }

  /// The front end itself: before the first measurement, or after flush().
  CameraFrontEnd& cameras() { return cameras_; }
  const CameraFrontEnd& cameras() const { return cameras_; }
  /// Whether the front end runs on a lane of its own (not the caller's thread).
  bool threaded() const { return lane_ != nullptr; }
  /// The camera back end, or null when the cameras do not enter the estimate.
  const CameraFactors* camera_factors() const { return factors_.get(); }

 private:
  void on_frame(const vision::FrontendFrame& frame,
                const vision::VisualFrontend& frontend) override;
  // The window's view of the camera back end (CameraFactors), joined with the lane first.
  void relative_motions(const estimator::SlidingWindow& window, const imu::ImuState& next,
                        std::vector<estimator::RelativeMotion>& out) override;
  void set_lidar_state(const LidarState& state) override;
  bool active() const override { return active_; }
  std::uint8_t add_factors(estimator::SlidingWindow& window) override;
  void after_solve(const estimator::SlidingWindow& window) override;

  /// States appended from `first` on go to the front end (camera poses for the depth cloud).
  void feed_states(const std::vector<NavState>& states, std::size_t first);
  /// Runs `task` on the lane, or here when there is none.
  template <class Task>
  void run(Task&& task);
  /// Waits for the lane, then takes what the scan match and figures() read.
  void sync();

  std::unique_ptr<FusionCore> inner_;
  CameraFrontEnd cameras_;
  std::unique_ptr<CameraFactors> factors_;
  TaskLane* lane_ = nullptr;
  /// the back end's active() as of the last sync (what the next scan match sees)
  bool active_ = false;
  CameraFigures camera_figures_;                         // as of the last sync, with a lane
  std::array<VisualStreamFigures, 3> visual_figures_{};  // the same
  std::string description_;
};

}  // namespace posed::fusion
