#pragma once
// rt/posed/cloud and rt/posed/map off the fusion thread. After each scan the fusion stage shows
// the core to after_scan(), which builds the PointCloud2 of the newest matched scan (only when
// someone reads rt/posed/cloud, at most publish.cloud_max_rate_hz) and, at publish.map_rate_hz,
// of the local map, and hands them to this object's thread through one-slot mailboxes; the
// thread writes them to DDS. A slow reader or a big cloud delays only that thread: odometry and
// poses never wait for it, and when it falls behind the newer cloud replaces the one not yet
// written (counted), so memory stays at three clouds of each kind.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

#include "daemon/config/posed_config.hpp"
#include "daemon/dds/messages.hpp"
#include "daemon/pipeline/scan_observer.hpp"

namespace posed {

namespace dds {
class Publisher;
}

struct CloudOutputCounters {
  std::uint64_t clouds = 0;            ///< rt/posed/cloud messages written [count]
  std::uint64_t clouds_replaced = 0;   ///< built but replaced by a newer one before the write
  std::uint64_t maps = 0;              ///< rt/posed/map messages written [count]
  std::uint64_t failed = 0;            ///< writes Cyclone rejected [count]
  std::uint64_t last_cloud_bytes = 0;  ///< point data of the last cloud [B]
  std::uint64_t last_map_bytes = 0;    ///< point data of the last map [B]
};

class CloudOutput final : public pipeline::ScanObserver {
 public:
  /// Starts the writer thread. `publisher` must outlive this object.
  CloudOutput(const config::PosedConfig& config, dds::Publisher& publisher, HostToWall to_wall);
  ~CloudOutput() override;
  CloudOutput(const CloudOutput&) = delete;
  CloudOutput& operator=(const CloudOutput&) = delete;

  /// On the fusion thread, after every scan.
  void after_scan(const FusionCore& core) override;
  /// Writes what is still waiting and ends the thread. Idempotent.
  void stop();
  CloudOutputCounters counters() const;

 private:
  /// One kind of message through a one-slot mailbox: `building` is the fusion thread's,
  /// `sending` the writer's, `pending` changes hands under the mutex. No allocation once each
  /// has held a message of full size.
  struct Mailbox {
    dds::CloudMessage building, pending, sending;
    bool full = false;
  };
  void run();
  /// Fusion thread: swaps `box.building` into `box.pending`; true when it replaced one.
  bool post(Mailbox& box);

  const config::PosedConfig& config_;
  dds::Publisher& publisher_;
  HostToWall to_wall_;
  bool cloud_on_;
  bool map_on_;
  std::uint64_t last_scan_index_ = 0;
  HostTime next_cloud_stamp_;
  HostTime next_map_stamp_;
  std::vector<Eigen::Vector3f> map_points_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  Mailbox cloud_;
  Mailbox map_;
  bool stopping_ = false;
  CloudOutputCounters counters_;
  std::thread thread_;
};

}  // namespace posed
