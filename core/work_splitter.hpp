#pragma once
// Work the core cuts into parts that may run at the same time: the lidar front end's per-point
// loops (issue 18), so a 2-core robot matches a scan on both cores instead of one.
//
// The core cuts its work so that the result does not depend on how the parts are run: each part
// reads shared inputs, writes only its own output, and the caller joins the outputs in part order.
// The estimate is then bit-identical with or without a splitter, with any number of helper
// threads, however they are scheduled. The core starts no thread (DESIGN.md: threads belong to a
// runner around the core); the daemon's LidarHelper (daemon/pipeline/lidar_helper.hpp) gives it
// one. Without a splitter the core runs the parts itself, in order.

#include <cstddef>
#include <functional>

namespace posed {

class WorkSplitter {
 public:
  using Part = std::function<void(std::size_t part)>;
  virtual ~WorkSplitter() = default;
  /// Runs part(i) for every i in [0, parts) and returns once all have run; what they wrote is
  /// then visible to the caller. The caller may run some of them itself.
  virtual void run(std::size_t parts, const Part& part) = 0;
};

/// part(i) for i in [0, parts): on `splitter` when there is one, else here, in order.
inline void run_parts(WorkSplitter* splitter, std::size_t parts, const WorkSplitter::Part& part) {
  if (splitter != nullptr && parts > 1) {
    splitter->run(parts, part);
    return;
  }
  for (std::size_t i = 0; i < parts; ++i) part(i);
}

/// The range [begin, end) of part `part` of `parts` over `n` items: contiguous, in order.
struct PartRange {
  std::size_t begin = 0, end = 0;
};
inline PartRange part_range(std::size_t n, std::size_t part, std::size_t parts) {
  return {n * part / parts, n * (part + 1) / parts};
}

}  // namespace posed
