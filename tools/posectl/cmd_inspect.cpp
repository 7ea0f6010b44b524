// posectl inspect KIND FILE: decodes a raw capture of one sensor and prints one line per unit
// (frame, packet, ...) and a summary. Each kind is one row of kKinds; add yours there.

#include <CLI/CLI.hpp>
#include <array>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "core/sync/counter_unwrapper.hpp"
#include "drivers/imu/a9_protocol.hpp"
#include "tools/posectl/commands.hpp"

namespace posed::posectl {
namespace {

struct InspectKind {
  std::string_view name;
  std::string_view summary;
  /// argv[0] is the kind name; returns the exit code
  int (*run)(int argc, char** argv);
};

int inspect_a9(int argc, char** argv) {
  CLI::App app{
      "Decodes a raw Handsfree A9 serial capture (the bytes as read from the port):\n"
      "one line per frame (kind, offset, counter, values with units, CRC), then a summary.",
      "posectl inspect a9"};
  std::string path;
  bool summary_only = false;
  app.add_option("FILE", path, "raw serial bytes (e.g. `cat /dev/ttyUSB0 > a9.bin` in raw mode)")
      ->required();
  app.add_flag("-s,--summary-only", summary_only, "print only the summary");
  CLI11_PARSE(app, argc, argv);

  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "posectl inspect a9: cannot open %s: %s\n", path.c_str(),
                 std::strerror(errno));
    return 1;
  }
  drivers::a9::A9Decoder decoder;
  // The A9 counter: 32 bits of µs (core/sync, the same unwrapper ClockSync uses).
  auto unwrap = CounterUnwrapper::with_bits(32, Duration::from_us(1));
  std::int64_t first_ns = 0, last_ns = 0;
  std::uint64_t timed_frames = 0;

  auto on_event = [&](drivers::a9::DecodeStatus s, const drivers::a9::A9Frame& f) {
    using drivers::a9::DecodeStatus;
    using drivers::a9::FrameKind;
    if (s == DecodeStatus::kFrame) {
      const std::uint32_t counter =
          f.kind == FrameKind::kSensor ? f.sensor.counter_us : f.attitude.counter_us;
      if (f.kind == FrameKind::kSensor) {
        const std::int64_t t = unwrap.unwrap(counter).stamp.ns;
        if (timed_frames++ == 0) first_ns = t;
        last_ns = t;
      }
      if (summary_only) return;
      if (f.kind == FrameKind::kSensor) {
        const auto& x = f.sensor;
        std::printf(
            "sensor   offset=%llu counter=%u us gyro=[%.6g %.6g %.6g] rad/s "
            "accel=[%.6g %.6g %.6g] g mag=[%.6g %.6g %.6g] (device units) info=0x%08x crc=ok\n",
            static_cast<unsigned long long>(f.stream_offset), x.counter_us,
            static_cast<double>(x.gyro_radps[0]), static_cast<double>(x.gyro_radps[1]),
            static_cast<double>(x.gyro_radps[2]), static_cast<double>(x.accel_g[0]),
            static_cast<double>(x.accel_g[1]), static_cast<double>(x.accel_g[2]),
            static_cast<double>(x.mag[0]), static_cast<double>(x.mag[1]),
            static_cast<double>(x.mag[2]), x.frame_info);
      } else {
        const auto& a = f.attitude;
        std::printf(
            "attitude offset=%llu counter=%u us roll=%.6g deg pitch=%.6g deg yaw=%.6g deg "
            "info=0x%08x crc=ok\n",
            static_cast<unsigned long long>(f.stream_offset), a.counter_us,
            static_cast<double>(a.roll_deg), static_cast<double>(a.pitch_deg),
            static_cast<double>(a.yaw_deg), a.frame_info);
      }
      return;
    }
    if (summary_only) return;
    const auto& e = decoder.last_error();
    std::printf("%-8.*s offset=%llu len=0x%02x crc_stored=0x%04x crc_computed=0x%04x crc=bad\n",
                static_cast<int>(to_string(s).size()), to_string(s).data(),
                static_cast<unsigned long long>(e.stream_offset), e.len, e.crc_stored,
                e.crc_computed);
  };

