#include "core/fusion/camera_aided_core.hpp"

namespace posed::fusion {

CameraAidedCore::CameraAidedCore(std::unique_ptr<FusionCore> inner,
                                 const CameraFrontEndConfig& cameras)
    : inner_(std::move(inner)), cameras_(cameras) {
  description_ = std::string(inner_->description()) + " with the " +
                 std::string(vision::to_string(cameras.frontend.mode)) +
                 " camera front end (features, quality and lidar depth; not yet in the estimate)";
}

void CameraAidedCore::feed_states(const std::vector<NavState>& states, std::size_t first) {
  for (std::size_t i = first; i < states.size(); ++i) cameras_.add_state(states[i]);
  cameras_.process(inner_->figures().gyro_bias_radps);
}

void CameraAidedCore::add_imu(const ImuSample& sample, std::vector<NavState>& states) {
  const std::size_t first = states.size();
  inner_->add_imu(sample, states);
  cameras_.add_imu(sample);
  feed_states(states, first);
}

void CameraAidedCore::add_scan(LidarScan scan, std::vector<NavState>& states) {
  const std::size_t first = states.size();
  inner_->add_scan(std::move(scan), states);
  MatchedScan matched;
  if (inner_->latest_matched_scan(matched)) cameras_.add_scan(matched);
  feed_states(states, first);
}

void CameraAidedCore::add_image(CameraStream stream, Image image, std::vector<NavState>& states) {
  cameras_.add_image(stream, std::move(image));
  feed_states(states, states.size());
}

FusionFigures CameraAidedCore::figures() const {
  FusionFigures f = inner_->figures();
  f.camera = cameras_.figures();
  return f;
}

}  // namespace posed::fusion
