#include "daemon/pipeline/odometry_path.hpp"

namespace posed::pipeline {

OdometryPath::OdometryPath(const estimator::OdometryPropagatorConfig& config,
                           SpscQueue<AnchorItem>& anchors,
                           std::function<void(const NavState&)> on_odom)
    : propagator_(config), anchors_(anchors), on_odom_(std::move(on_odom)) {}

void OdometryPath::on_imu(const ImuSample& sample, HostTime received) {
  std::lock_guard lock(mutex_);
  if (have_last_ && sample.stamp <= last_stamp_) return;
  have_last_ = true;
  last_stamp_ = sample.stamp;
  AnchorItem item;
  while (anchors_.try_pop(item)) propagator_.set_anchor(item.state);
  NavState odom;
  if (!propagator_.add_imu(sample, odom)) return;
  odom.received = received;
  if (on_odom_) on_odom_(odom);
}

}  // namespace posed::pipeline
