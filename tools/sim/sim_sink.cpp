#include "tools/sim/sim_sink.hpp"

namespace posed::sim {

void HashSink::mix(const void* data, std::size_t size) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    hash_ ^= p[i];
    hash_ *= 0x100000001b3ull;
  }
}

int HashSink::add_stream(const SimStream& stream) {
  mix(stream.name.data(), stream.name.size());
  mix(stream.wire_format.data(), stream.wire_format.size());
  mix(&stream.source_channel, sizeof stream.source_channel);
  for (const auto& [k, v] : stream.metadata) {
    mix(k.data(), k.size());
    mix(v.data(), v.size());
  }
  messages_.push_back(0);
  return static_cast<int>(messages_.size() - 1);
}

bool HashSink::write_raw(int stream, HostTime host_time, std::span<const std::byte> bytes) {
  if (stream < 0 || static_cast<std::size_t>(stream) >= messages_.size()) return false;
  mix(&stream, sizeof stream);
  mix(&host_time.ns, sizeof host_time.ns);
  mix(bytes.data(), bytes.size());
  ++messages_[static_cast<std::size_t>(stream)];
  bytes_ += bytes.size();
  return true;
}

bool HashSink::write_ground_truth(HostTime stamp, const GroundTruthPose& pose) {
  mix(&stamp.ns, sizeof stamp.ns);
  mix(pose.p_map_base_m.data(), 3 * sizeof(double));
  mix(pose.q_map_base.coeffs().data(), 4 * sizeof(double));
  ++poses_;
  return true;
}

int MemorySink::add_stream(const SimStream& stream) {
  streams.push_back(stream);
  return static_cast<int>(streams.size() - 1);
}

bool MemorySink::write_raw(int stream, HostTime host_time, std::span<const std::byte> bytes) {
  messages.push_back({stream, host_time, {bytes.begin(), bytes.end()}});
  return true;
}

bool MemorySink::write_ground_truth(HostTime stamp, const GroundTruthPose& pose) {
  poses.push_back({stamp, pose});
  return true;
}

int MemorySink::find(const std::string& name, std::uint32_t source_channel) const {
  for (std::size_t i = 0; i < streams.size(); ++i)
    if (streams[i].name == name && streams[i].source_channel == source_channel)
      return static_cast<int>(i);
  return -1;
}

}  // namespace posed::sim
