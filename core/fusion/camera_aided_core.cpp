#include "core/fusion/camera_aided_core.hpp"

#include <algorithm>

namespace posed::fusion {

CameraAidedCore::CameraAidedCore(std::unique_ptr<FusionCore> inner,
                                 const CameraFrontEndConfig& cameras,
                                 const CameraFactorsConfig& factors,
                                 estimator::LioEstimator* window_owner)
    : inner_(std::move(inner)), cameras_(cameras) {
  const bool any_stream =
      std::any_of(factors.streams.begin(), factors.streams.end(), [](bool on) { return on; });
  std::string streams;
  if (window_owner != nullptr && any_stream) {
    factors_ = std::make_unique<CameraFactors>(factors);
    window_owner->set_aiding(factors_.get());
    cameras_.set_back_end(this);
    for (std::size_t i = 0; i < 3; ++i) {
      if (!factors.streams[i]) continue;
      if (!streams.empty()) streams += " and ";
      streams += vision::to_string(static_cast<vision::FrontendMode>(i));
    }
  }
  description_ = std::string(inner_->description()) + " with the " +
                 std::string(vision::to_string(cameras.frontend.mode)) + " camera front end";
  description_ += factors_ ? " (" + streams + " motion in the window, weighed by image quality)"
                           : " (features, quality and lidar depth; not in the estimate)";
}

void CameraAidedCore::on_frame(const vision::FrontendFrame& frame,
                               const vision::VisualFrontend& frontend) {
  (void)frontend;
  factors_->add_frame(frame.mode, frame);
}

void CameraAidedCore::feed_states(const std::vector<NavState>& states, std::size_t first) {
  for (std::size_t i = first; i < states.size(); ++i) cameras_.add_state(states[i]);
}

void CameraAidedCore::add_imu(const ImuSample& sample, std::vector<NavState>& states) {
  // The cameras first: the frames this sample covers reach the back end before a scan it
  // releases, so the new state finds the last frame at or before its stamp.
  cameras_.add_imu(sample);
  cameras_.process(inner_->figures().gyro_bias_radps);
  const std::size_t first = states.size();
  inner_->add_imu(sample, states);
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
  (void)states;
  cameras_.add_image(stream, std::move(image));
  cameras_.process(inner_->figures().gyro_bias_radps);
}

FusionFigures CameraAidedCore::figures() const {
  FusionFigures f = inner_->figures();
  f.camera = cameras_.figures();
  if (factors_) f.visual = factors_->figures();
  return f;
}

}  // namespace posed::fusion
