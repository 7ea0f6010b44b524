#include "daemon/pipeline/fusion_stage.hpp"

#include <algorithm>
#include <optional>

#include "daemon/pipeline/thread_policy.hpp"
#include "drivers/common/log.hpp"

namespace posed::pipeline {

namespace {
HostTime stamp_of(const ImuItem& item) { return item.sample.stamp; }
HostTime stamp_of(const ScanItem& item) { return item.scan.end_stamp; }
HostTime stamp_of(const ImageItem& item) { return item.image.stamp; }
}  // namespace

// One input stream with a one-item look-ahead, so the merge can compare heads without popping.
template <class Item>
class FusionStage::Lane {
 public:
  explicit Lane(SpscQueue<Item>* queue) : queue_(queue), end_seen_(queue == nullptr) {}
  /// Pops the next item into the head slot when it is empty.
  void refill() {
    if (head_ || end_seen_) return;
    Item item;
    if (!queue_->try_pop(item)) return;
    if (item.end_of_stream) {
      end_seen_ = true;
    } else {
      head_.emplace(std::move(item));
    }
  }
  bool has_head() const { return head_.has_value(); }
  /// stamp order must wait for this lane: it has no head yet but more may come
  bool waiting() const { return !head_ && !end_seen_; }
  /// no head and none to come
  bool ended() const { return end_seen_ && !head_; }
  HostTime head_stamp() const { return stamp_of(*head_); }
  Item take() {
    Item item = std::move(*head_);
    head_.reset();
    return item;
  }

