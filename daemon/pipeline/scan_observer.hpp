#pragma once
// A look at the estimator after each scan, on the fusion thread, for outputs that need more than
// states (rt/posed/cloud, rt/posed/map: CloudOutput). The observer copies what it wants and
// returns; whatever it does with the copy happens on its own thread.

#include "core/estimator/fusion_core.hpp"

namespace posed::pipeline {

class ScanObserver {
 public:
  virtual ~ScanObserver() = default;
  /// Right after the core was handed a scan (which it may not have matched yet, or at all).
  virtual void after_scan(const FusionCore& core) = 0;
  /// After the last scan: the fusion stage has ended.
  virtual void after_last_scan() {}
};

}  // namespace posed::pipeline
