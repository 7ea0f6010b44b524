#include "daemon/pipeline/mapping_stage.hpp"

#include <algorithm>

#include "daemon/pipeline/estimator_config.hpp"
#include "daemon/pipeline/thread_policy.hpp"
#include "drivers/common/log.hpp"

namespace posed::pipeline {

MappingStage::MappingStage(const config::PosedConfig& config, bool in_data_order,
                           Heartbeat& heartbeat,
                           std::shared_ptr<const mapping::KeyframeMap> prior_map)
    : in_data_order_(in_data_order),
      capacity_(static_cast<std::size_t>(config.mapping.queue_capacity)),
      T_base_lidar_(to_isometry(config.extrinsics.T_imu_lidar)),
      heartbeat_(heartbeat),
      closer_(loop_closure_config(config)),
      selector_(closer_.config().keyframe_distance_m, closer_.config().keyframe_angle_rad) {
  corrections_.emplace_back(0, Eigen::Isometry3d::Identity());
  if (prior_map) {
    localiser_.emplace(*prior_map, localisation_config(config));
    figures_.localising = true;
    if (config.mapping.initial_pose_given) {
      initial_T_map_base_ = initial_pose(config.mapping);
    }
  }
}

void MappingStage::set_initial_pose(const Eigen::Isometry3d& T_map_base) {
  std::lock_guard lock(mutex_);
  initial_T_map_base_ = T_map_base;
}

void MappingStage::after_scan(const FusionCore& core) {
  Item item;
  MatchedScan scan;
  // A scan the core did not match (yet, or at all) is still one item: states count scans.
  if (core.latest_matched_scan(scan) && scan.index != last_scan_index_) {
    last_scan_index_ = scan.index;
    const Eigen::Isometry3d T_odom_base = scan.T_map_lidar * T_base_lidar_.inverse();
    // Localising needs every scan: while aligning each is a lookup.
    if (localiser_ || selector_.take(T_odom_base)) {
      item.has_scan = true;
      // How much of the odometry since the last keyframe ran on degenerate matches.
      const FusionFigures f = core.figures();
      const std::uint64_t used = f.scans_used - used_at_keyframe_;
      const std::uint64_t degenerate = f.scans_degenerate - degenerate_at_keyframe_;
      item.degenerate_share =
          used > 0 ? std::min(1.0, static_cast<double>(degenerate) / static_cast<double>(used))
                   : 0.0;
      used_at_keyframe_ = f.scans_used;
      degenerate_at_keyframe_ = f.scans_degenerate;
      item.stamp = scan.stamp;
      item.T_odom_base = T_odom_base;
      item.points_base.reserve(scan.points_lidar.size());
      const Eigen::Isometry3f T_base_lidar = T_base_lidar_.cast<float>();
      for (const lidar::ScanPoint& p : scan.points_lidar) {
        item.points_base.push_back(T_base_lidar * p.p);
      }
    }
  }
  push(std::move(item));
}

void MappingStage::after_last_scan() {
  Item item;
  item.last = true;
  push(std::move(item));
}

void MappingStage::push(Item item) {
  {
    std::unique_lock lock(mutex_);
    if (in_data_order_) {
      // A replay waits for the mapping thread rather than lose a keyframe.
      progress_.wait(lock, [this] { return queue_.size() < capacity_; });
    } else if (queue_.size() >= capacity_ && item.has_scan) {
      // Live, the fusion thread never waits: the scan's cloud is let go (the scan still counts,
      // so later states find their place); the graph bridges the gap by odometry, and the
      // localiser waits for the next scan.
      item.has_scan = false;
      item.points_base = {};
      ++figures_.keyframes_dropped;
    }
    queue_.push_back(std::move(item));
  }
  item_ready_.notify_one();
}

void MappingStage::run() {
  apply_thread_policy("posed-mapping", config::ThreadSection{});
  for (;;) {
    heartbeat_.beat();
    Item item;
    {
      std::unique_lock lock(mutex_);
      if (!item_ready_.wait_for(lock, kStageWaitTimeout, [this] { return !queue_.empty(); })) {
        continue;
      }
      item = std::move(queue_.front());
      queue_.pop_front();
    }
    progress_.notify_all();  // room in the queue
    if (item.last) {
      std::lock_guard lock(mutex_);
      ended_ = true;
      break;
    }
    take(item);
    progress_.notify_all();
  }
  progress_.notify_all();
}

bool MappingStage::take(Item& item) {
  if (localiser_) {
    std::optional<Eigen::Isometry3d> initial;
    {
      std::lock_guard lock(mutex_);
      initial.swap(initial_T_map_base_);
    }
    const mapping::LocalisationState state_before = localiser_->state();
    if (initial) {
      localiser_->set_initial_pose(*initial);
      POSED_LOG_NOTICE("mapping: initial pose (%.2f, %.2f, %.2f) m in the map",
                       initial->translation().x(), initial->translation().y(),
                       initial->translation().z());
    }
    const std::uint64_t fixes_before = localiser_->figures().fixes;
    if (item.has_scan) {
      localiser_->add_scan(item.stamp, item.T_odom_base, item.points_base);
    }
    const mapping::LocalisationFigures& f = localiser_->figures();
    const bool changed = f.fixes != fixes_before;
    {
      std::lock_guard lock(mutex_);
      ++taken_;
      ++figures_.scans;
      figures_.state = localiser_->state();
      figures_.localisation = f;
      if (changed) {
        corrections_.emplace_back(taken_, localiser_->T_map_odom());
        figures_.T_map_odom = localiser_->T_map_odom();
      }
    }
    if (localiser_->state() != state_before) {
      const Eigen::Vector3d p = (localiser_->T_map_odom() * item.T_odom_base).translation();
      POSED_LOG_NOTICE(
          "mapping: %s at %.3f s (at (%.2f, %.2f, %.2f) m in the map; fit %.3f m, "
          "overlap %.2f; %llu lookups, %llu fixes)",
          std::string(mapping::state_name(localiser_->state())).c_str(), item.stamp.seconds(),
          p.x(), p.y(), p.z(), f.last_fix_rms_m, f.last_fix_overlap,
          static_cast<unsigned long long>(f.lookups), static_cast<unsigned long long>(f.fixes));
    }
    return changed;
  }
  const std::size_t loops_before = closer_.loops().size();
  const std::uint64_t implausible_before = closer_.figures().implausible;
  if (item.has_scan) {
    closer_.add_keyframe(item.stamp, item.T_odom_base, item.points_base, item.degenerate_share);
  }
  const std::size_t loops_now = closer_.loops().size();
  {
    std::lock_guard lock(mutex_);
    ++taken_;
    ++figures_.scans;
    figures_.loops = closer_.figures();
    if (loops_now != loops_before) {
      corrections_.emplace_back(taken_, closer_.T_map_odom());
      figures_.accepted = closer_.loops();
      figures_.T_map_odom = closer_.T_map_odom();
    }
  }
  // A confirmed descriptor loop accepts two at once: each is logged.
  for (std::size_t i = loops_before; i < loops_now; ++i) {
    const mapping::LoopRecord& loop = closer_.loops()[i];
    POSED_LOG_NOTICE(
        "mapping: loop %zu at %.3f s: keyframe %zu -> %zu (%s), fit %.3f m, overlap %.2f, "
        "correction %.2f m (%.1f sigma); map -> odom now %.2f m off",
        i + 1, loop.stamp.seconds(), loop.query, loop.candidate,
        loop.by_descriptor ? "descriptor" : "distance", loop.rms_m, loop.overlap, loop.correction_m,
        loop.correction_sigmas, closer_.T_map_odom().translation().norm());
  }
  if (closer_.figures().implausible != implausible_before && closer_.last_implausible()) {
    const mapping::LoopRecord& loop = *closer_.last_implausible();
    POSED_LOG_NOTICE(
        "mapping: loop refused at %.3f s: keyframe %zu -> %zu (%s) fits (%.3f m, overlap %.2f) "
        "but asks for a correction of %.2f m, %.1f sigma of the odometry between them: another "
        "place like this one?",
        loop.stamp.seconds(), loop.query, loop.candidate,
        loop.by_descriptor ? "descriptor" : "distance", loop.rms_m, loop.overlap, loop.correction_m,
        loop.correction_sigmas);
  }
  return loops_now != loops_before;
}

bool MappingStage::wait_until_taken(std::uint64_t scans, std::chrono::milliseconds timeout) {
  if (!in_data_order_) {
    return true;
  }
  std::unique_lock lock(mutex_);
  return progress_.wait_for(lock, timeout, [&] { return taken_ >= scans || ended_; });
}

Eigen::Isometry3d MappingStage::T_map_odom(std::uint64_t scans_before) const {
  std::lock_guard lock(mutex_);
  if (!in_data_order_) {
    return corrections_.back().second;
  }
  // The newest correction that took effect by then.
  for (auto it = corrections_.rbegin(); it != corrections_.rend(); ++it) {
    if (it->first <= scans_before) {
      return it->second;
    }
  }
  return Eigen::Isometry3d::Identity();
}

std::vector<std::pair<HostTime, Eigen::Isometry3d>> MappingStage::optimised_keyframes() const {
  std::vector<std::pair<HostTime, Eigen::Isometry3d>> out;
  if (localiser_) {
    return out;
  }
  out.reserve(closer_.keyframe_count());
  for (std::size_t i = 0; i < closer_.keyframe_count(); ++i) {
    out.emplace_back(closer_.keyframe_stamp(i), closer_.T_map_keyframe(i));
  }
  return out;
}

mapping::KeyframeMap MappingStage::built_map() const {
  if (localiser_) {
    return {};
  }
  return closer_.snapshot();
}

MappingFigures MappingStage::figures() const {
  std::lock_guard lock(mutex_);
  return figures_;
}

}  // namespace posed::pipeline
