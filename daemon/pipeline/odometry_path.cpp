#include "daemon/pipeline/odometry_path.hpp"

namespace posed::pipeline {

OdometryPath::OdometryPath(const estimator::OdometryPropagatorConfig& config,
                           SpscQueue<AnchorItem>& anchors, BackEndProgress& progress,
                           bool deterministic, std::function<void(const NavState&)> on_odom)
    : propagator_(config),
      anchors_(anchors),
      progress_(progress),
      deterministic_(deterministic),
      on_odom_(std::move(on_odom)) {}

void OdometryPath::take_anchors(HostTime sample_stamp) {
  for (;;) {
    if (!next_) {
      AnchorItem item;
      if (!anchors_.try_pop(item)) return;
      next_ = item;
    }
    // Deterministic: an anchor released by this very sample (or later) waits for the next one,
    // since whether it has been queued yet depends on the scheduling.
    if (deterministic_ && !(next_->released_at < sample_stamp)) return;
    propagator_.set_anchor(next_->state);
    next_.reset();
  }
}

void OdometryPath::on_imu(const ImuSample& sample, HostTime received, Heartbeat& heartbeat) {
  if (deterministic_) {
    while (!progress_.reached(sample.stamp)) {
      progress_.wait_for(kStageWaitTimeout);
      heartbeat.beat();
    }
  }
  take_anchors(sample.stamp);
  NavState odom;
  if (!propagator_.add_imu(sample, odom)) return;
  odom.received = received;
  if (on_odom_) on_odom_(odom);
}

}  // namespace posed::pipeline