  std::vector<std::uint8_t> buf(1 << 16);
  drivers::a9::A9Frame frame;
  while (in) {
    in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(buf.size()));
    std::span<const std::uint8_t> chunk(buf.data(), static_cast<std::size_t>(in.gcount()));
    for (drivers::a9::DecodeStatus s;
         (s = decoder.next(chunk, frame)) != drivers::a9::DecodeStatus::kNeedMore;) {
      on_event(s, frame);
    }
  }
  for (drivers::a9::DecodeStatus s;
       (s = decoder.finish(frame)) != drivers::a9::DecodeStatus::kNeedMore;) {
    on_event(s, frame);
  }

  const auto& c = decoder.counters();
  const double span_s = static_cast<double>(last_ns - first_ns) * 1e-9;
  const double rate_hz =
      timed_frames > 1 && span_s > 0 ? static_cast<double>(timed_frames - 1) / span_s : 0.0;
  std::printf(
      "summary: bytes=%llu frames=%llu (sensor=%llu attitude=%llu) rate=%.2f Hz (sensor, device "
      "counter) skipped_bytes=%llu bad_crc=%llu truncated=%llu unknown_kind=%llu\n",
      static_cast<unsigned long long>(decoder.stream_position()),
      static_cast<unsigned long long>(c.frames_ok),
      static_cast<unsigned long long>(c.sensor_frames),
      static_cast<unsigned long long>(c.frames_ok - c.sensor_frames), rate_hz,
      static_cast<unsigned long long>(c.skipped_bytes), static_cast<unsigned long long>(c.bad_crc),
      static_cast<unsigned long long>(c.truncated),
      static_cast<unsigned long long>(c.unknown_kind));
  return 0;
}

// One row per sensor kind. Keep it a plain table: other drivers add their row here.
constexpr std::array kKinds = {
    InspectKind{"a9", "Handsfree A9 IMU raw serial bytes", inspect_a9},
    InspectKind{"velodyne", "Velodyne VLP-32C/VLP-16/HDL-32E pcap or pcapng", run_inspect_velodyne},
    InspectKind{"mcap", "MCAP recording: channels, counts, rates, gaps, errors", run_inspect_mcap},
    InspectKind{"frontend",
                "camera front end on a recording: visible, thermal and fused side by side",
                run_inspect_frontend},
    InspectKind{"camera", "cameras: --list (V4L2, GenICam), or capture N frames to PNG",
                run_inspect_camera},
};

void print_usage(std::FILE* out) {
  std::fprintf(out,
               "usage: posectl inspect KIND FILE [options]\n"
               "       posectl inspect FILE.mcap [options]   (same as: posectl inspect mcap FILE)\n"
               "       posectl inspect KIND --help\n\n"
               "Decodes a raw capture and prints one line per frame/packet, then a summary.\n\n"
               "kinds:\n");
  for (const auto& k : kKinds) {
    std::fprintf(out, "  %-10.*s %.*s\n", static_cast<int>(k.name.size()), k.name.data(),
                 static_cast<int>(k.summary.size()), k.summary.data());
  }
}

}  // namespace

int run_inspect(int argc, char** argv) {
  if (argc < 2) {
    print_usage(stderr);
    return 2;
  }
  const std::string_view kind = argv[1];
  if (kind == "--help" || kind == "-h") {
    print_usage(stdout);
    return 0;
  }
  for (const auto& k : kKinds) {
    if (k.name == kind) return k.run(argc - 1, argv + 1);
  }
  // `posectl inspect FILE.mcap`: a recording needs no kind; argv[1] is then its FILE.
  if (kind.size() > 5 && kind.substr(kind.size() - 5) == ".mcap") {
    return run_inspect_mcap(argc, argv);
  }
  std::fprintf(stderr, "posectl inspect: unknown kind '%s'\n\n", argv[1]);
  print_usage(stderr);
  return 2;
}

}  // namespace posed::posectl
