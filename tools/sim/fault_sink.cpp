#include "tools/sim/fault_sink.hpp"

#include <cmath>
#include <cstdio>

#include "drivers/imu/a9_protocol.hpp"
#include "drivers/velodyne/packet_format.hpp"
#include "drivers/velodyne/position_packet.hpp"
#include "tools/faults/fault_text.hpp"

namespace posed::sim {

namespace {

constexpr FaultKind kKinds[] = {
    FaultKind::kLidarOutage,  FaultKind::kImuGap,     FaultKind::kCameraBlackout,
    FaultKind::kCameraFreeze, FaultKind::kThermalFfc, FaultKind::kCorruptBurst,
    FaultKind::kDuplicate,    FaultKind::kReorder,    FaultKind::kImuReset,
    FaultKind::kPpsLoss,
};

std::uint32_t get_u32(const std::vector<std::byte>& b, std::size_t at) {
  std::uint32_t v = 0;
  for (std::size_t k = 0; k < 4; ++k) v |= std::to_integer<std::uint32_t>(b[at + k]) << (8 * k);
  return v;
}
void put_u32(std::vector<std::byte>& b, std::size_t at, std::uint32_t v) {
  for (std::size_t k = 0; k < 4; ++k) b[at + k] = static_cast<std::byte>((v >> (8 * k)) & 0xFF);
}

/// Where an A9 frame's µs counter sits: after sync, LEN and the u32 frame info.
constexpr std::size_t kA9CounterOffset = 3 + 4;

}  // namespace

std::string_view to_string(FaultKind kind) {
  switch (kind) {
    case FaultKind::kLidarOutage:
      return "lidar_outage";
    case FaultKind::kImuGap:
      return "imu_gap";
    case FaultKind::kCameraBlackout:
      return "camera_blackout";
    case FaultKind::kCameraFreeze:
      return "camera_freeze";
    case FaultKind::kThermalFfc:
      return "thermal_ffc";
    case FaultKind::kCorruptBurst:
      return "corrupt_burst";
    case FaultKind::kDuplicate:
      return "duplicate";
    case FaultKind::kReorder:
      return "reorder";
    case FaultKind::kImuReset:
      return "imu_reset";
    case FaultKind::kPpsLoss:
      return "pps_loss";
  }
  return "unknown";
}

std::string to_string(const Fault& fault) {
  return std::string(to_string(fault.kind)) +
         faults::window_text({fault.start_s, fault.duration_s});
}

std::string fault_kind_names() {
  std::string names;
  for (const FaultKind k : kKinds) names += (names.empty() ? "" : ", ") + std::string(to_string(k));
  return names;
}

bool parse_fault(std::string_view text, Fault& out, std::string& error) {
  std::string_view name;
  faults::FaultWindow window;
  if (!faults::parse_fault_text(text, "KIND@START+DURATION (seconds), e.g. lidar_outage@30+5", name,
                                window, error)) {
    return false;
  }
  bool known = false;
  for (const FaultKind k : kKinds) {
    if (to_string(k) == name) {
      out.kind = k;
      known = true;
    }
  }
  if (!known) {
    error = "fault '" + std::string(text) + "': unknown kind '" + std::string(name) +
            "' (kinds: " + fault_kind_names() + ")";
    return false;
  }
  out.start_s = window.start_s;
  out.duration_s = window.duration_s;
  return true;
}

FaultSink::FaultSink(SimSink& inner, std::vector<Fault> faults, std::int64_t host_epoch_ns,
                     std::uint64_t seed)
    : inner_(inner),
      faults_(std::move(faults)),
      host_epoch_ns_(host_epoch_ns),
      random_(seed),
      reset_counter_us_(faults_.size()) {}

int FaultSink::add_stream(const SimStream& stream) {
  const int id = inner_.add_stream(stream);
  if (id < 0) return id;
  const auto n = static_cast<std::size_t>(id) + 1;
  if (streams_.size() < n) {
    streams_.resize(n);
    counts_.resize(n);
    last_frame_.resize(n);
    held_.resize(n);
  }
  streams_[static_cast<std::size_t>(id)] = stream;
  return id;
}

bool FaultSink::is_frame(int stream) const {
  const SimStream& s = streams_[static_cast<std::size_t>(stream)];
  return (s.name == "visible" || s.name == "thermal") && s.source_channel == 0;
}

bool FaultSink::applies(const Fault& f, int stream) const {
  const SimStream& s = streams_[static_cast<std::size_t>(stream)];
  switch (f.kind) {
    case FaultKind::kLidarOutage:
      return s.name == "lidar";
    case FaultKind::kImuGap:
    case FaultKind::kImuReset:
      return s.name == "imu";
    case FaultKind::kPpsLoss:
      return s.name == "lidar";
    case FaultKind::kCameraBlackout:
    case FaultKind::kCameraFreeze:
      return is_frame(stream);
    case FaultKind::kThermalFfc:
      return s.name == "thermal" && s.source_channel == 0;
    case FaultKind::kCorruptBurst:
    case FaultKind::kDuplicate:
    case FaultKind::kReorder:
      return true;
  }
  return false;
}

bool FaultSink::write_raw(int stream, HostTime host_time, std::span<const std::byte> bytes) {
  const auto i = static_cast<std::size_t>(stream);
  if (stream < 0 || i >= streams_.size()) return inner_.write_raw(stream, host_time, bytes);
  last_host_time_ = host_time;
  const double t_s = static_cast<double>(host_time.ns - host_epoch_ns_) / 1e9;
  FaultCounts& count = counts_[i];
  bool drop = false, blank = false, freeze = false, corrupt = false, duplicate = false;
  bool reorder = false;
  for (const Fault& f : faults_) {
    if (!f.active(t_s) || !applies(f, stream)) continue;
    switch (f.kind) {
      case FaultKind::kLidarOutage:
      case FaultKind::kImuGap:
        drop = true;
        break;
      case FaultKind::kImuReset: {
        // Rebooting: silent. The first frame it silences fixes where the counter restarts.
        auto& counter = reset_counter_us_[static_cast<std::size_t>(&f - faults_.data())];
        if (!counter && bytes.size() >= kA9CounterOffset + 4) {
          counter = get_u32(std::vector<std::byte>(bytes.begin(), bytes.end()), kA9CounterOffset);
        }
        drop = true;
        break;
      }
      case FaultKind::kPpsLoss:
        break;  // free_run() below
      case FaultKind::kCameraBlackout:
        blank = true;
        break;
      case FaultKind::kCameraFreeze:
      case FaultKind::kThermalFfc:
        freeze = true;
        break;
      case FaultKind::kCorruptBurst:
        corrupt = true;
        break;
      case FaultKind::kDuplicate:
        duplicate = true;
        break;
      case FaultKind::kReorder:
        reorder = true;
        break;
    }
  }
  if (drop) {
    ++count.dropped;
    return true;
  }
  std::vector<std::byte> out(bytes.begin(), bytes.end());
  if ((streams_[i].name == "imu" && restart_counter(t_s, out)) ||
      (streams_[i].name == "lidar" && free_run(t_s, stream, out))) {
    ++count.restamped;
  }
  if (is_frame(stream)) {
    if (freeze && !last_frame_[i].empty() && last_frame_[i].size() == out.size()) {
      out = last_frame_[i];
      ++count.frozen;
    } else if (!freeze) {
      last_frame_[i] = out;
    }
    if (blank) {
      const std::string& format = streams_[i].wire_format;
      if (format == "yuyv") {
        for (std::size_t k = 0; k < out.size(); ++k)
          out[k] = k % 2 == 0 ? std::byte{16} : std::byte{128};
      } else {
        // A covered thermal lens sees the cover: every pixel alike, at the frame's mean.
        const std::size_t step = format == "y16" ? 2 : 1;
        double sum = 0;
        for (std::size_t k = 0; k + step <= out.size(); k += step) {
          sum += step == 2 ? static_cast<double>(std::to_integer<unsigned>(out[k]) |
                                                 std::to_integer<unsigned>(out[k + 1]) << 8)
                           : static_cast<double>(std::to_integer<unsigned>(out[k]));
        }
        const auto mean = static_cast<unsigned>(sum / static_cast<double>(out.size() / step));
        for (std::size_t k = 0; k + step <= out.size(); k += step) {
          out[k] = static_cast<std::byte>(mean & 0xFF);
          if (step == 2) out[k + 1] = static_cast<std::byte>(mean >> 8);
        }
      }
      ++count.blanked;
    }
  }
  if (corrupt && !out.empty()) {
    faults::flip_random_bits(out, random_);
    ++count.corrupted;
  }
  Held& held = held_[i];
  if (reorder && !held.held) {
    // Held back: it arrives after the next message of its stream.
    held = {true, std::move(out)};
    return true;
  }
  if (!inner_.write_raw(stream, host_time, out)) return false;
  if (duplicate) {
    if (!inner_.write_raw(stream, host_time, out)) return false;
    ++count.duplicated;
  }
  if (held.held) {
    held.held = false;
    ++count.reordered;
    // Late: stamped with the time it finally arrives.
    if (!inner_.write_raw(stream, host_time, held.bytes)) return false;
  }
  return true;
}

bool FaultSink::restart_counter(double t_s, std::vector<std::byte>& frame) {
  namespace a9 = drivers::a9;
  std::uint32_t restarted_by_us = 0;
  for (std::size_t k = 0; k < faults_.size(); ++k) {
    const Fault& f = faults_[k];
    if (f.kind != FaultKind::kImuReset || t_s < f.start_s + f.duration_s) continue;
    // A reboot the run never saw the device deliver during (no frame in the window) still
    // restarts the counter: from the first frame after it, which reads ~0 after the boot.
    if (!reset_counter_us_[k] && frame.size() >= kA9CounterOffset + 4) {
      reset_counter_us_[k] = get_u32(frame, kA9CounterOffset) -
                             static_cast<std::uint32_t>(std::llround(f.duration_s * 1e6));
    }
    restarted_by_us += *reset_counter_us_[k];
  }
  if (restarted_by_us == 0 || frame.size() < a9::kFrameOverhead + a9::kMinBodyLen ||
      frame[0] != std::byte{a9::kSync0} || frame[1] != std::byte{a9::kSync1}) {
    return false;
  }
  const std::size_t len = std::to_integer<std::size_t>(frame[2]);
  if (frame.size() < len + a9::kFrameOverhead) return false;
  // The µs counter wraps at 2^32: unsigned subtraction is the restarted counter.
  put_u32(frame, kA9CounterOffset, get_u32(frame, kA9CounterOffset) - restarted_by_us);
  const auto* crc_bytes = reinterpret_cast<const std::uint8_t*>(frame.data() + 2);
  const std::uint16_t crc = a9::crc16_modbus({crc_bytes, len + 1});
  frame[3 + len] = static_cast<std::byte>(crc & 0xFF);
  frame[4 + len] = static_cast<std::byte>(crc >> 8);
  return true;
}

bool FaultSink::free_run(double t_s, int stream, std::vector<std::byte>& packet) const {
  namespace vel = drivers::velodyne;
  const bool position = streams_[static_cast<std::size_t>(stream)].source_channel == 1;
  const std::size_t stamp_at = position ? vel::kPositionTimestampOffset : vel::kTimestampOffset;
  if (packet.size() < (position ? vel::kPositionPacketBytes : vel::kDataPacketBytes)) {
    return false;
  }
  for (const Fault& f : faults_) {
    if (f.kind != FaultKind::kPpsLoss || !f.active(t_s)) continue;
    // Without PPS the lidar's µs past the hour runs on its crystal, kFreeRunPpm fast; the
    // host sees the packet's time creep ahead until the PPS re-locks it.
    const auto ahead_us = static_cast<std::uint64_t>(std::llround((t_s - f.start_s) * kFreeRunPpm));
    const std::uint64_t stamp = get_u32(packet, stamp_at);
    put_u32(packet, stamp_at, static_cast<std::uint32_t>((stamp + ahead_us) % vel::kUsPerHour));
    if (position) packet[vel::kPpsOffset] = static_cast<std::byte>(vel::PpsStatus::kAbsent);
    return true;
  }
  return false;
}

bool FaultSink::write_ground_truth(HostTime stamp, const GroundTruthPose& pose) {
  return inner_.write_ground_truth(stamp, pose);
}

bool FaultSink::finish() {
  for (std::size_t i = 0; i < held_.size(); ++i) {
    if (!held_[i].held) continue;
    held_[i].held = false;
    // After everything else: the sink takes host times in order.
    if (!inner_.write_raw(static_cast<int>(i), last_host_time_, held_[i].bytes)) return false;
  }
  return true;
}

}  // namespace posed::sim
