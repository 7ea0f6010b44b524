#include "daemon/pipeline/publisher_stage.hpp"

#include "daemon/pipeline/mapping_stage.hpp"
#include "daemon/pipeline/thread_policy.hpp"
#include "drivers/common/host_clock.hpp"

namespace posed::pipeline {

PublisherStage::PublisherStage(const config::PosedConfig& config, SpscQueue<StateItem>& states,
                               Wakeup& ready, Heartbeat& heartbeat, StateCallback on_state,
                               std::function<void(const PipelineStatus&)> on_status,
                               std::function<PipelineStatus()> snapshot, MappingStage* mapping)
    : config_(config),
      states_(states),
      ready_(ready),
      heartbeat_(heartbeat),
      on_state_(std::move(on_state)),
      mapping_(mapping),
      on_status_(std::move(on_status)),
      snapshot_(std::move(snapshot)) {}

void PublisherStage::publish_status() {
  PipelineStatus st = snapshot_();
  // Rates from the difference to the previous snapshot, which only this thread keeps.
  if (previous_.stamp.ns != 0 && st.stamp > previous_.stamp) {
    const double dt = (st.stamp - previous_.stamp).seconds();
    for (std::size_t i = 0; i < st.streams.size() && i < previous_.streams.size(); ++i) {
      st.streams[i].rate_hz =
          static_cast<double>(st.streams[i].decoded - previous_.streams[i].decoded) / dt;
    }
  }
  previous_ = st;
  if (on_status_) on_status_(st);
}

void PublisherStage::run() {
  apply_thread_policy("posed-publish", config_.threads.publisher);
  const Duration status_period = Duration::from_seconds(1.0 / config_.publish.status_rate_hz);
  HostTime next_status = drivers::host_now() + status_period;
  bool done = false;
  while (!done) {
    heartbeat_.beat();
    ready_.wait_for(kStageWaitTimeout);
    StateItem item;
    while (states_.try_pop(item)) {
      if (item.end_of_stream) {
        done = true;
        break;
      }
      if (!on_state_) continue;
      if (mapping_ == nullptr) {
        on_state_(item.state, Eigen::Isometry3d::Identity());
        continue;
      }
      // In data order the correction waits for the mapping stage to reach the state; the
      // watchdog must see this thread alive meanwhile.
      while (!mapping_->wait_until_taken(item.scans_before, kStageWaitTimeout)) {
        heartbeat_.beat();
      }
      on_state_(item.state, mapping_->T_map_odom(item.scans_before));
    }
    const HostTime now = drivers::host_now();
    if (done || now >= next_status) {
      next_status = now + status_period;
      publish_status();
    }
  }
}

}  // namespace posed::pipeline
