#include "tools/eval/association.hpp"

#include <algorithm>
#include <map>
#include <string>

#include "tools/eval/eval_error.hpp"

namespace posed::eval {
namespace {

struct Claim {
  std::size_t short_index;
  std::int64_t abs_diff_ns;
};

}  // namespace

Association associate(const Trajectory& gt, const Trajectory& est,
                      const AssociationOptions& options) {
  Association result;
  if (!gt.has_stamps() || !est.has_stamps()) {
    if (gt.has_stamps() != est.has_stamps()) {
      throw EvalError("cannot associate " + gt.source + " (" + to_string(gt.format) + ") with " +
                      est.source + " (" + to_string(est.format) +
                      "): one has stamps and the other has none; convert both to one format");
    }
    if (gt.size() != est.size()) {
      throw EvalError("cannot associate by index: " + gt.source + " has " +
                      std::to_string(gt.size()) + " poses, " + est.source + " has " +
                      std::to_string(est.size()) +
                      " (files without stamps pair pose i with pose i, so lengths must match)");
    }
    result.by_index = true;
    for (std::size_t i = 0; i < gt.size(); ++i) {
      result.gt_index.push_back(i);
      result.est_index.push_back(i);
    }
    return result;
  }

  // evo walks the shorter trajectory; on equal length the estimate is the one walked.
  const bool est_longer = est.size() > gt.size();
  const Trajectory& walked = est_longer ? gt : est;
  const Trajectory& searched = est_longer ? est : gt;
  // Both stamp lists are on the ground-truth clock once the estimate is shifted.
  auto walked_ns = [&](std::size_t i) {
    return walked.stamps[i].ns + (est_longer ? 0 : options.est_offset.ns);
  };
  auto searched_ns = [&](std::size_t j) {
    return searched.stamps[j].ns + (est_longer ? options.est_offset.ns : 0);
  };

  std::map<std::size_t, Claim> claims;  // searched index -> the walked pose holding it
  std::size_t j = 0;                    // stamps increase, so the search only moves forward
  for (std::size_t i = 0; i < walked.size(); ++i) {
    const std::int64_t t = walked_ns(i);
    while (j + 1 < searched.size() && searched_ns(j + 1) <= t) ++j;
    // Nearest of searched[j] (last at or before t, or the first) and searched[j + 1]; on a tie
    // the earlier, as numpy's argmin would pick.
    std::size_t best = j;
    std::int64_t best_diff = std::llabs(searched_ns(j) - t);
    if (j + 1 < searched.size()) {
      const std::int64_t d = std::llabs(searched_ns(j + 1) - t);
      if (d < best_diff) {
        best = j + 1;
        best_diff = d;
      }
    }
    if (best_diff > options.max_diff.ns) {
      ++result.beyond_max_diff;
      continue;
    }
    auto [it, inserted] = claims.try_emplace(best, Claim{i, best_diff});
    if (!inserted) {
      ++result.duplicates_dropped;
      if (best_diff < it->second.abs_diff_ns) it->second = Claim{i, best_diff};
    }
  }

  for (const auto& [searched_index, claim] : claims) {
    result.gt_index.push_back(est_longer ? claim.short_index : searched_index);
    result.est_index.push_back(est_longer ? searched_index : claim.short_index);
    result.max_abs_diff = std::max(result.max_abs_diff, Duration::from_ns(claim.abs_diff_ns));
  }
  return result;
}

}  // namespace posed::eval
