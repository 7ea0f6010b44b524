#include "daemon/pipeline/fusion_stage.hpp"

#include <optional>

#include "daemon/pipeline/thread_policy.hpp"

namespace posed::pipeline {

namespace {
HostTime stamp_of(const ImuItem& item) { return item.sample.stamp; }
HostTime stamp_of(const ScanItem& item) { return item.scan.end_stamp; }
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
                         FusionCounters& counters)
    : config_(config),
      core_(std::move(core)),
      inputs_(inputs),
      in_stamp_order_(in_stamp_order),
      states_(states),
      inputs_ready_(inputs_ready),
      publisher_(publisher),
      heartbeat_(heartbeat),
      counters_(counters) {
  // A scan can release a burst of states (the IMU samples it waited for); no allocation later.
  produced_.reserve(4096);
}

void FusionStage::emit_states() {
  if (produced_.empty()) return;
  for (const NavState& state : produced_) states_.push(StateItem{state, false});
  counters_.states.fetch_add(produced_.size(), std::memory_order_relaxed);
  produced_.clear();
  publisher_.signal();
}

void FusionStage::run() {
  apply_thread_policy("posed-fusion", config_.threads.fusion);
  Lane<ImuItem> imu(inputs_.imu);
  Lane<ScanItem> scans(inputs_.scans);

  // Which lane goes next: the oldest head; IMU first on equal stamps, so a scan ending exactly at
  // an IMU sample finds it already in the core. Stamp order waits for every open lane.
  enum class Next { kNone, kImu, kScan };
  const auto next = [&] {
    imu.refill();
    scans.refill();
    if (in_stamp_order_ &&
        ((!imu.has_head() && !imu.ended()) || (!scans.has_head() && !scans.ended()))) {
      return Next::kNone;
    }
    if (imu.has_head() && (!scans.has_head() || imu.head_stamp() <= scans.head_stamp())) {
      return Next::kImu;
    }
    return scans.has_head() ? Next::kScan : Next::kNone;
  };

  std::uint64_t handed_since_figures = 0;
  while (!imu.ended() || !scans.ended()) {
    heartbeat_.beat();
    bool handed = false;
    for (Next n = next(); n != Next::kNone; n = next()) {
      heartbeat_.beat();  // a backlog can take a while; the watchdog must see the stage alive
      if (n == Next::kImu) {
        core_->add_imu(imu.take().sample, produced_);
      } else {
        core_->add_scan(scans.take().scan, produced_);
        counters_.scans_fused.fetch_add(1, std::memory_order_relaxed);
      }
      counters_.mode.store(core_->mode(), std::memory_order_relaxed);
      handed = true;
      ++handed_since_figures;
      // Bounded latency for the publisher even while a backlog drains.
      if (produced_.size() >= 64) emit_states();
    }
    emit_states();
    if (handed_since_figures > 0) {
      counters_.publish_figures(core_->figures());
      handed_since_figures = 0;
    }
    if (!handed) inputs_ready_.wait_for(kStageWaitTimeout);
  }
  counters_.publish_figures(core_->figures());
  states_.push(StateItem{{}, true});
  publisher_.signal();
}

}  // namespace posed::pipeline
