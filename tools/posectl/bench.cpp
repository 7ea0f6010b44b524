#include "tools/posectl/bench.hpp"

#include <array>
#include <cstring>
#include <string_view>

#include "tools/posectl/commands.hpp"

namespace posed::posectl {

std::span<const Benchmark> benchmarks() {
  static const std::array kBenchmarks = {
      Benchmark{"queue", "SPSC queue: 64-byte items between two threads, throughput and latency",
                bench_queue},
      Benchmark{"imu", "A9 parser throughput; serial pty write -> decoded sample latency",
                bench_imu},
      Benchmark{"sync", "ClockSync: stamp error, re-lock and cost on simulated sensor clocks",
                bench_sync},
      Benchmark{"velodyne", "Velodyne decode rate and loopback UDP receive at 15k packets/s",
                bench_velodyne},
      Benchmark{"dds",
                "DDS odom 400 Hz publish -> receive latency and CPU, plain and DDS Security, two "
                "processes",
                bench_dds},
      Benchmark{"camera", "Camera decode per frame: YUYV->BGR, Z16, Y16 AGC, MJPEG (one core)",
                bench_camera},
      Benchmark{"sim",
                "Simulator real-time factor on one core: all sensors, lidar+IMU, cameras+IMU",
                bench_sim},
      Benchmark{"lio",
                "Lidar-inertial estimator per scan on one core, by step (simulated VLP-32C + A9)",
                bench_lio},
      Benchmark{"frontend", "Visual-thermal front end per frame pair on one core, by step",
                bench_frontend},
      Benchmark{"backend",
                "Cameras in the window per state on one core: frame motion, solve with and without",
                bench_backend},
      Benchmark{"recording", "MCAP write (lz4, one core) and read throughput on /dev/shm",
                bench_recording},
  };
  return kBenchmarks;
}

int run_bench(int argc, char** argv) {
  if (argc >= 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
    std::printf(
        "usage: posectl bench [NAME ...]\n\n"
        "Runs the named benchmarks (all when none is named) and prints one line per figure:\n"
        "  NAME METRIC VALUE UNIT\n\nbenchmarks:\n");
    for (const auto& b : benchmarks()) {
      std::printf("  %-10.*s %.*s\n", static_cast<int>(b.name.size()), b.name.data(),
                  static_cast<int>(b.summary.size()), b.summary.data());
    }
    return 0;
  }
  int failures = 0;
  bool matched_all = true;
  for (int i = 1; i < argc; ++i) {
    bool found = false;
    for (const auto& b : benchmarks()) found = found || b.name == argv[i];
    if (!found) {
      std::fprintf(stderr, "posectl bench: unknown benchmark '%s' (see --help)\n", argv[i]);
      matched_all = false;
    }
  }
  if (!matched_all) return 2;
  for (const auto& b : benchmarks()) {
    bool selected = argc < 2;
    for (int i = 1; i < argc; ++i) selected = selected || b.name == argv[i];
    if (!selected) continue;
    std::fprintf(stderr, "posectl bench: running %.*s ...\n", static_cast<int>(b.name.size()),
                 b.name.data());
    if (b.run() != 0) ++failures;
  }
  return failures == 0 ? 0 : 1;
}

}  // namespace posed::posectl
