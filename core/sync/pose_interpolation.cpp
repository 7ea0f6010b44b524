#include "core/sync/pose_interpolation.hpp"

namespace posed {

Eigen::Quaterniond slerp_shortest(const Eigen::Quaterniond& qa, const Eigen::Quaterniond& qb,
                                  double s) {
  const Eigen::Quaterniond a = qa.normalized();
  Eigen::Quaterniond delta = a.conjugate() * qb.normalized();
  // q and -q are one rotation; the one with w >= 0 is the short way round (angle <= pi).
  if (delta.w() < 0.0) delta.coeffs() = -delta.coeffs();
  // Axis-angle rather than Eigen's slerp: it also extrapolates (s outside [0, 1]) and needs no
  // small-angle branch (AngleAxis picks a unit axis when the angle is 0).
  const Eigen::AngleAxisd step(delta);
  return (a * Eigen::Quaterniond(Eigen::AngleAxisd(s * step.angle(), step.axis()))).normalized();
}

std::optional<Pose> interpolate_pose(const Pose& a, const Pose& b, HostTime t,
                                     Duration max_extrapolation) {
  if (a.stamp > b.stamp || max_extrapolation.ns < 0) return std::nullopt;
  if (t < a.stamp - max_extrapolation || t > b.stamp + max_extrapolation) return std::nullopt;
  if (t == a.stamp) return a;
  if (t == b.stamp) return b;
  if (a.stamp == b.stamp) {
    Pose held = a;
    held.stamp = t;
    return held;
  }
  const double s =
      static_cast<double>((t - a.stamp).ns) / static_cast<double>((b.stamp - a.stamp).ns);
  Pose out;
  out.stamp = t;
  out.p = a.p + s * (b.p - a.p);
  out.q = slerp_shortest(a.q, b.q, s);
  return out;
}

PoseHistory::PoseHistory(const PoseHistoryConfig& config)
    : config_(config), ring_(config.capacity) {}

bool PoseHistory::push(const Pose& pose) {
  using Push = StampedRing<Pose>::Push;
  switch (ring_.push(pose)) {
    case Push::kAppended:
      ++counters_.accepted;
      return true;
    case Push::kAppendedOverwrote:
      ++counters_.accepted;
      ++counters_.overwritten;
      return true;
    case Push::kRefusedDuplicate:
    case Push::kRefusedOutOfOrder:
      ++counters_.out_of_order_dropped;
      return false;
    case Push::kRefusedNoCapacity:
      break;
  }
  return false;
}

std::optional<Pose> PoseHistory::at(HostTime t) const {
  const std::size_t n = ring_.size();
  if (n == 0) return std::nullopt;
  if (n == 1) return interpolate_pose(ring_[0], ring_[0], t, config_.max_extrapolation);
  // The pair to use: the one bracketing t, or the end pair when t is outside (extrapolation).
  std::size_t i = ring_.lower_bound(t);  // first pose with stamp >= t
  if (i == 0) i = 1;
  if (i >= n) i = n - 1;
  return interpolate_pose(ring_[i - 1], ring_[i], t, config_.max_extrapolation);
}

}  // namespace posed
