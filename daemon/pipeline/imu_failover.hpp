#pragma once
// The rule that hands the estimate from the A9 to the D435i's IMU and back (realsense_imu.
// failover), in sample time so that a replay decides the same way on every run: a D435i sample
// stands in for the A9 when the A9's newest sample is older than it by more than failover_after_s
// (or the A9 never spoke); the A9's samples are used again from the first one newer than the last
// sample used (an A9 not heard yet counts as silent from the D435i's first sample). One instance
// decides for the fusion core (fusion stage, in data order); live, a second one on the D435i
// stage's thread decides for rt/posed/odom from the A9's newest stamp, which the A9 stage
// publishes.

#include <algorithm>
#include <cstdint>

#include "core/time.hpp"

namespace posed::pipeline {

enum class ImuInUse : std::uint8_t { kA9, kBackup };

class ImuFailover {
 public:
  explicit ImuFailover(Duration after) : after_(after) {}

  /// The A9's sample at `stamp`: true to use it (it is newer than the last sample used).
  bool take_primary(HostTime stamp) {
    switched_ = false;
    saw_primary(stamp);
    if (have_used_ && stamp <= last_used_) return false;
    use(ImuInUse::kA9, stamp);
    return true;
  }
  /// The D435i's sample at `stamp`: true to use it in the A9's place.
  bool take_backup(HostTime stamp) {
    switched_ = false;
    if (!heard_backup_) first_backup_ = stamp;
    heard_backup_ = true;
    // An A9 that has not spoken yet gets as long, from the D435i's first sample, as a silent one.
    const HostTime primary = heard_primary_ ? newest_primary_ : first_backup_;
    if (stamp - primary <= after_) return false;
    if (have_used_ && stamp <= last_used_) return false;
    use(ImuInUse::kBackup, stamp);
    ++backup_used_;
    return true;
  }
  /// The A9's newest stamp, for an instance that does not see its samples one by one.
  void saw_primary(HostTime stamp) {
    if (heard_primary_ && stamp <= newest_primary_) return;
    heard_primary_ = true;
    newest_primary_ = stamp;
  }
  ImuInUse in_use() const { return in_use_; }
  /// times the backup took over
  std::uint64_t failovers() const { return failovers_; }
  /// D435i samples used in the A9's place
  std::uint64_t backup_used() const { return backup_used_; }
  /// the last switch's sample time and the A9's newest stamp then (for the log)
  HostTime switched_at() const { return switched_at_; }
  HostTime newest_primary() const { return newest_primary_; }
  /// set by take_*() when that call switched
  bool switched() const { return switched_; }

 private:
  void use(ImuInUse next, HostTime stamp) {
    if (next != in_use_) {
      switched_ = true;
      if (next == ImuInUse::kBackup) ++failovers_;
      in_use_ = next;
      switched_at_ = stamp;
    }
    last_used_ = stamp;
    have_used_ = true;
  }

  Duration after_;
  bool heard_primary_ = false;
  bool heard_backup_ = false;
  HostTime first_backup_;
  HostTime newest_primary_;
  bool have_used_ = false;
  HostTime last_used_;
  ImuInUse in_use_ = ImuInUse::kA9;
  std::uint64_t failovers_ = 0;
  std::uint64_t backup_used_ = 0;
  HostTime switched_at_;
  bool switched_ = false;
};

}  // namespace posed::pipeline
