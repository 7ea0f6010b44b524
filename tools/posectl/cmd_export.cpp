// posectl export FILE.mcap --tum OUT.txt: writes a pose channel (geometry_msgs/msg/PoseStamped
// or nav_msgs/msg/Odometry in CDR) as a TUM trajectory: one line per pose,
// `timestamp tx ty tz qx qy qz qw` with the header stamp in seconds [s] and positions in [m].

#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>
#include <vector>

#include "drivers/recording/mcap_reader.hpp"
#include "drivers/recording/ros2_messages.hpp"
#include "tools/posectl/commands.hpp"

namespace posed::posectl {

namespace rec = drivers::recording;

int run_export(int argc, char** argv) {
  CLI::App app{
      "Exports poses from an MCAP recording. --tum writes a TUM trajectory (timestamp [s], "
      "position [m],\nquaternion x y z w) from a PoseStamped or Odometry channel.",
      "posectl export"};
  std::string path, tum_path, topic;
  app.add_option("FILE", path, "MCAP recording")->required();
  app.add_option("--tum", tum_path, "TUM trajectory to write")->required();
  app.add_option("--topic", topic, "pose channel (needed when the file has more than one)");
  CLI11_PARSE(app, argc, argv);

  rec::McapReader reader;
  std::string error;
  if (!reader.open(path, error)) {
    std::fprintf(stderr, "posectl export: %s\n", error.c_str());
    return 1;
  }
  auto kind_of = [&](const rec::McapChannelRecord& c) -> int {
    const auto* s = reader.schema(c.schema_id);
    if (s == nullptr || c.message_encoding != rec::ros2::kMessageEncoding) return 0;
    if (s->name == rec::ros2::kPoseStampedName) return 1;
    if (s->name == rec::ros2::kOdometryName) return 2;
    return 0;
  };
  // With an intact summary the pose channels are known now; otherwise pick while scanning.
  if (topic.empty() && reader.summary().usable()) {
    std::vector<std::string> topics;
    for (const auto& [id, c] : reader.channels()) {
      if (kind_of(c) != 0) topics.push_back(c.topic);
    }
    if (topics.empty()) {
      std::fprintf(stderr, "posectl export: %s holds no PoseStamped/Odometry channel\n",
                   path.c_str());
      return 1;
    }
    if (topics.size() > 1) {
      std::fprintf(stderr, "posectl export: %s holds several pose channels; pick one with --topic:",
                   path.c_str());
      for (const auto& t : topics) std::fprintf(stderr, " %s", t.c_str());
      std::fprintf(stderr, "\n");
      return 2;
    }
    topic = topics.front();
  }
  std::FILE* out = std::fopen(tum_path.c_str(), "w");
  if (out == nullptr) {
    std::fprintf(stderr, "posectl export: cannot create %s\n", tum_path.c_str());
    return 1;
  }
  std::uint64_t written = 0, undecodable = 0;
  rec::McapMessage m;
  rec::ros2::StampedPose p;
  while (reader.next(m)) {
    const int kind = kind_of(*m.channel);
    if (kind == 0) continue;
    if (topic.empty()) topic = m.channel->topic;  // damaged file: the first pose channel
    if (m.channel->topic != topic) continue;
    const bool ok = kind == 1 ? rec::ros2::decode_pose_stamped(m.data, p)
                              : rec::ros2::decode_odometry(m.data, p);
    if (!ok) {
      ++undecodable;
      continue;
    }
    std::fprintf(out, "%lld.%09lld %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n",
                 static_cast<long long>(p.stamp.ns / 1'000'000'000),
                 static_cast<long long>(p.stamp.ns % 1'000'000'000), p.p_xyz_m[0], p.p_xyz_m[1],
                 p.p_xyz_m[2], p.q_xyzw[0], p.q_xyzw[1], p.q_xyzw[2], p.q_xyzw[3]);
    ++written;
  }
  const bool write_ok = std::fclose(out) == 0;
  std::fprintf(stderr, "posectl export: %llu poses from %s to %s (%llu undecodable)%s%s\n",
               static_cast<unsigned long long>(written), topic.c_str(), tum_path.c_str(),
               static_cast<unsigned long long>(undecodable),
               reader.complete() ? "" : "; recording damaged: ", reader.stop_reason().c_str());
  if (!write_ok) {
    std::fprintf(stderr, "posectl export: writing %s failed\n", tum_path.c_str());
    return 1;
  }
  return written > 0 ? 0 : 1;
}

}  // namespace posed::posectl
