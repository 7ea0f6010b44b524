#include "drivers/velodyne/scan_assembler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace posed::drivers::velodyne {

ScanAssembler::ScanAssembler(PayloadPool& pool, ScanAssemblerConfig config)
    : pool_(pool), config_(config) {
  config_.cut_azimuth_cdeg %= kFullTurnCdeg;
  // offset_ns is an int32: keep every scan well inside ±2.1 s.
  config_.max_scan_duration.ns =
      std::clamp<std::int64_t>(config_.max_scan_duration.ns, 1'000'000, 2'000'000'000);
}

bool ScanAssembler::crossed_cut(std::uint32_t prev_az, std::uint32_t az, std::int64_t dt_ns) const {
  const std::uint32_t turned = (az + kFullTurnCdeg - prev_az) % kFullTurnCdeg;
  // While packets were lost the head may have turned past the cut and beyond: if the rotation
  // expected from the speed exceeds the visible change by more than three quarters of a turn,
  // it lapped. (Not half a turn: recorders that keep only part of each turn, and splice the
  // parts inside one packet, produce stamps that are off by exactly half a turn.)
  if (rate_cdeg_per_ns_ > 0.0) {
    const double expected = rate_cdeg_per_ns_ * static_cast<double>(dt_ns);
    if (expected - turned > kFullTurnCdeg * 0.75) return true;
  }
  const std::uint32_t to_cut = (config_.cut_azimuth_cdeg + kFullTurnCdeg - prev_az) % kFullTurnCdeg;
  return to_cut > 0 && to_cut <= turned;
}

void ScanAssembler::open(DeviceTime start, bool at_cut) {
  open_ = true;
  count_ = 0;
  info_ = ScanInfo{};
  info_.device_start = start;
  info_.device_end = start;
  info_.starts_at_cut = at_cut;
  lease_ = pool_.acquire();
  if (lease_) {
    const auto span = lease_.as<LidarPoint>();
    points_ = span.data();
    capacity_ = static_cast<std::uint32_t>(
        std::min<std::size_t>(span.size(), std::numeric_limits<std::uint32_t>::max()));
  } else {
    points_ = nullptr;
    capacity_ = 0;
    ++counters_.scans_no_buffer;
  }
}

void ScanAssembler::close(bool at_cut) {
  if (!open_) return;
  open_ = false;
  info_.ends_at_cut = at_cut;
  const std::uint64_t sequence = next_sequence_++;
  if (!lease_) return;  // counted in open(); the sequence gap tells the consumer
  if (ready_count_ == kReady) {
    ready_head_ = (ready_head_ + 1) % kReady;  // drop the oldest unread scan
    --ready_count_;
    ++counters_.scans_unread;
  }
  AssembledScan& slot = ready_[(ready_head_ + ready_count_) % kReady];
  slot.scan.points = std::move(lease_);
  slot.scan.point_count = count_;
  slot.scan.sequence = sequence;
  slot.scan.start_stamp = HostTime::from_ns(info_.device_start.ns + config_.host_minus_device.ns);
  slot.scan.end_stamp = HostTime::from_ns(info_.device_end.ns + config_.host_minus_device.ns);
  slot.info = info_;
  ++ready_count_;
  ++counters_.scans;
  points_ = nullptr;
  capacity_ = 0;
}

void ScanAssembler::add(const DecodedPacket& packet, DeviceTime packet_time) {
  ++counters_.packets;
  const std::int64_t packet_period_ns =
      static_cast<std::int64_t>(packet.firing_count) * packet.firing_period_ns;
  if (packet.rpm > 0.f) rate_cdeg_per_ns_ = packet.rpm * (36000.0 / 60.0) * 1e-9;

  std::uint32_t missing = 0;
  if (have_packet_) {
    const std::int64_t dt = packet_time.ns - last_packet_time_.ns;
    if (dt == 0) {
      // The same device time again: a duplicated datagram, or one that arrived after its
      // successor (ScanBuilder stamps packets with the newest device time). Its firings would
      // run backwards through the open scan and cut it at every packet: left out, counted.
      ++counters_.repeated_packets;
      return;
    }
    if (dt < 0) {
      ++counters_.time_jumps;
      close(false);
      have_firing_ = false;
    } else if (packet_period_ns > 0 && dt > packet_period_ns + packet_period_ns / 2) {
      missing = static_cast<std::uint32_t>(
          std::min<std::int64_t>((dt + packet_period_ns / 2) / packet_period_ns - 1,
                                 std::numeric_limits<std::int32_t>::max()));
      ++counters_.gaps;
      counters_.missing_packets += missing;
    }
  }
  have_packet_ = true;
  last_packet_time_ = packet_time;

  const std::uint32_t blocks_per_firing = packet.return_mode == ReturnMode::kDual ? 2 : 1;
  std::uint32_t next_point = 0;
  bool counted_packet = false;
  for (std::uint32_t f = 0; f < packet.firing_count; ++f) {
    const DeviceTime t =
        packet_time + Duration::from_ns(static_cast<std::int64_t>(f) * packet.firing_period_ns);
    const std::uint32_t az = packet.block_azimuth_cdeg[f * blocks_per_firing];
    if (have_firing_ && open_) {
      if (crossed_cut(last_azimuth_cdeg_, az, t.ns - last_firing_time_.ns)) {
        close(true);
        open(t, true);
        counted_packet = false;
      } else if (t - info_.device_start >= config_.max_scan_duration) {
        close(false);
        open(t, false);
        counted_packet = false;
      }
    }
    if (!open_) {
      open(t, false);
      counted_packet = false;
    }
    if (!counted_packet) {
      ++info_.packets;
      info_.missing_packets += missing;  // the gap lies before this packet's first firing
      missing = 0;
      counted_packet = true;
    }
    have_firing_ = true;
    last_azimuth_cdeg_ = az;
    last_firing_time_ = t;

    // Points are in block order; take this firing's.
    while (next_point < packet.point_count &&
           packet.points[next_point].block / blocks_per_firing == f) {
      const DecodedPoint& p = packet.points[next_point++];
      if (count_ >= capacity_) {
        if (points_ != nullptr) {
          ++info_.points_overflow;
          ++counters_.points_overflow;
        }
        continue;
      }
      const DeviceTime point_time = packet_time + Duration::from_ns(p.t_ns);
      LidarPoint& out = points_[count_++];
      out.x = p.x_m;
      out.y = p.y_m;
      out.z = p.z_m;
      out.intensity = static_cast<float>(p.intensity);
      out.offset_ns = static_cast<std::int32_t>(point_time.ns - info_.device_start.ns);
      out.ring = p.ring;
      out.return_index = p.return_index;
      if (point_time > info_.device_end) info_.device_end = point_time;
      ++counters_.points;
    }
  }
}

void ScanAssembler::flush() { close(false); }

bool ScanAssembler::pop(AssembledScan& out) {
  if (ready_count_ == 0) return false;
  out = std::move(ready_[ready_head_]);
  ready_head_ = (ready_head_ + 1) % kReady;
  --ready_count_;
  return true;
}

}  // namespace posed::drivers::velodyne
