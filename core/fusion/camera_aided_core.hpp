#pragma once
// A fusion core with cameras: the lidar-inertial (or IMU-only) core it wraps keeps producing
// the states, and the camera front end runs beside it on the same thread, fed by the wrapped
// core's states and matched scans. Its features and per-stream confidence are the camera
// figures of the status; a visual back end that turns them into factors of the window is the
// next step (the wrapped core does not use them yet).

#include <memory>
#include <vector>

#include "core/estimator/fusion_core.hpp"
#include "core/fusion/camera_front_end.hpp"

namespace posed::fusion {

class CameraAidedCore final : public FusionCore {
 public:
  CameraAidedCore(std::unique_ptr<FusionCore> inner, const CameraFrontEndConfig& cameras);

  void add_imu(const ImuSample& sample, std::vector<NavState>& states) override;
  void add_scan(LidarScan scan, std::vector<NavState>& states) override;
  void add_image(CameraStream stream, Image image, std::vector<NavState>& states) override;
  EstimatorMode mode() const override { return inner_->mode(); }
  std::string_view description() const override { return description_; }
  FusionFigures figures() const override;
  void export_map(MapExport& out) const override { inner_->export_map(out); }
  bool latest_matched_scan(MatchedScan& out) const override {
    return inner_->latest_matched_scan(out);
  }

  CameraFrontEnd& cameras() { return cameras_; }
  const CameraFrontEnd& cameras() const { return cameras_; }

 private:
  /// States appended from `first` on go to the front end; then it processes what is ready.
  void feed_states(const std::vector<NavState>& states, std::size_t first);

  std::unique_ptr<FusionCore> inner_;
  CameraFrontEnd cameras_;
  std::string description_;
};

}  // namespace posed::fusion
