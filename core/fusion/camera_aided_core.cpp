#include "core/fusion/camera_aided_core.hpp"

#include <algorithm>
#include <memory>
#include <utility>

namespace posed::fusion {

CameraAidedCore::CameraAidedCore(std::unique_ptr<FusionCore> inner,
                                 const CameraFrontEndConfig& cameras,
                                 const CameraFactorsConfig& factors,
                                 estimator::LioEstimator* window_owner, TaskLane* lane)
    : inner_(std::move(inner)), cameras_(cameras) {
  const bool any_stream =
      std::any_of(factors.streams.begin(), factors.streams.end(), [](bool on) { return on; });
  std::string streams;
  if (window_owner != nullptr && any_stream) {
    factors_ = std::make_unique<CameraFactors>(factors);
    window_owner->set_aiding(this);
    cameras_.set_back_end(this);
    active_ = factors_->active();
    // Only the window step joins the lane: without camera factors nothing would wait for it.
    lane_ = lane;
    for (std::size_t i = 0; i < 3; ++i) {
      if (!factors.streams[i]) continue;
      if (!streams.empty()) streams += " and ";
      streams += vision::to_string(static_cast<vision::FrontendMode>(i));
    }
  }
  description_ = std::string(inner_->description()) + " with the " +
                 std::string(vision::to_string(cameras.frontend.mode)) + " camera front end";
  if (lane_ != nullptr) description_ += " on a thread of its own";
  if (!factors_) {
    description_ += " (features, quality and lidar depth; not in the estimate)";
  } else if (factors.coupling != CameraCoupling::kBetween) {
    description_ += " (" + streams + " landmarks in the window, weighed by image quality)";
  } else {
    description_ += " (" + streams + " motion in the window, weighed by image quality)";
  }
}

CameraAidedCore::~CameraAidedCore() {
  if (lane_ != nullptr) lane_->drain();  // its tasks point into this core
}

template <class Task>
void CameraAidedCore::run(Task&& task) {
  if (lane_ == nullptr) {
    task();
  } else {
    lane_->post(std::forward<Task>(task));
  }
}

void CameraAidedCore::sync() {
  if (lane_ != nullptr) {
    lane_->drain();
    camera_figures_ = cameras_.figures();
    if (factors_) visual_figures_ = factors_->figures();
  }
  if (factors_) active_ = factors_->active();
}

void CameraAidedCore::set_lidar_state(const LidarState& state) {
  sync();
  factors_->set_lidar_state(state);
}

void CameraAidedCore::relative_motions(const estimator::SlidingWindow& window,
                                       const imu::ImuState& next,
                                       std::vector<estimator::RelativeMotion>& out) {
  sync();
  factors_->relative_motions(window, next, out);
}

std::uint8_t CameraAidedCore::add_factors(estimator::SlidingWindow& window) {
  // The lane is idle: relative_motions joined it for this state.
  return factors_->add_factors(window);
}

void CameraAidedCore::after_solve(const estimator::SlidingWindow& window) {
  // The lane is idle: nothing was posted since the join in relative_motions, and active_ stays
  // as that join took it (after_solve weighs streams; it does not open or close them).
  factors_->after_solve(window);
}

void CameraAidedCore::on_frame(const vision::FrontendFrame& frame,
                               const vision::VisualFrontend& frontend) {
  (void)frontend;
  factors_->add_frame(frame.mode, frame);
}

void CameraAidedCore::feed_states(const std::vector<NavState>& states, std::size_t first) {
  for (std::size_t i = first; i < states.size(); ++i) {
    run([this, state = states[i]] { cameras_.add_state(state); });
  }
}

void CameraAidedCore::add_imu(const ImuSample& sample, std::vector<NavState>& states) {
  // The cameras first: the frames this sample covers reach the back end before a scan it
  // releases, so the new state finds the last frame at or before its stamp.
  run([this, sample, bias = inner_->figures().gyro_bias_radps] {
    cameras_.add_imu(sample);
    cameras_.process(bias);
  });
  const std::size_t first = states.size();
  inner_->add_imu(sample, states);
  feed_states(states, first);
}

void CameraAidedCore::add_scan(LidarScan scan, std::vector<NavState>& states) {
  const std::size_t first = states.size();
  inner_->add_scan(std::move(scan), states);
  MatchedScan matched;
  if (inner_->latest_matched_scan(matched)) {
    if (lane_ == nullptr) {
      cameras_.add_scan(matched);
    } else {
      // The points are a view into the core's last scan, which the next scan overwrites: the
      // lane gets a copy.
      auto copy = std::make_shared<std::vector<lidar::ScanPoint>>(matched.points_lidar.begin(),
                                                                  matched.points_lidar.end());
      lane_->post([this, matched, copy] {
        MatchedScan own = matched;
        own.points_lidar = *copy;
        cameras_.add_scan(own);
      });
    }
  }
  feed_states(states, first);
}

void CameraAidedCore::add_image(CameraStream stream, Image image, std::vector<NavState>& states) {
  (void)states;
  const Eigen::Vector3d bias = inner_->figures().gyro_bias_radps;
  if (lane_ == nullptr) {
    cameras_.add_image(stream, std::move(image));
    cameras_.process(bias);
    return;
  }
  // A task must be copyable: the image (its pool buffer) travels in a shared holder.
  auto held = std::make_shared<Image>(std::move(image));
  lane_->post([this, stream, held, bias] {
    cameras_.add_image(stream, std::move(*held));
    cameras_.process(bias);
  });
}

FusionFigures CameraAidedCore::figures() const {
  FusionFigures f = inner_->figures();
  if (lane_ == nullptr) {
    f.camera = cameras_.figures();
    if (factors_) f.visual = factors_->figures();
  } else {
    f.camera = camera_figures_;
    f.visual = visual_figures_;
  }
  return f;
}

}  // namespace posed::fusion
