#pragma once
// Pairs ground-truth poses with estimate poses. Stamped files are matched by time the way evo's
// `associate_trajectories` does: the trajectory with fewer poses is walked, each of its stamps
// takes the nearest stamp of the other (estimate stamps shifted by `est_offset`), and the pair
// is kept when |difference| <= max_diff. Unlike evo, a pose of the longer trajectory is used at
// most once: when two stamps pick it, the closer keeps it (the earlier on a tie) and the other
// is dropped and counted, so no pose is weighted twice.
// Files without stamps (KITTI) pair pose i with pose i and must have equal length.

#include <cstddef>
#include <vector>

#include "core/time.hpp"
#include "tools/eval/trajectory.hpp"

namespace posed::eval {

struct AssociationOptions {
  /// largest accepted |t_gt - (t_est + est_offset)| [ns]
  Duration max_diff = Duration::from_ms(10);
  /// added to every estimate stamp before matching [ns]
  Duration est_offset = Duration::from_ns(0);
};

struct Association {
  /// index into the ground truth of each pair, increasing [1]
  std::vector<std::size_t> gt_index;
  /// index into the estimate of each pair (same length as gt_index) [1]
  std::vector<std::size_t> est_index;
  /// true when paired by index (no stamps), false when by time
  bool by_index = false;
  /// poses of the shorter trajectory whose nearest stamp was farther than max_diff [1]
  std::size_t beyond_max_diff = 0;
  /// poses of the shorter trajectory dropped because a closer one took their match [1]
  std::size_t duplicates_dropped = 0;
  /// largest |time difference| among the pairs kept [ns]
  Duration max_abs_diff = Duration::from_ns(0);

  std::size_t size() const { return gt_index.size(); }
};

/// Throws EvalError when one file has stamps and the other has none, or when two stamp-less
/// files differ in length. Fewer than 3 pairs is not an error here (see evaluate()).
Association associate(const Trajectory& gt, const Trajectory& est,
                      const AssociationOptions& options = {});

}  // namespace posed::eval
