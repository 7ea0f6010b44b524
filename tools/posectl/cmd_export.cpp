// posectl export FILE.mcap --tum OUT.txt: writes a pose channel (geometry_msgs/msg/PoseStamped
// or nav_msgs/msg/Odometry in CDR) as a TUM trajectory: one line per pose,
// `timestamp tx ty tz qx qy qz qw` with the header stamp in seconds [s] and positions in [m].
// posectl export FILE.mcap --pcd MAP.pcd: replays the recording's raw sensor channels through
// posed's own pipeline at full speed (deterministic, no DDS) and writes the lidar map and its
// keyframe poses (daemon/run_daemon.hpp, --save-map).

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "daemon/config/config_loader.hpp"
#include "daemon/run_daemon.hpp"
#include "drivers/recording/map_files.hpp"
#include "drivers/recording/mcap_reader.hpp"
#include "drivers/recording/ros2_messages.hpp"
#include "tools/posectl/commands.hpp"

namespace posed::posectl {

namespace rec = drivers::recording;

namespace {

/// Replays `path` through the daemon's pipeline without DDS and saves the map.
int export_map(const std::string& path, const std::string& config_path, const std::string& pcd_path,
               const std::string& map_dir) {
  config::LoadResult loaded =
      config_path.empty() ? config::LoadResult{} : config::load_config_file(config_path);
  if (config_path.empty()) loaded.config = config::default_config();
  if (!loaded.ok()) {
    std::fprintf(stderr, "posectl export: invalid configuration:\n%s", loaded.error_text().c_str());
    return 2;
  }
  RunOptions options;
  options.replay.path = path;
  options.replay.rate = 0;  // max speed: lossless and deterministic
  options.map_path = pcd_path;
  options.map_dir = map_dir;
  options.publish_dds = false;
  std::fprintf(stderr,
               "posectl export: replaying %s through posed's pipeline to build the map...\n",
               path.c_str());
  return run_daemon(loaded.config, options);
}

}  // namespace

/// posed's optimised poses in its recordings
constexpr const char* kPosedPoseTopic = "/posed/pose";

int run_export(int argc, char** argv) {
  CLI::App app{
      "Exports from an MCAP recording.\n  --tum: a TUM trajectory (timestamp [s], position [m], "
      "quaternion x y z w) from a PoseStamped\n         or Odometry channel in the file.\n"
      "  --pcd: the lidar map, built by replaying the raw lidar and IMU channels through posed's\n"
      "         pipeline at full speed (no DDS): a binary PCD (x y z [m], map frame) and the\n"
      "         keyframe poses next to it (MAP.keyframes.tum).\n"
      "  --map-dir: the loop-closed keyframe map, built the same way, as a directory posed --map\n"
      "         loads (docs/mapping.md).",
      "posectl export"};
  std::string path, tum_path, pcd_path, map_dir, topic, config_path;
  app.add_option("FILE", path, "MCAP recording")->required()->check(CLI::ExistingFile);
  app.add_option("--tum", tum_path, "TUM trajectory to write");
  app.add_option("--topic", topic,
                 "pose channel for --tum; default: the only one, or posed's /posed/pose in a posed "
                 "recording (which also holds /posed/odom)");
  app.add_option("--pcd", pcd_path, "map to write (PCD)");
  app.add_option("--map-dir", map_dir,
                 "loop-closed keyframe map to write to this directory, as posed --save-map DIR "
                 "(what posed --map DIR loads; docs/mapping.md)");
  app.add_option("-c,--config", config_path,
                 "posed configuration for --pcd (rig, estimator); default: the built-in defaults, "
                 "the rig of config/posed.yaml")
      ->check(CLI::ExistingFile);
  CLI11_PARSE(app, argc, argv);
  if (tum_path.empty() && pcd_path.empty() && map_dir.empty()) {
    std::fprintf(stderr,
                 "posectl export: nothing to do: give --tum OUT.txt, --pcd MAP.pcd and/or "
                 "--map-dir DIR\n");
    return 2;
  }
  if (!pcd_path.empty() || !map_dir.empty()) {
    const int rc = export_map(path, config_path, pcd_path, map_dir);
    if (rc != 0 || tum_path.empty()) return rc;
  }

  rec::McapReader reader;
  std::string error;
  if (!reader.open(path, error)) {
    std::fprintf(stderr, "posectl export: %s\n", error.c_str());
    return 1;
  }
  // 1: PoseStamped, 2: Odometry, 0: not a pose channel
  const auto kind_of = [](const rec::McapReader& r, const rec::McapChannelRecord& c) -> int {
    const auto* s = r.schema(c.schema_id);
    if (s == nullptr || c.message_encoding != rec::ros2::kMessageEncoding) return 0;
    if (s->name == rec::ros2::kPoseStampedName) return 1;
    if (s->name == rec::ros2::kOdometryName) return 2;
    return 0;
  };
  if (topic.empty()) {
    // The pose channels: from the summary, or, in a file cut short, by reading it through once.
    rec::McapReader listing;
    if (!listing.open(path, error)) {
      std::fprintf(stderr, "posectl export: %s\n", error.c_str());
      return 1;
    }
    if (!listing.summary().usable()) {
      rec::McapMessage skipped;
      while (listing.next(skipped)) {
      }
    }
    std::vector<std::string> topics;
    for (const auto& [id, c] : listing.channels()) {
      if (kind_of(listing, c) != 0) topics.push_back(c.topic);
    }
    if (topics.empty()) {
      std::fprintf(stderr, "posectl export: %s holds no PoseStamped/Odometry channel\n",
                   path.c_str());
      return 1;
    }
    // A posed recording holds its optimised poses and its IMU-rate odometry: the poses are what
    // a trajectory is evaluated on (--topic /posed/odom for the other).
    const bool has_posed_poses =
        std::find(topics.begin(), topics.end(), kPosedPoseTopic) != topics.end();
    if (topics.size() > 1 && !has_posed_poses) {
      std::fprintf(stderr, "posectl export: %s holds several pose channels; pick one with --topic:",
                   path.c_str());
      for (const auto& t : topics) std::fprintf(stderr, " %s", t.c_str());
      std::fprintf(stderr, "\n");
      return 2;
    }
    topic = topics.size() > 1 ? std::string(kPosedPoseTopic) : topics.front();
  }
  std::FILE* out = std::fopen(tum_path.c_str(), "w");
  if (out == nullptr) {
    std::fprintf(stderr, "posectl export: cannot create %s\n", tum_path.c_str());
    return 1;
  }
  std::uint64_t written = 0, undecodable = 0, out_of_order = 0;
  std::optional<std::int64_t> last_stamp_ns;
  rec::McapMessage m;
  rec::ros2::StampedPose p;
  while (reader.next(m)) {
    const int kind = kind_of(reader, *m.channel);
    if (kind == 0) continue;
    if (m.channel->topic != topic) continue;
    const bool ok = kind == 1 ? rec::ros2::decode_pose_stamped(m.data, p)
                              : rec::ros2::decode_odometry(m.data, p);
    if (!ok) {
      ++undecodable;
      continue;
    }
    // A TUM trajectory's stamps increase (posectl eval refuses it otherwise). Recordings from
    // before posed kept /posed/pose in order could carry a first pose stamped after the second.
    if (last_stamp_ns && p.stamp.ns <= *last_stamp_ns) {
      ++out_of_order;
      continue;
    }
    last_stamp_ns = p.stamp.ns;
    const std::string line =
        rec::tum_line(p.stamp.ns, Eigen::Vector3d(p.p_xyz_m[0], p.p_xyz_m[1], p.p_xyz_m[2]),
                      Eigen::Quaterniond(p.q_xyzw[3], p.q_xyzw[0], p.q_xyzw[1], p.q_xyzw[2]));
    std::fputs(line.c_str(), out);
    ++written;
  }
  const bool write_ok = std::fclose(out) == 0;
  std::fprintf(stderr,
               "posectl export: %llu poses from %s to %s (%llu undecodable, %llu left out: "
               "stamped no later than the pose before)%s%s\n",
               static_cast<unsigned long long>(written), topic.c_str(), tum_path.c_str(),
               static_cast<unsigned long long>(undecodable),
               static_cast<unsigned long long>(out_of_order),
               reader.complete() ? "" : "; recording damaged: ", reader.stop_reason().c_str());
  if (!write_ok) {
    std::fprintf(stderr, "posectl export: writing %s failed\n", tum_path.c_str());
    return 1;
  }
  return written > 0 ? 0 : 1;
}

}  // namespace posed::posectl
