#include "daemon/cloud_output.hpp"

#include <utility>

#include "daemon/cloud_messages.hpp"
#include "daemon/dds/publisher.hpp"

namespace posed {

CloudOutput::CloudOutput(const config::PosedConfig& config, dds::Publisher& publisher,
                         HostToWall to_wall)
    : config_(config),
      publisher_(publisher),
      to_wall_(to_wall),
      cloud_on_(config.publish.cloud && publisher.has_writer(dds::Topic::kCloud)),
      map_on_(config.publish.map && publisher.has_writer(dds::Topic::kMap)) {
  thread_ = std::thread([this] { run(); });
}

CloudOutput::~CloudOutput() { stop(); }

void CloudOutput::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
}

bool CloudOutput::post(Mailbox& box) {
  bool replaced = false;
  {
    std::lock_guard lock(mutex_);
    replaced = box.full;
    std::swap(box.building, box.pending);
    box.full = true;
  }
  wake_.notify_one();
  return replaced;
}

void CloudOutput::after_scan(const FusionCore& core) {
  if (!cloud_on_ && !map_on_) return;
  MatchedScan scan;
  if (!core.latest_matched_scan(scan) || scan.index == last_scan_index_) return;
  last_scan_index_ = scan.index;
  const WallTime stamp = to_wall_(scan.stamp);
  // Rate limits run on the data's clock, so a max-speed replay thins the same scans as live.
  if (cloud_on_ && scan.stamp >= next_cloud_stamp_ && publisher_.wanted(dds::Topic::kCloud)) {
    if (config_.publish.cloud_max_rate_hz > 0) {
      next_cloud_stamp_ =
          scan.stamp + Duration::from_seconds(1.0 / config_.publish.cloud_max_rate_hz);
    }
    scan_cloud(scan, stamp, config_.dds.lidar_frame, cloud_.building);
    if (post(cloud_)) {
      std::lock_guard lock(mutex_);
      ++counters_.clouds_replaced;
    }
  }
  // The map is transient-local: written whether or not anyone reads it now, for who joins later.
  if (map_on_ && scan.stamp >= next_map_stamp_) {
    next_map_stamp_ = scan.stamp + Duration::from_seconds(1.0 / config_.publish.map_rate_hz);
    core.local_map(map_points_);
    // The estimator's local map is in its own frame: odom (loops move map -> odom only).
    map_cloud(map_points_, stamp, config_.dds.odom_frame, map_.building);
    post(map_);
  }
}

void CloudOutput::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stopping_ || cloud_.full || map_.full; });
    const bool send_cloud = cloud_.full, send_map = map_.full;
    if (!send_cloud && !send_map && stopping_) return;
    if (send_cloud) std::swap(cloud_.pending, cloud_.sending);
    if (send_map) std::swap(map_.pending, map_.sending);
    cloud_.full = map_.full = false;
    lock.unlock();
    // Outside the lock: the fusion thread posts the next scan while this one is written.
    const bool cloud_ok = !send_cloud || publisher_.publish_cloud(cloud_.sending);
    const bool map_ok = !send_map || publisher_.publish_map(map_.sending);
    lock.lock();
    if (send_cloud && cloud_ok) {
      ++counters_.clouds;
      counters_.last_cloud_bytes = cloud_.sending.data.size();
    }
    if (send_map && map_ok) {
      ++counters_.maps;
      counters_.last_map_bytes = map_.sending.data.size();
    }
    counters_.failed += (cloud_ok ? 0 : 1) + (map_ok ? 0 : 1);
  }
}

CloudOutputCounters CloudOutput::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

}  // namespace posed
