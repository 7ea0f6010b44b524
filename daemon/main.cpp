// posed: the driver-to-pose daemon. Reads the configured sensors, fuses them, and publishes the
// robot's pose over DDS (ROS 2 types), as a systemd service or from a terminal.

#include <malloc.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <string>

#include "daemon/build_info.hpp"
#include "daemon/config/config_loader.hpp"
#include "daemon/pipeline/replay_sources.hpp"
#include "daemon/run_daemon.hpp"
#include "drivers/common/log.hpp"

int main(int argc, char** argv) noexcept try {
  // glibc gives each thread that allocates an arena of its own and keeps what is freed there:
  // posed's stage threads (new ones each --loop pass) made resident memory creep up although the
  // heap in use did not (30 passes of a 10 s recording: heap and stacks +18.7 %; with two arenas
  // +0.6 %). With two, a pass whose big allocators drew the other arena than the pass before
  // still held both arenas' worth (a 60 s recording looped at recorded timing for 10 minutes:
  // +21 % over the first minute); with one and the payload pools mapped apart, +9 %
  // (docs/faults.md, Endurance). The one lock every thread now allocates under cost the
  // odometry nothing measurable (docs/realtime.md, stop 45). Before any thread exists; an
  // explicit MALLOC_ARENA_MAX in the environment wins.
  if (std::getenv("MALLOC_ARENA_MAX") == nullptr) ::mallopt(M_ARENA_MAX, 1);
  // Blocks from 128 kB on (scans' point arrays, images, map messages) straight from the kernel
  // and back to it when freed, not the heap: glibc's default threshold rises to the largest block
  // freed, and megabyte blocks coming and going between long-lived small ones left freed pages
  // resident in the heap, more every minute (the 60 s recording looped at recorded timing for 10
  // minutes: +8.4 %; with this, flat). Costs +3.5 % of a core at recorded timing, and a
  // --max-speed replay 5.62x -> 4.75x (docs/faults.md, stop 46). MALLOC_MMAP_THRESHOLD_ or
  // GLIBC_TUNABLES in the environment win.
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (std::getenv("MALLOC_MMAP_THRESHOLD_") == nullptr &&
      (tunables == nullptr || std::strstr(tunables, "mmap_threshold") == nullptr)) {
    ::mallopt(M_MMAP_THRESHOLD, 128 * 1024);
  }
  posed::log::set_program_name("posed");
  CLI::App app{
      "posed: real-time driver-to-pose daemon. Reads the VLP-32C, D435i, PLUG 617 and A9 (or the\n"
      "synthetic IMU), puts every sample on the host clock, fuses them and publishes the pose on\n"
      "DDS topics rt/posed/odom, rt/posed/pose and rt/posed/status (ROS 2 types).\n"
      "SIGTERM or SIGINT drains and exits 0; a second one aborts.",
      "posed"};
  posed::RunOptions options;
  bool print_config = false;
  bool version = false;
  auto* config_option =
      app.add_option("-c,--config", options.config_path, "configuration file (YAML)")
          ->capture_default_str();
  app.add_flag("--print-config", print_config,
               "print the effective configuration with units, ranges and descriptions, then exit");
  app.add_option("--duration", options.duration_s,
                 "stop by itself after this long [s] (with --replay: replay this much of the "
                 "recording); 0 runs until SIGTERM/SIGINT or the end of the recording")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--record", options.record_path,
                 "record every sensor's raw bytes and the poses to this MCAP file");
  app.add_option("--record-outputs", options.record_outputs,
                 "with --record: which DDS outputs to record too, as ROS 2 (ros2msg/CDR) channels "
                 "Foxglove opens: comma-separated from tf, tf_static, path, diagnostics, status, "
                 "cloud, map, image; all; or none (a cloud is ~1.2 MB a scan)")
      ->capture_default_str();
  std::string save_map_path;
  auto* save_map =
      app.add_option("--save-map", save_map_path,
                     "at the end of the run (or on SIGTERM): a path ending in .pcd gets the "
                     "estimator's lidar map (binary PCD, x y z in the odometry frame [m]) and the "
                     "keyframe poses in FILE.keyframes.tum; any other path is a directory that "
                     "gets the loop-closed keyframe map (map.pcd, keyframes.tum, edges.txt, "
                     "scan_contexts.bin, map.yaml; docs/mapping.md) that --map loads");
  app.add_option("--map", options.prior_map_dir,
                 "localise on the keyframe map in this directory (written by --save-map DIR): "
                 "find the place by descriptor or from mapping.initial_* / rt/initialpose, then "
                 "track the map; rt/posed/pose and map -> odom are in the map's frame, and the "
                 "map is not grown")
      ->check(CLI::ExistingDirectory)
      ->excludes(save_map);
  auto* replay = app.add_option("--replay", options.replay.path,
                                "replay this MCAP recording through the same pipeline instead of "
                                "opening the sensors")
                     ->check(CLI::ExistingFile);
  bool max_speed = false;
  app.add_option("--rate", options.replay.rate,
                 "replay speed: 1 = recorded timing, N = N times faster")
      ->check(CLI::PositiveNumber)
      ->needs(replay);
  app.add_flag("--max-speed", max_speed,
               "replay as fast as the pipeline goes; lossless and deterministic")
      ->needs(replay);
  auto* live_stamps =
      app.add_flag("--live-stamps", options.replay.live_stamps,
                   "with --replay: at recorded timing, re-stamped onto this host's clock now, so "
                   "the replay looks live to every DDS subscriber (stamp-to-receive latency as on "
                   "the robot, with all four sensors) and the summary and status report posed's "
                   "own latency; raw recordings only (an imported ROS 1 topic keeps its header "
                   "stamps)")
          ->needs(replay);
  auto* loop =
      app.add_flag(
             "--loop", options.replay.loop,
             "replay the recording again and again, each pass from a fresh start (decoders, "
             "clock sync and estimator as on the first), its stamps continuing where the last "
             "pass ended; until SIGINT/SIGTERM or --passes")
          ->needs(replay);
  app.add_option("--passes", options.replay.max_passes,
                 "with --loop: stop after this many passes (0: until a signal)")
      ->needs(loop);
  app.add_option("--streams", options.replay.only_streams,
                 "with --replay: replay only these recorded streams, comma-separated (e.g. "
                 "imu,lidar for lidar-inertial odometry alone on a four-sensor recording, its "
                 "images never read); imu must be among them; default: every recorded stream")
      ->delimiter(',')
      ->check(CLI::IsMember({"imu", "lidar", "visible", "thermal", "depth", "realsense_imu"}))
      ->needs(replay);
  app.add_option("--start", options.replay.start_s, "skip this much of the recording [s]")
      ->check(CLI::NonNegativeNumber)
      ->needs(replay);
  app.add_flag("--recorded-config", options.replay.recorded_config,
               "with --replay: run with the configuration the recording was made with (posed "
               "--record and posectl record store it, with the lidar calibration file's text), as "
               "the robot ran; its dds section is replaced by --config's (this machine's "
               "network), or the defaults without --config")
      ->needs(replay);
  app.add_option("--wait-subscribers", options.wait_subscribers_s,
                 "before publishing, wait up to this long for a reader of rt/posed/odom or "
                 "rt/posed/pose to match, over DDS or a Foxglove client subscribed to /posed/odom "
                 "or /posed/pose [s]; default 1 with --replay, 0 live")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--version", version, "print the version and exit");
  CLI11_PARSE(app, argc, argv);
  if (live_stamps->count() > 0 && (max_speed || options.replay.rate != 1.0)) {
    std::fprintf(stderr,
                 "posed: --live-stamps replays at recorded timing: drop --max-speed and "
                 "--rate\n");
    return 2;
  }
  if (max_speed) options.replay.rate = 0;
  options.replay.duration_s = options.duration_s;
  if (!save_map_path.empty()) {
    (posed::is_map_directory_path(save_map_path) ? options.map_dir : options.map_path) =
        save_map_path;
  }

  if (version) {
    std::printf("%.*s\n", static_cast<int>(posed::version_string().size()),
                posed::version_string().data());
    return 0;
  }
  posed::config::LoadResult loaded;
  if (!options.replay.recorded_config) {
    loaded = posed::config::load_config_file(options.config_path);
  } else {
    // The recording's configuration, with this machine's DDS settings: --config's, or the
    // defaults when none was given (the robot's network settings rarely fit a laptop).
    std::string yaml, error;
    if (!posed::pipeline::read_recorded_config(options.replay.path, yaml, error)) {
      std::fprintf(stderr, "posed: %s\n", error.c_str());
      return 2;
    }
    loaded =
        posed::config::load_config_text(yaml, options.replay.path + " (recorded configuration)");
    if (config_option->count() > 0) {
      const auto local = posed::config::load_config_file(options.config_path);
      loaded.errors.insert(loaded.errors.begin(), local.errors.begin(), local.errors.end());
      loaded.config.dds = local.config.dds;
    } else {
      loaded.config.dds = posed::config::default_config().dds;
    }
  }
  if (!loaded.ok()) {
    std::fprintf(stderr, "posed: invalid configuration:\n%s", loaded.error_text().c_str());
    return 2;
  }
  if (print_config) {
    std::fputs(posed::config::print_config(loaded.config).c_str(), stdout);
    return 0;
  }
  return posed::run_daemon(loaded.config, options);
} catch (const std::exception& e) {
  std::fprintf(stderr, "posed: error: %s\n", e.what());
  return 1;
} catch (...) {
  std::fprintf(stderr, "posed: error: unknown exception\n");
  return 1;
}
