// posectl sim: simulates the rig of config/posed.yaml driving through a scenario and writes what
// its sensors would have sent as a posed recording (MCAP: the raw channels a live recording has,
// plus the ground truth), and optionally the ground truth as a TUM file. docs/simulator.md.
// Exit codes: 0 ok, 1 the simulation or the recording failed, 2 bad arguments or config.

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "daemon/config/config_loader.hpp"
#include "drivers/recording/recorder.hpp"
#include "tools/posectl/commands.hpp"
#include "tools/sim/fault_sink.hpp"
#include "tools/sim/miscalibration.hpp"
#include "tools/sim/rig_config.hpp"
#include "tools/sim/scenarios.hpp"
#include "tools/sim/simulator.hpp"

namespace posed::posectl {
namespace {

/// The simulator's output into a posed recording, and the ground truth into a TUM file.
class RecorderSink : public sim::SimSink {
 public:
  RecorderSink(drivers::recording::Recorder& recorder, std::ofstream* tum, HostToWall to_wall)
      : recorder_(recorder), tum_(tum), to_wall_(to_wall) {}

  int add_stream(const sim::SimStream& s) override {
    const std::uint16_t id =
        recorder_.add_raw_channel(s.name, s.wire_format, s.metadata, s.source_channel);
    if (id == drivers::recording::Recorder::kInvalidChannel) return -1;
    ids_.push_back(id);
    channels_.push_back(s.source_channel);
    return static_cast<int>(ids_.size() - 1);
  }

