#pragma once
// A fusion core with cameras: the camera front end runs beside the lidar-inertial (or IMU-only)
// core it wraps, on the same thread, fed by that core's states and matched scans. With a
// lidar-inertial core and camera factors configured, the front end's frames also go to the
// camera back end (CameraFactors), which hands the window a between factor per camera stream and
// state: the cameras are then in the estimate. Without a lidar (an IMU-only core) the front end
// only reports (a visual-inertial window without scan states is not built).

#include <memory>
#include <string>
#include <vector>

#include "core/estimator/fusion_core.hpp"
#include "core/estimator/lio_estimator.hpp"
#include "core/fusion/camera_factors.hpp"
#include "core/fusion/camera_front_end.hpp"

namespace posed::fusion {

class CameraAidedCore final : public FusionCore, private FrontendObserver {
 public:
  /// `window_owner`: the lidar-inertial core inside `inner` (the same object) whose window the
  /// camera factors join, or null; `factors` says which streams enter it (none: front end only).
  CameraAidedCore(std::unique_ptr<FusionCore> inner, const CameraFrontEndConfig& cameras,
                  const CameraFactorsConfig& factors, estimator::LioEstimator* window_owner);

  void add_imu(const ImuSample& sample, std::vector<NavState>& states) override;
  void add_scan(LidarScan scan, std::vector<NavState>& states) override;
  void add_image(CameraStream stream, Image image, std::vector<NavState>& states) override;
  EstimatorMode mode() const override { return inner_->mode(); }
  std::string_view description() const override { return description_; }
  FusionFigures figures() const override;
  void export_map(MapExport& out) const override { inner_->export_map(out); }
  void local_map(std::vector<Eigen::Vector3f>& points_map_m) const override {
    inner_->local_map(points_map_m);
  }
  bool latest_matched_scan(MatchedScan& out) const override {
    return inner_->latest_matched_scan(out);
  }

  CameraFrontEnd& cameras() { return cameras_; }
  const CameraFrontEnd& cameras() const { return cameras_; }
  /// The camera back end, or null when the cameras do not enter the estimate.
  const CameraFactors* camera_factors() const { return factors_.get(); }

 private:
  void on_frame(const vision::FrontendFrame& frame,
                const vision::VisualFrontend& frontend) override;
  /// States appended from `first` on go to the front end (camera poses for the depth cloud).
  void feed_states(const std::vector<NavState>& states, std::size_t first);

  std::unique_ptr<FusionCore> inner_;
  CameraFrontEnd cameras_;
  std::unique_ptr<CameraFactors> factors_;
  std::string description_;
};

}  // namespace posed::fusion
