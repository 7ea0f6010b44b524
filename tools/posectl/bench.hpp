#pragma once
// Benchmarks behind `posectl bench [NAME ...]`. Each prints lines `NAME METRIC VALUE UNIT`
// (machine-readable, one figure per line) followed by nothing else on stdout.

#include <cstdio>
#include <span>
#include <string_view>

namespace posed::posectl {

/// Prints one figure: `bench metric value unit`.
inline void report(std::string_view bench, std::string_view metric, double value,
                   std::string_view unit) {
  std::printf("%.*s %.*s %.6g %.*s\n", static_cast<int>(bench.size()), bench.data(),
              static_cast<int>(metric.size()), metric.data(), value, static_cast<int>(unit.size()),
              unit.data());
  std::fflush(stdout);
}

struct Benchmark {
  std::string_view name;
  std::string_view summary;
  /// returns 0 on success; prints its figures with report()
  int (*run)();
};

std::span<const Benchmark> benchmarks();

int bench_queue();
int bench_imu();
int bench_sync();
int bench_velodyne();
int bench_dds();
int bench_camera();
int bench_recording();
int bench_sim();
int bench_lio();
int bench_frontend();
int bench_backend();

}  // namespace posed::posectl
