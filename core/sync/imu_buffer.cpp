#include "core/sync/imu_buffer.hpp"

#include <cmath>
#include <cstdint>

namespace posed {

ImuBuffer::ImuBuffer(const ImuBufferConfig& config) : config_(config), ring_(config.capacity) {}

ImuPushResult ImuBuffer::push(const ImuSample& sample) {
  using Push = StampedRing<ImuSample>::Push;
  switch (ring_.push(sample)) {
    case Push::kAppended:
      ++counters_.accepted;
      return ImuPushResult::kAccepted;
    case Push::kAppendedOverwrote:
      ++counters_.accepted;
      ++counters_.overwritten;
      return ImuPushResult::kAcceptedOverwrote;
    case Push::kRefusedDuplicate:
      ++counters_.duplicate_dropped;
      return ImuPushResult::kDroppedDuplicate;
    case Push::kRefusedOutOfOrder:
      ++counters_.out_of_order_dropped;
      return ImuPushResult::kDroppedOutOfOrder;
    case Push::kRefusedNoCapacity:
      break;
  }
  return ImuPushResult::kDroppedNoCapacity;
}

bool ImuBuffer::covers(HostTime t) const { return !ring_.empty() && ring_.back().stamp >= t; }

ImuRange ImuBuffer::samples_between(HostTime t0, HostTime t1, std::vector<ImuSample>& out) const {
  out.clear();
  ImuRange range;
  if (t0 > t1 || ring_.empty()) return range;
  const std::size_t first_inside = ring_.lower_bound(t0);
  const std::size_t past_inside = ring_.upper_bound(t1);
  const std::size_t begin = first_inside > 0 ? first_inside - 1 : first_inside;
  const std::size_t end = past_inside < ring_.size() ? past_inside + 1 : past_inside;
  for (std::size_t i = begin; i < end; ++i) out.push_back(ring_[i]);
  range.count = end - begin;
  range.has_before = begin < first_inside;
  range.has_after = end > past_inside;
  if (range.count > 0) {
    range.covers_begin = out.front().stamp <= t0;
    range.covers_end = out.back().stamp >= t1;
  }
  return range;
}

std::optional<ImuSample> ImuBuffer::interpolate(HostTime t) const {
  if (ring_.empty() || t < ring_.front().stamp || t > ring_.back().stamp) return std::nullopt;
  const std::size_t i = ring_.lower_bound(t);  // exists: t <= newest
  const ImuSample& b = ring_[i];
  if (b.stamp == t) return b;
  const ImuSample& a = ring_[i - 1];  // exists: t > oldest and b is the first >= t
  const double s =
      static_cast<double>((t - a.stamp).ns) / static_cast<double>((b.stamp - a.stamp).ns);
  ImuSample out;
  out.stamp = t;
  // In integer ns, rounded: a device stamp must not go through double seconds.
  out.device_stamp =
      a.device_stamp + Duration::from_ns(static_cast<std::int64_t>(std::llround(
                           s * static_cast<double>((b.device_stamp - a.device_stamp).ns))));
  out.angular_velocity_radps =
      a.angular_velocity_radps + s * (b.angular_velocity_radps - a.angular_velocity_radps);
  out.specific_force_mps2 =
      a.specific_force_mps2 + s * (b.specific_force_mps2 - a.specific_force_mps2);
  return out;
}

std::size_t ImuBuffer::discard_before(HostTime t) {
  const std::size_t older = ring_.lower_bound(t);
  if (older <= 1) return 0;  // keep the newest older sample as the lower bracket
  const std::size_t removed = older - 1;
  ring_.pop_front(removed);
  counters_.discarded += removed;
  return removed;
}

}  // namespace posed
