#pragma once
// The mapping stage (one thread; DESIGN.md, Data flow: mapping → tf map→odom). On the fusion
// thread, after every scan, it copies the newest matched scan when it is a keyframe (the
// estimator's keyframe spacing) and queues it; its own thread feeds core/mapping's LoopCloser,
// which verifies loops and optimises the pose graph off the real-time path. What comes out is
// map -> odom, which the publisher applies to rt/posed/pose and rt/tf.
//
// With a prior map (posed --map DIR) the stage localises instead (core/mapping's Localiser): it
// is shown every scan, looks its place up in the map, tracks the map by registration, and the
// map is not grown. map -> odom then moves the odometry onto the prior map's frame.
//
// Order. Every scan the fusion stage hands the core is one item here, keyframe or not, and every
// state carries how many scans came before it (StateItem::scans_before). Live, a state gets the
// newest correction there is: odometry and poses never wait for a registration. In a replay in
// data order the publisher waits until this stage has taken the scans before the state and uses
// the correction as it stood then, so a max-speed replay puts the same poses in the map frame on
// every run however the threads were scheduled.

#include <Eigen/Geometry>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "core/mapping/localiser.hpp"
#include "core/mapping/loop_closer.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/pipeline/scan_observer.hpp"
#include "daemon/pipeline/stage_support.hpp"

namespace posed::pipeline {

struct MappingFigures {
  /// localising on a prior map (the localisation figures below), not closing loops
  bool localising = false;
  mapping::LocalisationState state = mapping::LocalisationState::kAligning;
  mapping::LocalisationFigures localisation;
  mapping::LoopClosureFigures loops;
  std::vector<mapping::LoopRecord> accepted;  ///< every accepted loop, oldest first
  Eigen::Isometry3d T_map_odom = Eigen::Isometry3d::Identity();
  std::uint64_t scans = 0;              ///< scans the stage was shown [1]
  std::uint64_t keyframes_dropped = 0;  ///< live: keyframes the full queue refused [1]
};

class MappingStage final : public ScanObserver {
 public:
  /// `in_data_order`: a replay whose poses must not depend on thread timing (see above).
  /// `prior_map`: localise on it instead of closing loops (null: close loops).
  MappingStage(const config::PosedConfig& config, bool in_data_order, Heartbeat& heartbeat,
               std::shared_ptr<const mapping::KeyframeMap> prior_map = nullptr);

  /// Fusion thread, after every scan handed to the core.
  void after_scan(const FusionCore& core) override;
  /// Fusion thread: no scan follows; the stage's thread ends once it has taken the queue.
  void after_last_scan() override;
  /// The stage's thread.
  void run();

  /// Publisher thread, in data order: waits up to `timeout` for the stage to take the first
  /// `scans` scans; true once it has (at once live, and once the stage has ended).
  bool wait_until_taken(std::uint64_t scans, std::chrono::milliseconds timeout);
  /// Publisher thread: map -> odom for a state made after `scans_before` scans: in data order
  /// the correction as it stood once the stage had taken them (wait_until_taken() first); live,
  /// the newest.
  Eigen::Isometry3d T_map_odom(std::uint64_t scans_before) const;
  MappingFigures figures() const;
  /// Any thread, localising: where base_link is in the map now (config mapping.initial_pose,
  /// rt/initialpose); the stage's thread looks there first at the next scan.
  void set_initial_pose(const Eigen::Isometry3d& T_map_base);
  /// Every keyframe's stamp and optimised pose (base_link in map), oldest first. After the
  /// stage's thread has ended.
  std::vector<std::pair<HostTime, Eigen::Isometry3d>> optimised_keyframes() const;
  /// The map the loop closer built (KeyframeMap stamps: HostTime), for posed --save-map DIR.
  /// After the stage's thread has ended; empty when localising (the map is not grown).
  mapping::KeyframeMap built_map() const;

 private:
  struct Item {
    bool has_scan = false;  ///< a keyframe's scan (closing loops) or every scan (localising)
    bool last = false;      ///< after_last_scan(): nothing follows
    HostTime stamp;
    Eigen::Isometry3d T_odom_base = Eigen::Isometry3d::Identity();
    std::vector<Eigen::Vector3f> points_base;
    double degenerate_share = 0;  ///< of the scans used since the last keyframe [0..1]
  };
  void push(Item item);
  /// The stage's thread: one scan into the localiser or loop closer; true when map -> odom
  /// changed.
  bool take(Item& item);

  const bool in_data_order_;
  const std::size_t capacity_;
  const Eigen::Isometry3d T_base_lidar_;
  Heartbeat& heartbeat_;
  mapping::LoopCloser closer_;                   ///< the stage's thread only
  std::optional<mapping::Localiser> localiser_;  ///< with a prior map; the stage's thread only
  // Fusion thread only.
  mapping::KeyframeSelector selector_;
  std::uint64_t last_scan_index_ = 0;
  std::uint64_t used_at_keyframe_ = 0;        ///< FusionFigures::scans_used at the last keyframe
  std::uint64_t degenerate_at_keyframe_ = 0;  ///< and scans_degenerate

  mutable std::mutex mutex_;
  std::condition_variable item_ready_;  ///< the stage's thread waits for items
  std::condition_variable progress_;    ///< the fusion and publisher threads wait for it
  std::deque<Item> queue_;
  std::uint64_t taken_ = 0;  ///< items (scans) the stage's thread has finished [1]
  bool ended_ = false;       ///< the last item was taken
  /// (items taken when it took effect, map -> odom), one entry per change, oldest first
  std::vector<std::pair<std::uint64_t, Eigen::Isometry3d>> corrections_;
  MappingFigures figures_;
  std::optional<Eigen::Isometry3d> initial_T_map_base_;  ///< set_initial_pose(), not yet taken
};

}  // namespace posed::pipeline
