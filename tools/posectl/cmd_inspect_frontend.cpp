// posectl inspect frontend FILE.mcap: runs a recording's cameras through posed's pipeline (the
// same decoders, clock sync, lidar-inertial estimator and camera front end as `posed --replay`,
// at full speed, without DDS) with the front end in all three modes at once, visible-only,
// thermal-only and fused, on the same frame events, and prints them side by side in the form of
// seed 001's Table 2 (features extracted, tracked, match success rate) with seed 000's lidar
// depth association and seed 002's image quality. --save-frames writes annotated mosaics,
// --timeline the figures of every frame; a simulated recording with a degraded colour view
// (the smoke scenario) also gets them before, during and after it.

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "daemon/config/config_loader.hpp"
#include "daemon/pipeline/frontend_config.hpp"
#include "daemon/pipeline/pipeline.hpp"
#include "daemon/pipeline/replay_sources.hpp"
#include "tools/posectl/commands.hpp"
#include "tools/posectl/frontend_depth_truth.hpp"
#include "tools/posectl/frontend_snapshots.hpp"
#include "tools/posectl/frontend_timeline.hpp"
#include "tools/posectl/terminal_progress.hpp"

namespace posed::posectl {
namespace {

constexpr vision::FrontendMode kModes[] = {
    vision::FrontendMode::kVisible, vision::FrontendMode::kThermal, vision::FrontendMode::kFused};

/// Per-frame mean of a total; "-" without frames.
std::string per_frame(std::uint64_t total, std::uint64_t frames) {
  if (frames == 0) return "-";
  char text[32];
  std::snprintf(text, sizeof text, "%.1f",
                static_cast<double>(total) / static_cast<double>(frames));
  return text;
}

std::string percent(double part, double whole) {
  if (whole <= 0) return "-";
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", 100.0 * part / whole);
  return text;
}

std::string number(double v, const char* format) {
  char text[32];
  std::snprintf(text, sizeof text, format, v);
  return text;
}

void print_table(const std::vector<const CameraFigures*>& columns,
                 const FrontendDepthTruth* truth) {
  std::printf("%-46s", "");
  for (const CameraFigures* c : columns) std::printf("%12s", std::string(c->mode).c_str());
  std::printf("\n");
  const auto row = [&](const char* name, auto cell) {
    std::printf("%-46s", name);
    for (const CameraFigures* c : columns) std::printf("%12s", cell(*c).c_str());
    std::printf("\n");
  };
  row("frames processed [1]", [](const CameraFigures& c) { return std::to_string(c.frames); });
  row("frames unusable [1]", [](const CameraFigures& c) {
    return std::to_string(c.frames_unusable + c.frames_without_imu);
  });
  row("features extracted / frame [1]",
      [](const CameraFigures& c) { return per_frame(c.extracted_total, c.frames); });
  row("features carried in / frame [1]",
      [](const CameraFigures& c) { return per_frame(c.previous_total, c.frames); });
  row("features tracked (RANSAC inliers) / frame [1]",
      [](const CameraFigures& c) { return per_frame(c.inliers_total, c.frames); });
  row("match success rate [%]", [](const CameraFigures& c) {
    return percent(static_cast<double>(c.inliers_total), static_cast<double>(c.previous_total));
  });
  row("features output / frame [1]",
      [](const CameraFigures& c) { return per_frame(c.features_total, c.frames); });
  row("with lidar depth / frame [1]",
      [](const CameraFigures& c) { return per_frame(c.depth_total, c.frames); });
  row("depth association [% of features]", [](const CameraFigures& c) {
    return percent(static_cast<double>(c.depth_total), static_cast<double>(c.features_total));
  });
  if (truth != nullptr) {
    const auto mode_of = [](const CameraFigures& c) {
      vision::FrontendMode mode = vision::FrontendMode::kFused;
      for (const vision::FrontendMode m : kModes) {
        if (vision::to_string(m) == c.mode) mode = m;
      }
      return mode;
    };
    const auto stats = [&](const CameraFigures& c) { return truth->stats(mode_of(c)); };
    row("lidar depth error vs truth, median [m]", [&](const CameraFigures& c) {
      const DepthErrorStats s = stats(c);
      return s.features > 0 ? number(s.median_abs_m, "%.3f") : std::string("-");
    });
    row("lidar depth error vs truth, p90 [m]", [&](const CameraFigures& c) {
      const DepthErrorStats s = stats(c);
      return s.features > 0 ? number(s.p90_abs_m, "%.3f") : std::string("-");
    });
    row("lidar depth bias vs truth, median [%]", [&](const CameraFigures& c) {
      const DepthErrorStats s = stats(c);
      return s.features > 0 ? number(100.0 * s.median_signed_relative, "%+.1f") : std::string("-");
    });
    row("lidar depth within 10 % of truth [%]", [&](const CameraFigures& c) {
      const DepthErrorStats s = stats(c);
      return s.features > 0 ? number(100.0 * s.within_10_percent, "%.1f") : std::string("-");
    });
    const auto tracks = [&](const CameraFigures& c) { return truth->track_stats(mode_of(c)); };
    // Track steps whose world point moved >= 2 px under the true motion (frontend_depth_truth.hpp)
    row("track steps judged vs truth [1]", [&](const CameraFigures& c) {
      const TrackTruthStats s = tracks(c);
      return s.steps > 0 ? number(static_cast<double>(s.steps), "%.0f") : std::string("-");
    });
    row("track error vs truth, median [px]", [&](const CameraFigures& c) {
      const TrackTruthStats s = tracks(c);
      return s.steps > 0 ? number(s.median_error_px, "%.2f") : std::string("-");
    });
    row("tracks following the world [%]", [&](const CameraFigures& c) {
      const TrackTruthStats s = tracks(c);
      return s.steps > 0 ? number(100.0 * s.with_world, "%.1f") : std::string("-");
    });
    row("tracks held still [%]", [&](const CameraFigures& c) {
      const TrackTruthStats s = tracks(c);
      return s.steps > 0 ? number(100.0 * s.held_still, "%.1f") : std::string("-");
    });
    row("verified tracks following the world [%]", [&](const CameraFigures& c) {
      const TrackTruthStats s = tracks(c);
      return s.verified_steps > 0 ? number(100.0 * s.verified_with_world, "%.1f")
                                  : std::string("-");
    });
    row("verified tracks held still [%]", [&](const CameraFigures& c) {
      const TrackTruthStats s = tracks(c);
      return s.verified_steps > 0 ? number(100.0 * s.verified_held_still, "%.1f")
                                  : std::string("-");
    });
  }
  const char* quality_names[3] = {"mean confidence, visible [0..1]",
                                  "mean confidence, thermal [0..1]",
                                  "mean confidence, fused [0..1]"};
  for (std::size_t i = 0; i < 3; ++i) {
    row(quality_names[i], [i](const CameraFigures& c) {
      return c.quality_frames[i] > 0 ? number(c.mean_confidence[i], "%.3f") : std::string("-");
    });
  }
}

}  // namespace

int run_inspect_frontend(int argc, char** argv) {
  CLI::App app{
      "Runs a recording's cameras through posed's pipeline (decoders, clock sync, lidar-inertial\n"
      "estimator, camera front end; full speed, no DDS) with the front end in all three modes on\n"
      "the same frames, and prints visible-only, thermal-only and fused side by side: features\n"
      "extracted and tracked, match success rate, lidar depth association, image quality.",
      "posectl inspect frontend"};
  std::string path, config_path, frames_dir, timeline_path;
  SnapshotOptions snapshots;
  app.add_option("FILE", path, "MCAP recording with visible and/or thermal frames")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("-c,--config", config_path,
                 "posed configuration (rig, front end); default: the built-in defaults, the rig "
                 "of config/posed.yaml")
      ->check(CLI::ExistingFile);
  app.add_option("--save-frames", snapshots.directory,
                 "write annotated PNG mosaics (visible, thermal, fusion, features) here");
  app.add_option("--every", snapshots.every_frames, "one mosaic per this many frames of a mode")
      ->check(CLI::PositiveNumber);
  app.add_option("--max-frames", snapshots.max_snapshots, "at most this many mosaics per mode");
  app.add_option("--timeline", timeline_path,
                 "write one CSV line per frame and mode here: time (true time since the start "
                 "for a posectl sim recording), features, confidence and gradient per stream");
  CLI11_PARSE(app, argc, argv);

  config::LoadResult loaded =
      config_path.empty() ? config::LoadResult{} : config::load_config_file(config_path);
  if (config_path.empty()) loaded.config = config::default_config();
  if (!loaded.ok()) {
    std::fprintf(stderr, "posectl inspect frontend: invalid configuration:\n%s",
                 loaded.error_text().c_str());
    return 2;
  }
  config::PosedConfig config = loaded.config;
  if (config.frontend.mode == "off") config.frontend.mode = "fused";

  pipeline::ReplayOptions replay_options;
  replay_options.path = path;
  replay_options.rate = 0;  // as fast as the pipeline goes: lossless and deterministic
  std::string error;
  pipeline::ReplaySources replay = pipeline::make_replay_sources(replay_options, error);
  if (!replay.built.sources.imu) {
    std::fprintf(stderr, "posectl inspect frontend: %s\n", error.c_str());
    return 1;
  }
  if (!replay.built.sources.visible && !replay.built.sources.thermal) {
    std::fprintf(stderr, "posectl inspect frontend: %s has no camera stream (found: %s)\n",
                 path.c_str(), replay.streams.c_str());
    return 1;
  }
  // The configured mode is the primary front end; the other two run beside it.
  std::string note;
  const fusion::CameraFrontEndConfig primary =
      pipeline::camera_front_end_config(config, replay.built.sources.visible != nullptr,
                                        replay.built.sources.thermal != nullptr, true, note);
  if (!note.empty()) std::fprintf(stderr, "posectl inspect frontend: %s\n", note.c_str());

  FrontendSnapshots observer(snapshots);
  // A simulated recording's world gives each feature's true depth.
  std::string truth_note;
  std::unique_ptr<FrontendDepthTruth> truth =
      FrontendDepthTruth::for_recording(path, config, truth_note);
  // A simulated recording whose colour view was degraded for a while (the smoke scenario): the
  // figures before, during and after it.
  FrontendTimeline timeline(timeline_path, sim_timing(path));
  if (!timeline.open(error)) {
    std::fprintf(stderr, "posectl inspect frontend: %s\n", error.c_str());
    return 1;
  }
  FrontendObservers observers;
  observers.add(&observer);
  observers.add(truth.get());
  observers.add(&timeline);
  pipeline::PipelineOutputs outputs;
  outputs.on_state = [](const NavState&, const Eigen::Isometry3d&) {};
  outputs.on_status = [](const pipeline::PipelineStatus&) {};
  for (const vision::FrontendMode m : kModes) {
    if (m != primary.frontend.mode) outputs.frontend_compare_modes.push_back(m);
  }
  outputs.frontend_observer = &observers;
  pipeline::Pipeline pipe(config, std::move(replay.built.sources), std::move(outputs));
  if (!pipe.start(error)) {
    std::fprintf(stderr, "posectl inspect frontend: %s\n", error.c_str());
    return 1;
  }
  std::fprintf(stderr, "posectl inspect frontend: replaying %s (%s)\n", path.c_str(),
               replay.streams.c_str());
  const auto started = std::chrono::steady_clock::now();
  {
    TerminalProgress progress;
    while (!pipe.finished()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      const double s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      char line[128];
      std::snprintf(line, sizeof line, "posectl inspect frontend: %llu frames processed in %.0f s",
                    static_cast<unsigned long long>(observer.frames()), s);
      progress.show(line);
    }
  }
  pipe.join();
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  const pipeline::PipelineStatus status = pipe.status();
  const std::vector<CameraFigures> others = pipe.camera_compare_figures();
  std::vector<const CameraFigures*> columns;
  for (const vision::FrontendMode m : kModes) {
    const std::string_view name = vision::to_string(m);
    if (status.estimator.camera.mode == name) columns.push_back(&status.estimator.camera);
    for (const CameraFigures& c : others) {
      if (c.mode == name) columns.push_back(&c);
    }
  }
  std::printf("camera front end on %s (%.1f s to run; config %s)\n", path.c_str(), elapsed_s,
              config_path.empty() ? "built-in defaults" : config_path.c_str());
  for (const auto& s : status.streams) {
    std::printf("  %-8s %llu decoded, %llu malformed, %llu dropped; clock %s\n", s.name.c_str(),
                static_cast<unsigned long long>(s.decoded),
                static_cast<unsigned long long>(s.malformed),
                static_cast<unsigned long long>(s.dropped), s.clock_state.c_str());
  }
  std::printf("  depth truth: %s\n\n",
              truth ? ("the simulator's world, " + truth->description()).c_str()
                    : ("none: " + truth_note).c_str());
  print_table(columns, truth.get());
  if (!timeline.finish()) {
    std::fprintf(stderr, "posectl inspect frontend: writing %s failed\n", timeline_path.c_str());
    return 1;
  }
  if (!timeline_path.empty()) std::printf("\nper-frame figures in %s\n", timeline_path.c_str());
  if (!snapshots.directory.empty()) {
    std::printf("\n%zu annotated frames in %s\n", observer.written().size(),
                snapshots.directory.c_str());
  }
  if (!observer.error().empty()) {
    std::fprintf(stderr, "posectl inspect frontend: %s\n", observer.error().c_str());
    return 1;
  }
  return 0;
}

}  // namespace posed::posectl