  bool write_raw(int stream, HostTime host_time, std::span<const std::byte> bytes) override {
    const auto i = static_cast<std::size_t>(stream);
    const drivers::RawChunk chunk{bytes, host_time, channels_[i]};
    // The simulator runs faster than real time: when the writer thread falls behind, wait for
    // it instead of losing data (the Recorder's drop-newest policy is for live Sources).
    for (int tries = 0; !recorder_.record(ids_[i], chunk); ++tries) {
      if (tries > 20000) return false;  // 20 s without progress: the disk is gone
      ++waits_;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return true;
  }

  bool write_ground_truth(HostTime stamp, const sim::GroundTruthPose& pose) override {
    const Eigen::Vector3d& p = pose.p_map_base_m;
    const Eigen::Quaterniond& q = pose.q_map_base;
    const Eigen::Vector3d v_base = q.conjugate() * pose.v_map_mps;
    if (!recorder_.write_odometry(
            "/posed/ground_truth", to_wall_(stamp), "map", "base_link", {p.x(), p.y(), p.z()},
            {q.x(), q.y(), q.z(), q.w()}, {v_base.x(), v_base.y(), v_base.z()},
            {pose.w_base_radps.x(), pose.w_base_radps.y(), pose.w_base_radps.z()})) {
      return false;
    }
    if (tum_ != nullptr) {
      // Wall time, as posed stamps its DDS messages when replaying this recording (it applies the
      // recording's host-to-wall offset), so poses captured from DDS line up without an offset.
      const WallTime wall = to_wall_(stamp);
      char line[256];
      std::snprintf(line, sizeof line, "%lld.%09lld %.6f %.6f %.6f %.9f %.9f %.9f %.9f\n",
                    static_cast<long long>(wall.ns / 1'000'000'000),
                    static_cast<long long>(wall.ns % 1'000'000'000), p.x(), p.y(), p.z(), q.x(),
                    q.y(), q.z(), q.w());
      *tum_ << line;
      if (!*tum_) return false;
    }
    return true;
  }

  /// times record() refused because the writer's queue was full (each was retried)
  std::uint64_t waits() const { return waits_; }

 private:
  drivers::recording::Recorder& recorder_;
  std::ofstream* tum_;
  HostToWall to_wall_;
  std::vector<std::uint16_t> ids_;
  std::vector<std::uint32_t> channels_;
  std::uint64_t waits_ = 0;
};

}  // namespace

int run_sim(int argc, char** argv) {
  std::string scenarios;
  for (std::string_view n : sim::scenario_names())
    scenarios += (scenarios.empty() ? "" : ", ") + std::string(n);
  CLI::App app{
      "Simulates the rig of the config (VLP-32C, A9, D435i colour and optionally depth, PLUG 617 "
      "thermal) driving "
      "through a scenario and writes a posed recording: the sensors' raw bytes on the channels a "
      "live recording has, stamped with host arrival time, plus the ground truth (base_link in "
      "map) as nav_msgs/Odometry on /posed/ground_truth. Deterministic for a seed.\n"
      "Scenarios: " +
          scenarios + " (docs/simulator.md).",
      "posectl sim"};
  std::string scenario = "room", out_path, gt_path, config_path = "config/posed.yaml";
  double duration_s = 60.0;
  std::uint64_t seed = 1;
  bool no_cameras = false, no_lidar = false, no_noise = false, depth = false, rsimu = false;
  std::string thermal_format;
  app.add_option("--scenario", scenario, "world and drive: " + scenarios)->capture_default_str();
  app.add_option("--duration", duration_s, "simulated time [s]")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  app.add_option("--seed", seed, "seed: same seed, same bytes; another, another world")
      ->capture_default_str();
  std::uint64_t drive_seed_value = 0;
  CLI::Option* drive_seed_option = app.add_option(
      "--drive-seed", drive_seed_value,
      "drive the --seed world again on another path (localisation on a prior map): start, "
      "direction, line within the road and speeds from this seed; campus and street_night only "
      "(default: the drive --seed gives)");
  app.add_option("-o,--output", out_path, "recording to write (MCAP)")->required();
  app.add_option(
      "--gt", gt_path,
      "also write the ground truth as TUM (stamp [s, wall time as posed --replay stamps its "
      "poses] x y z qx qy qz qw)");
  app.add_option("--config", config_path, "the rig: extrinsics, rates, IMU noise, intrinsics")
      ->capture_default_str();
  app.add_flag("--no-cameras", no_cameras, "lidar and IMU only (cameras cost most of the time)");
  app.add_flag("--no-lidar", no_lidar, "no lidar");
  app.add_flag("--depth", depth,
               "also the D435i's Z16 depth stream (as config depth_camera.enabled: true)");
  app.add_flag("--realsense-imu", rsimu,
               "also the D435i's own IMU (accel 250 Hz, gyro 200 Hz as IIO HID records), the A9's "
               "backup (as config realsense_imu.enabled: true)");
  bool dynamic = false;
  app.add_flag("--dynamic", dynamic,
               "people walking beside the robot's path with it and against it, and on the street "
               "vehicles in the next lane, seen by every sensor (tools/sim/moving_objects.hpp); "
               "listed in the recording's metadata");
  app.add_option("--thermal-format", thermal_format,
                 "thermal output: y8 (8-bit video after AGC, as M2DGR) or y16 (raw counts); "
                 "default: the config's thermal_camera.format")
      ->check(CLI::IsMember({"y8", "y16"}));
  app.add_flag("--no-noise", no_noise, "ideal sensors: no noise, jitter or dropouts");
  bool miscalibrate = false;
  app.add_flag("--miscalibrate", miscalibrate,
               "simulate a rig off from what --config says, drawn from the seed: extrinsics by "
               "1 deg and 2 cm, camera latencies by 2-5 ms, IMU scale and axes by up to 0.5 % "
               "(tools/sim/miscalibration.hpp); listed in the recording's metadata");
  std::vector<std::string> fault_texts;
  app.add_option("--fault", fault_texts,
                 "a sensor fault KIND@START+DURATION (seconds of true time), repeatable: " +
                     sim::fault_kind_names() +
                     " (tools/sim/fault_sink.hpp); listed in the recording's metadata");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  std::vector<sim::Fault> faults;
  for (const std::string& text : fault_texts) {
    sim::Fault f;
    std::string e;
    if (!sim::parse_fault(text, f, e)) {
      std::fprintf(stderr, "posectl sim: --fault %s\n", e.c_str());
      return 2;
    }
    faults.push_back(f);
  }
  const config::LoadResult loaded = config::load_config_file(config_path);
  if (!loaded.ok()) {
    std::fprintf(stderr, "posectl sim: %s", loaded.error_text().c_str());
    return 2;
  }
  sim::SimRig rig = sim::rig_from_config(loaded.config);
  std::optional<sim::Miscalibration> miscalibration;
  if (miscalibrate) {
    miscalibration = sim::draw_miscalibration(seed);
    sim::apply_miscalibration(*miscalibration, rig);
  }
  if (thermal_format.empty()) thermal_format = loaded.config.thermal_camera.format;
  if (const auto f = sim::thermal_format_from_string(thermal_format)) {
    rig.thermal_format = *f;
  } else if (!no_cameras) {
    std::fprintf(stderr,
                 "posectl sim: thermal_camera.format %s: the simulator writes y8 or y16 "
                 "(--thermal-format)\n",
                 thermal_format.c_str());
    return 2;
  }
  sim::SimOptions options;
  options.scenario = scenario;
  options.duration_s = duration_s;
  options.seed = seed;
  if (drive_seed_option->count() > 0) {
    options.drive_seed = drive_seed_value;
  }
  options.lidar = !no_lidar;
  options.visible_camera = options.thermal_camera = !no_cameras;
  options.depth_camera = !no_cameras && (depth || loaded.config.depth_camera.enabled);
  options.realsense_imu = rsimu || loaded.config.realsense_imu.enabled;
  options.dynamic = dynamic;
  options.noise = !no_noise;
  std::string error;
  // Built here too for what the recording's metadata says of it (run_simulation builds its own).
  sim::SmokeSchedule smoke;
  {
    std::string e;
    const auto built =
        sim::make_scenario(scenario, seed, options.drive_seed, duration_s, rig.gravity_mps2, e);
    if (!built) {
      std::fprintf(stderr, "posectl sim: %s\n", e.c_str());
      return 2;
    }
    smoke = built->world.smoke;
  }

  const auto exact = [](double v) {  // round-trips through strtod
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", v);
    return std::string(text);
  };
  drivers::recording::RecorderOptions ropt;
  // A fixed host-to-wall offset (not the machine's clock) keeps the file a function of the seed.
  ropt.host_to_wall = HostToWall{Duration::from_ns(sim::kSimWallStartNs - options.host_epoch_ns)};
  // Chunks close when full, never on the writer thread's clock: the same seed writes the same
  // file, byte for byte.
  ropt.flush_interval = Duration::from_ns(0);
  // And messages go into the file in the order the simulator made them, not in the order the
  // writer thread happened to drain its queues.
  ropt.in_push_order = true;
  // How the run was made, so tools can rebuild its world (posectl inspect frontend measures
  // lidar depth against it) and a person can reproduce it.
  ropt.metadata[std::string(sim::kSimMetadataName)] = {
      {"scenario", scenario},
      {"seed", std::to_string(seed)},
      {"duration_s", exact(duration_s)},
      {"host_epoch_ns", std::to_string(options.host_epoch_ns)},
      {"gravity_mps2", exact(rig.gravity_mps2)},
      {"noise", options.noise ? "true" : "false"}};
  if (options.drive_seed) {
    // Only when given, so a recording without one keeps the bytes it always had.
    ropt.metadata[std::string(sim::kSimMetadataName)]["drive_seed"] =
        std::to_string(*options.drive_seed);
  }
  if (smoke.any()) {
    // When the colour camera's view was degraded, in true time since the start [s]: from the
    // first trace of smoke to the last, and the dense part (smoke.hpp).
    auto& md = ropt.metadata[std::string(sim::kSimMetadataName)];
    md["visible_degraded_from_s"] = exact(smoke.start_s);
    md["visible_degraded_to_s"] = exact(smoke.clear_s);
    md["smoke_dense_from_s"] = exact(smoke.dense_from_s);
    md["smoke_dense_to_s"] = exact(smoke.dense_to_s);
    md["smoke_extinction_per_m"] = exact(smoke.dense_extinction_per_m);
  }
  if (!faults.empty()) {
    // When each fault began and how long it lasted, in true time since the start [s].
    std::string list;
    for (const sim::Fault& f : faults) list += (list.empty() ? "" : ",") + sim::to_string(f);
    ropt.metadata[std::string(sim::kSimMetadataName)]["faults"] = list;
  }
  if (dynamic) {
    // Moving people and vehicles (their number; where they are follows from the seed).
    ropt.metadata[std::string(sim::kSimMetadataName)]["dynamic"] = "true";
  }
  if (miscalibration) {
    // How the simulated rig differs from the configured one (true = configured · error).
    ropt.metadata[std::string(sim::kSimMetadataName)]["miscalibration"] =
        miscalibration->describe();
  }
  drivers::recording::Recorder recorder;
  if (!recorder.open(out_path, ropt, error)) {
    std::fprintf(stderr, "posectl sim: %s\n", error.c_str());
    return 1;
  }
  std::ofstream tum;
  if (!gt_path.empty()) {
    tum.open(gt_path);
    if (!tum) {
      std::fprintf(stderr, "posectl sim: cannot write %s\n", gt_path.c_str());
      return 1;
    }
    tum << "# posectl sim --scenario " << scenario << " --seed " << seed;
    if (options.drive_seed) {
      tum << " --drive-seed " << *options.drive_seed;
    }
    tum << ": base_link in map; stamp = wall time [s] (the recording's log time + its "
           "host-to-wall offset, as posed --replay stamps DDS messages)\n";
  }
  RecorderSink sink(recorder, gt_path.empty() ? nullptr : &tum, ropt.host_to_wall);
  sim::SimSummary summary;
  const auto t0 = std::chrono::steady_clock::now();
  auto progress = [&](double done_s) {
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::fprintf(stderr, "\rposectl sim: %.0f / %.0f s simulated, %.2fx real time   ", done_s,
                 duration_s, done_s / std::max(wall, 1e-9));
    return true;
  };
  // The faults sit between the simulator and the file (seeded apart from the world's noise).
  sim::FaultSink faulted(sink, faults, options.host_epoch_ns, seed ^ 0x9e3779b97f4a7c15ull);
  sim::SimSink& out = faults.empty() ? static_cast<sim::SimSink&>(sink) : faulted;
  bool ok = sim::run_simulation(rig, options, out, summary, error, progress);
  if (ok && !faults.empty() && !faulted.finish()) {
    ok = false;
    error = "cannot write the recording";
  }
  std::fprintf(stderr, "\n");
  const bool closed = recorder.close();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!ok) {
    std::fprintf(stderr, "posectl sim: %s\n", error.c_str());
    return 1;
  }
  if (!closed) {
    std::fprintf(stderr, "posectl sim: %s\n", recorder.error().c_str());
    return 1;
  }
  const auto counters = recorder.counters();
  const std::string drive =
      options.drive_seed ? " drive seed " + std::to_string(*options.drive_seed) : std::string();
  std::printf(
      "posectl sim: %s seed %llu%s, %.1f s simulated in %.1f s (%.2fx real time), %llu boxes, "
      "loop %.0f m, driven %.0f m\n"
      "  lidar %llu packets (%llu rays, %.1f %% returns), %llu position packets; imu %llu frames; "
      "visible %llu frames; thermal %llu frames (%s); depth %llu frames; ground truth %llu "
      "poses\n"
      "  %s: %llu messages, %.1f MB%s%s\n",
      scenario.c_str(), static_cast<unsigned long long>(seed), drive.c_str(), duration_s, wall,
      duration_s / std::max(wall, 1e-9), static_cast<unsigned long long>(summary.boxes),
      summary.path_length_m, summary.distance_m,
      static_cast<unsigned long long>(summary.lidar_packets),
      static_cast<unsigned long long>(summary.lidar_rays),
      summary.lidar_rays > 0 ? 100.0 * static_cast<double>(summary.lidar_returns) /
                                   static_cast<double>(summary.lidar_rays)
                             : 0.0,
      static_cast<unsigned long long>(summary.position_packets),
      static_cast<unsigned long long>(summary.imu_frames),
      static_cast<unsigned long long>(summary.visible_frames),
      static_cast<unsigned long long>(summary.thermal_frames),
      std::string(sim::to_string(rig.thermal_format)).c_str(),
      static_cast<unsigned long long>(summary.depth_frames),
      static_cast<unsigned long long>(summary.ground_truth_poses), out_path.c_str(),
      static_cast<unsigned long long>(counters.messages_written),
      static_cast<double>(counters.bytes_on_disk) / 1e6, gt_path.empty() ? "" : "; ground truth ",
      gt_path.c_str());
  if (!summary.moving_objects.empty()) {
    std::printf("  moving  %s\n", summary.moving_objects.c_str());
  }
  if (options.realsense_imu) {
    std::printf("  D435i IMU  %llu accel and %llu gyro records\n",
                static_cast<unsigned long long>(summary.realsense_accel_records),
                static_cast<unsigned long long>(summary.realsense_gyro_records));
  }
  if (miscalibration) {
    std::printf("  miscalibrated rig  %s\n", miscalibration->describe().c_str());
  }
  for (const sim::Fault& f : faults) std::printf("  fault %s\n", sim::to_string(f).c_str());
  for (std::size_t i = 0; i < faulted.counts().size() && !faults.empty(); ++i) {
    const sim::FaultCounts& c = faulted.counts()[i];
    if (c.dropped + c.blanked + c.frozen + c.corrupted + c.duplicated + c.reordered + c.restamped ==
        0) {
      continue;
    }
    const sim::SimStream& st = faulted.streams()[i];
    std::printf(
        "    %s/%u: %llu dropped, %llu blanked, %llu frozen, %llu corrupted, %llu duplicated, "
        "%llu reordered, %llu restamped\n",
        st.name.c_str(), st.source_channel, static_cast<unsigned long long>(c.dropped),
        static_cast<unsigned long long>(c.blanked), static_cast<unsigned long long>(c.frozen),
        static_cast<unsigned long long>(c.corrupted), static_cast<unsigned long long>(c.duplicated),
        static_cast<unsigned long long>(c.reordered), static_cast<unsigned long long>(c.restamped));
  }
  if (smoke.any()) {
    std::printf(
        "  visible degraded (smoke) from %.1f s to %.1f s, dense from %.1f s to %.1f s "
        "(extinction %.2f /m, visibility %.1f m)\n",
        smoke.start_s, smoke.clear_s, smoke.dense_from_s, smoke.dense_to_s,
        smoke.dense_extinction_per_m, 3.0 / smoke.dense_extinction_per_m);
  }
  return 0;
}

}  // namespace posed::posectl