 private:
  SpscQueue<Item>* queue_;
  bool end_seen_;
  std::optional<Item> head_;
};

FusionStage::FusionStage(const config::PosedConfig& config, std::unique_ptr<FusionCore> core,
                         FusionInputs inputs, bool in_stamp_order, SpscQueue<StateItem>& states,
                         Wakeup& inputs_ready, Wakeup& publisher, Heartbeat& heartbeat,
                         FusionCounters& counters, OdometryHandover odometry,
                         std::vector<ScanObserver*> scan_observers)
    : config_(config),
      core_(std::move(core)),
      inputs_(inputs),
      in_stamp_order_(in_stamp_order),
      states_(states),
      inputs_ready_(inputs_ready),
      publisher_(publisher),
      heartbeat_(heartbeat),
      counters_(counters),
      odometry_(odometry),
      scan_observers_(std::move(scan_observers)),
      failover_(Duration::from_seconds(config.realsense_imu.failover_after_s)) {
  // A scan can release a burst of states (the IMU samples it waited for); no allocation later.
  produced_.reserve(4096);
  outgoing_.reserve(4096);
  produced_scans_before_.reserve(4096);
  outgoing_scans_before_.reserve(4096);
}

void FusionStage::tag_new_states() {
  produced_scans_before_.resize(produced_.size(), scans_handed_);
}

void FusionStage::route_states() {
  tag_new_states();
  for (std::size_t i = 0; i < produced_.size(); ++i) {
    NavState& state = produced_[i];
    state.received = newest_received_;
    const bool decoupled = odometry_.anchors != nullptr || odometry_.in_order != nullptr;
    if (state.anchor && odometry_.anchors != nullptr) odometry_.anchors->push(AnchorItem{state});
    if (state.anchor && odometry_.in_order != nullptr) odometry_.in_order->set_anchor(state);
    // With decoupled odometry, the core's own propagation is replaced by the odometry path's.
    if (!decoupled || state.optimised) {
      outgoing_.push_back(state);
      outgoing_scans_before_.push_back(produced_scans_before_[i]);
    }
  }
  counters_.states.fetch_add(produced_.size(), std::memory_order_relaxed);
  produced_.clear();
  produced_scans_before_.clear();
}

void FusionStage::emit_states() {
  route_states();
  if (outgoing_.empty()) return;
  for (std::size_t i = 0; i < outgoing_.size(); ++i) {
    states_.push(StateItem{outgoing_[i], false, outgoing_scans_before_[i]});
  }
  outgoing_.clear();
  outgoing_scans_before_.clear();
  publisher_.signal();
}

template <class Item>
void FusionStage::took(std::size_t stream, const Item& item) {
  static constexpr const char* kNames[] = {"imu",     "lidar",         "visible",
                                           "thermal", "realsense_imu", "depth"};
  const HostTime stamp = stamp_of(item);
  newest_received_ = std::max(newest_received_, item.received);
  newest_stamp_ = std::max(newest_stamp_, stamp);
  if (heard_[stream] && silent_[stream]) {
    silent_[stream] = false;
    POSED_LOG_NOTICE("stream %s: no_data -> ok at %.3f s (silent for %.2f s of data)",
                     kNames[stream], stamp.seconds(), (stamp - stream_stamp_[stream]).seconds());
  }
  stream_stamp_[stream] = heard_[stream] ? std::max(stream_stamp_[stream], stamp) : stamp;
  heard_[stream] = true;
  counters_.newest_stamp_by_stream_ns[stream].store(stream_stamp_[stream].ns,
                                                    std::memory_order_relaxed);
  // Live, the host clock judges silence and bad samples (fill_stream_status()).
  if (!in_stamp_order_) return;
  if (item.bad_before > bad_seen_[stream]) {
    bad_seen_[stream] = item.bad_before;
    bad_rose_[stream] = stamp;
    if (!degraded_[stream]) {
      degraded_[stream] = true;
      counters_.degraded_by_stream[stream].store(true, std::memory_order_relaxed);
      POSED_LOG_WARN("stream %s: ok -> degraded at %.3f s (%llu malformed or dropped so far)",
                     kNames[stream], stamp.seconds(),
                     static_cast<unsigned long long>(item.bad_before));
    }
  }
  for (std::size_t s = 0; s < kStreams; ++s) {
    if (degraded_[s] && newest_stamp_ - bad_rose_[s] > kStreamDegradedFor) {
      degraded_[s] = false;
      counters_.degraded_by_stream[s].store(false, std::memory_order_relaxed);
      POSED_LOG_NOTICE("stream %s: degraded -> ok at %.3f s", kNames[s],
                       (bad_rose_[s] + kStreamDegradedFor).seconds());
    }
    if (!heard_[s] || silent_[s] || newest_stamp_ - stream_stamp_[s] <= kStreamStaleAfter) {
      continue;
    }
    silent_[s] = true;
    POSED_LOG_WARN("stream %s: ok -> no_data at %.3f s (no sample since %.3f s)", kNames[s],
                   (stream_stamp_[s] + kStreamStaleAfter).seconds(), stream_stamp_[s].seconds());
  }
}

void FusionStage::hand_imu(const ImuItem& item) {
  if (odometry_.in_order != nullptr) {
    // From the anchors released before this sample, as the IMU stage would live.
    route_states();
    NavState odom;
    if (odometry_.in_order->add_imu(item.sample, odom)) {
      odom.received = item.received;
      outgoing_.push_back(odom);
      outgoing_scans_before_.push_back(scans_handed_);
    }
  }
  core_->add_imu(item.sample, produced_);
  tag_new_states();
}

void FusionStage::hand_image(Lane<ImageItem>& lane, CameraStream stream) {
  ImageItem item = lane.take();
  took(fusion_stream_index(stream), item);
  core_->add_image(stream, std::move(item.image), produced_);
  tag_new_states();
  counters_.frames_fused[static_cast<std::size_t>(stream)].fetch_add(1, std::memory_order_relaxed);
}

void FusionStage::note_imu_switch() {
  counters_.imu_on_backup.store(failover_.in_use() == ImuInUse::kBackup, std::memory_order_relaxed);
  counters_.imu_failovers.store(failover_.failovers(), std::memory_order_relaxed);
  if (failover_.in_use() == ImuInUse::kBackup) {
    POSED_LOG_WARN(
        "imu: the A9 is silent (newest sample %.3f s): the estimate runs on the D435i's "
        "IMU from %.3f s",
        failover_.newest_primary().seconds(), failover_.switched_at().seconds());
  } else {
    POSED_LOG_NOTICE("imu: back on the A9 at %.3f s (%llu D435i samples used so far)",
                     failover_.switched_at().seconds(),
                     static_cast<unsigned long long>(failover_.backup_used()));
  }
}

void FusionStage::note_reinitialisation() {
  const FusionFigures f = core_->figures();
  if (f.reinitialisations == reinitialisations_logged_) return;
  reinitialisations_logged_ = f.reinitialisations;
  POSED_LOG_WARN("estimator: the window restarted at %.3f s (%llu so far): %s",
                 f.last_reinitialisation_stamp.seconds(),
                 static_cast<unsigned long long>(f.reinitialisations),
                 f.last_reinitialisation_reason);
}

void FusionStage::run() {
  apply_thread_policy("posed-fusion", config_.threads.fusion);
  Lane<ImuItem> imu(inputs_.imu);
  Lane<ScanItem> scans(inputs_.scans);
  Lane<ImageItem> visible(inputs_.visible);
  Lane<ImageItem> thermal(inputs_.thermal);
  Lane<ImuItem> backup_imu(inputs_.backup_imu);
  Lane<ImageItem> depth(inputs_.depth);

  // Which lane goes next: the oldest head; on equal stamps the IMU first (a scan or frame ending
  // exactly at an IMU sample finds it already in the core), then scans, visible, thermal, and
  // the D435i's IMU (used only in a silent A9's place), its depth images. Stamp order waits for
  // every open lane.
  enum class Next { kNone, kImu, kScan, kVisible, kThermal, kBackupImu, kDepth };
  const auto next = [&] {
    imu.refill();
    scans.refill();
    visible.refill();
    thermal.refill();
    backup_imu.refill();
    depth.refill();
    if (in_stamp_order_ && (imu.waiting() || scans.waiting() || visible.waiting() ||
                            thermal.waiting() || backup_imu.waiting() || depth.waiting())) {
      return Next::kNone;
    }
    Next best = Next::kNone;
    HostTime best_stamp;
    const auto consider = [&](const auto& lane, Next which) {
      if (lane.has_head() && (best == Next::kNone || lane.head_stamp() < best_stamp)) {
        best = which;
        best_stamp = lane.head_stamp();
      }
    };
    consider(imu, Next::kImu);
    consider(scans, Next::kScan);
    consider(visible, Next::kVisible);
    consider(thermal, Next::kThermal);
    consider(backup_imu, Next::kBackupImu);
    consider(depth, Next::kDepth);
    return best;
  };
  const auto all_ended = [&] {
    return imu.ended() && scans.ended() && visible.ended() && thermal.ended() &&
           backup_imu.ended() && depth.ended();
  };

  std::uint64_t handed_since_figures = 0;
  while (!all_ended()) {
    heartbeat_.beat();
    bool handed = false;
    for (Next n = next(); n != Next::kNone; n = next()) {
      heartbeat_.beat();  // a backlog can take a while; the watchdog must see the stage alive
      switch (n) {
        case Next::kImu: {
          ImuItem item = imu.take();
          took(0, item);
          // Without a backup IMU every sample is the A9's and in order: nothing to decide.
          const bool use =
              inputs_.backup_imu == nullptr || failover_.take_primary(item.sample.stamp);
          if (failover_.switched()) note_imu_switch();
          if (use) hand_imu(item);
          break;
        }
        case Next::kBackupImu: {
          ImuItem item = backup_imu.take();
          took(4, item);
          if (failover_.take_backup(item.sample.stamp)) {
            if (failover_.switched()) note_imu_switch();
            counters_.imu_backup_used.store(failover_.backup_used(), std::memory_order_relaxed);
            hand_imu(item);
          }
          break;
        }
        case Next::kScan: {
          ScanItem item = scans.take();
          took(1, item);
          core_->add_scan(std::move(item.scan), produced_);
          note_reinitialisation();
          ++scans_handed_;
          tag_new_states();
          counters_.scans_fused.fetch_add(1, std::memory_order_relaxed);
          for (ScanObserver* observer : scan_observers_) observer->after_scan(*core_);
          break;
        }
        case Next::kVisible:
          hand_image(visible, CameraStream::kVisible);
          break;
        case Next::kThermal:
          hand_image(thermal, CameraStream::kThermal);
          break;
        case Next::kDepth:
          hand_image(depth, CameraStream::kDepth);
          break;
        case Next::kNone:
          break;
      }
      counters_.mode.store(core_->mode(), std::memory_order_relaxed);
      counters_.newest_stamp_ns.store(newest_stamp_.ns, std::memory_order_relaxed);
      handed = true;
      ++handed_since_figures;
      // Bounded latency for the publisher even while a backlog drains.
      if (produced_.size() + outgoing_.size() >= 64) emit_states();
    }
    emit_states();
    if (handed_since_figures > 0) {
      counters_.publish_figures(core_->figures());
      handed_since_figures = 0;
    }
    if (!handed) inputs_ready_.wait_for(kStageWaitTimeout);
  }
  core_->flush();
  counters_.publish_figures(core_->figures());
  for (ScanObserver* observer : scan_observers_) observer->after_last_scan();
  states_.push(StateItem{{}, true});
  publisher_.signal();
}

}  // namespace posed::pipeline
