// posectl replay FILE.mcap: hardware-in-the-loop re-emission (docs/recording.md). The recorded
// Velodyne packets go back out as UDP datagrams and the A9 byte stream onto a pseudo-terminal,
// at their recorded times (tools/hil), so a live posed (or any Velodyne or serial driver)
// receives them as from the sensors. Progress once a second; a summary with packets and bytes
// per output and how late they left (p50/p99/max).
// Exit codes: 0 sent, 1 the recording or an output failed, 2 bad arguments.

#include <CLI/CLI.hpp>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>

#include "drivers/common/host_clock.hpp"
#include "tools/hil/hil_replay.hpp"
#include "tools/posectl/commands.hpp"
#include "tools/posectl/stop_signals.hpp"
#include "tools/posectl/terminal_progress.hpp"

namespace posed::posectl {
namespace {

double ms(Duration d) { return static_cast<double>(d.ns) * 1e-6; }

std::string lateness_text(const hil::LatenessHistogram& h) {
  if (h.count() == 0) return "no messages";
  char buf[160];
  std::snprintf(buf, sizeof buf, "p50 %.3f ms, p99 %.3f ms, max %.3f ms", ms(h.quantile(0.5)),
                ms(h.quantile(0.99)), ms(h.max()));
  return buf;
}

}  // namespace

int run_replay(int argc, char** argv) {
  CLI::App app{
      "Hardware-in-the-loop replay: re-emits a recording's raw sensor data onto real interfaces "
      "with its recorded timing, so a live posed (or any Velodyne or serial driver) receives it "
      "as from the sensors.\n"
      "  Velodyne data packets   -> UDP datagrams to HOST:PORT (default 127.0.0.1:2368)\n"
      "  Velodyne position       -> UDP datagrams to HOST:POSITION_PORT (default 8308)\n"
      "  A9 serial byte stream   -> a pseudo-terminal in raw mode, symlinked at --pty PATH\n"
      "  D435i IMU (IIO records) -> IIO devices under --iio DIR, as the kernel lists them\n"
      "Messages are paced against an absolute schedule from their log times (lateness does not "
      "accumulate); how late each left is measured and reported. The live side's config names "
      "the same port (lidar.source: udp, lidar.data_port, lidar.address: the sender, e.g. "
      "127.0.0.1) and imu.serial_device: PATH (and realsense_imu.sysfs_root: DIR/sys, "
      "realsense_imu.dev_dir: DIR/dev).",
      "posectl replay"};
  std::string path, udp_text = "127.0.0.1:2368,8308", pty_link, iio_dir;
  double rate = 1.0, start_s = 0, duration_s = 0, wait_reader_s = 10;
  bool loop = false, no_udp = false, no_pty = false;
  app.add_option("FILE", path, "MCAP recording (posed --record, posectl record, posectl sim)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--udp", udp_text,
                 "where the lidar packets go: HOST:PORT[,POSITION_PORT] (position default 8308)")
      ->capture_default_str();
  app.add_option("--pty", pty_link,
                 "symlink to the pseudo-terminal carrying the A9 stream, e.g. /tmp/posed-a9 "
                 "(default: no link; the pty's own /dev/pts name is printed)");
  app.add_option("--iio", iio_dir,
                 "also re-emit the D435i's IMU (a recording's realsense_imu stream): DIR/sys/"
                 "iio:deviceN (accel_3d, gyro_3d) as the kernel's HID sensor drivers list them, "
                 "and DIR/dev/iio:deviceN as FIFOs carrying the records (default: not sent)");
  app.add_option("--rate", rate, "speed: 1 = recorded timing, 2 = twice as fast")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_flag("--loop", loop, "start again at the end, until SIGINT/SIGTERM");
  app.add_option("--start", start_s, "skip this much of the recording [s]")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--duration", duration_s, "send this much of the recording; 0 = all [s]")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--wait-reader", wait_reader_s,
                 "before sending, wait up to this long for a process to open the pty (start the "
                 "driver under test first); 0 = start at once [s]")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  std::vector<std::string> fault_texts;
  app.add_option("--fault", fault_texts,
                 "a transport fault KIND[:OUTPUT]@START+DURATION (seconds of the recording since "
                 "its first message), repeatable: drop, corrupt, duplicate, delay, unplug (the "
                 "pty); OUTPUT lidar, imu or all (tools/hil/hil_faults.hpp)");
  app.add_flag("--no-udp", no_udp, "do not send the lidar packets");
  app.add_flag("--no-pty", no_pty, "do not send the A9 stream");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  hil::HilReplayOptions options;
  std::string error;
  if (!hil::parse_udp_target(udp_text, options.udp, error)) {
    std::fprintf(stderr, "posectl replay: --udp %s\n", error.c_str());
    return 2;
  }
  options.rate = rate;
  options.pty_link = pty_link;
  options.iio_dir = iio_dir;
  options.playlist.iio = !iio_dir.empty();
  options.playlist.path = path;
  options.playlist.start = Duration::from_seconds(start_s);
  options.playlist.duration = Duration::from_seconds(duration_s);
  options.playlist.loop = loop;
  options.playlist.udp = !no_udp;
  options.playlist.serial = !no_pty;
  for (const std::string& text : fault_texts) {
    hil::HilFault fault;
    if (!hil::parse_hil_fault(text, fault, error)) {
      std::fprintf(stderr, "posectl replay: --fault %s\n", error.c_str());
      return 2;
    }
    options.faults.push_back(fault);
  }

  // Before the sending thread exists, so it inherits the blocked mask.
  StopSignals signals;
  hil::HilReplay replay(options);
  if (!replay.open(error)) {
    std::fprintf(stderr, "posectl replay: %s\n", error.c_str());
    return 1;
  }
  std::fprintf(stderr, "posectl replay: %s at rate %g%s\n", path.c_str(), rate,
               loop ? ", looping" : "");
  std::string pty_name;
  if (replay.pty() != nullptr) {
    pty_name = replay.pty()->slave_path();
    if (!pty_link.empty()) pty_name = pty_link + " -> " + pty_name;
  }
  for (const hil::HilChannel& c : replay.playlist().channels()) {
    std::string where;
    if (!c.sent) {
      where = c.output == hil::HilOutput::kNone ? "not sent (no HIL output for this wire format)"
                                                : "not sent (switched off)";
    } else if (c.output == hil::HilOutput::kSerial) {
      where = "pty " + pty_name;
    } else if (c.output == hil::HilOutput::kIio) {
      where = "iio " + iio_dir;
    } else {
      where = "udp " + replay.udp()->destination(c.output == hil::HilOutput::kUdpData ? 0 : 1);
    }
    std::fprintf(stderr, "  %-22s %-22s -> %s\n", c.topic.c_str(), c.wire_format.c_str(),
                 where.c_str());
  }

  std::atomic<bool> waiting{false};
  bool reader_found = true;
  const bool wait_for_reader = replay.pty() != nullptr && wait_reader_s > 0;
  std::thread sender([&] {
    if (wait_for_reader) {
      waiting.store(true);
      reader_found =
          replay.pty()->wait_for_reader(Duration::from_seconds(wait_reader_s), replay.stop_flag());
      waiting.store(false);
    }
    replay.run();
  });
  if (wait_for_reader) {
    std::fprintf(stderr, "posectl replay: waiting up to %.0f s for a reader to open %s\n",
                 wait_reader_s, pty_name.c_str());
  }

  const HostTime started = drivers::host_now();
  TerminalProgress progress;
  std::string stopped_by = "the end of the recording";
  bool stopping = false;
  HostTime last_report = started;
  for (;;) {
    const int sig = signals.wait(Duration::from_ms(200));
    if (sig != 0) {
      if (stopping) {
        std::fprintf(stderr, "\nposectl replay: second %s: exiting at once\n", strsignal(sig));
        std::_Exit(128 + sig);
      }
      stopping = true;
      stopped_by = strsignal(sig);
      replay.request_stop();
    }
    const hil::HilReplayStatus s = replay.status();
    if (s.finished) break;
    const HostTime now = drivers::host_now();
    if (stopping || now - last_report < Duration::from_s(1)) continue;
    last_report = now;
    if (!s.started) {
      if (waiting.load()) {
        progress.show("posectl replay: waiting for a reader on " + pty_name + " (" +
                      std::to_string(static_cast<int>((now - started).seconds())) + " s)");
      }
      continue;
    }
    hil::LatenessHistogram all;
    for (const auto& h : s.lateness) all.merge(h);
    const std::int64_t end = s.end_log_ns;
    const double done_s = static_cast<double>(s.last_log_ns - s.anchor_log_ns) * 1e-9;
    char line[512];
    std::snprintf(
        line, sizeof line,
        "posectl replay: %.1f s%s | lidar %llu pkts %.2f MB | position %llu pkts | "
        "imu %llu writes %.3f MB | late p99 %.3f ms max %.3f ms",
        done_s,
        end > 0 && !loop
            ? (" / " +
               std::to_string(static_cast<int>(static_cast<double>(end - s.anchor_log_ns) * 1e-9)) +
               " s")
                  .c_str()
            : "",
        static_cast<unsigned long long>(s.udp_data.datagrams), megabytes(s.udp_data.bytes),
        static_cast<unsigned long long>(s.udp_position.datagrams),
        static_cast<unsigned long long>(s.pty.writes), megabytes(s.pty.bytes),
        ms(all.quantile(0.99)), ms(all.max()));
    progress.show(line);
  }
  sender.join();
  progress.finish();
  const double run_s = (drivers::host_now() - started).seconds();
  const hil::HilReplayStatus s = replay.status();

  std::printf("\nposectl replay summary\n");
  std::printf("  replayed            %s at rate %g, %.1f s of log time in %.1f s, %llu pass%s\n",
              path.c_str(), rate,
              s.started ? static_cast<double>(s.last_log_ns - s.anchor_log_ns) * 1e-9 : 0.0, run_s,
              static_cast<unsigned long long>(s.passes + (s.started ? 1 : 0)),
              s.passes == 0 ? "" : "es");
  std::printf("  stopped by          %s\n", stopped_by.c_str());
  const auto slot = [](hil::HilOutput o) {
    for (std::size_t i = 0; i < hil::kHilOutputs.size(); ++i) {
      if (hil::kHilOutputs[i] == o) return i;
    }
    return std::size_t{0};
  };
  bool failed = false;
  if (replay.udp() != nullptr) {
    const std::pair<const char*, const hil::UdpChannelCounters*> rows[] = {
        {"udp data", &s.udp_data}, {"udp position", &s.udp_position}};
    for (std::uint32_t ch = 0; ch < 2; ++ch) {
      const auto& c = *rows[ch].second;
      const auto& h =
          s.lateness[slot(ch == 0 ? hil::HilOutput::kUdpData : hil::HilOutput::kUdpPosition)];
      std::printf("  %-19s %llu packets, %.3f MB to %s, %llu failed; lateness %s\n", rows[ch].first,
                  static_cast<unsigned long long>(c.datagrams), megabytes(c.bytes),
                  replay.udp()->destination(ch).c_str(), static_cast<unsigned long long>(c.failed),
                  lateness_text(h).c_str());
      failed = failed || c.failed > 0;
    }
    if (!replay.udp()->last_error().empty()) {
      std::printf("  udp error           %s\n", replay.udp()->last_error().c_str());
    }
  }
  if (replay.pty() != nullptr) {
    std::printf(
        "  pty                 %llu writes, %.3f MB to %s; %llu B discarded without a reader, "
        "%llu B overrun; lateness %s\n",
        static_cast<unsigned long long>(s.pty.writes), megabytes(s.pty.bytes), pty_name.c_str(),
        static_cast<unsigned long long>(s.pty.bytes_no_reader),
        static_cast<unsigned long long>(s.pty.bytes_overrun),
        lateness_text(s.lateness[slot(hil::HilOutput::kSerial)]).c_str());
    if (!reader_found) {
      std::printf("  pty reader          none opened %s within %.0f s; sent regardless\n",
                  pty_name.c_str(), wait_reader_s);
    }
  }
  if (replay.iio() != nullptr) {
    std::printf(
        "  iio                 %llu writes, %.3f MB to %s/dev; %llu B dropped (FIFO full); "
        "lateness %s\n",
        static_cast<unsigned long long>(s.iio.writes), megabytes(s.iio.bytes), iio_dir.c_str(),
        static_cast<unsigned long long>(s.iio.bytes_dropped),
        lateness_text(s.lateness[slot(hil::HilOutput::kIio)]).c_str());
  }
  hil::LatenessHistogram all;
  for (const auto& h : s.lateness) all.merge(h);
  std::printf("  lateness (all)      %s over %llu messages, %llu later than 100 ms\n",
              lateness_text(all).c_str(), static_cast<unsigned long long>(all.count()),
              static_cast<unsigned long long>(all.overflow()));
  HostToWall recorded{};
  if (s.started && rate == 1.0 && replay.playlist().recorded_host_to_wall(recorded)) {
    // live wall = host + (wall - host now); recorded wall = log + recorded offset. At rate 1 the
    // two differ by a constant over the first pass: what a comparison with the recording's
    // ground truth must subtract (posectl eval --offset).
    const Duration live_offset = drivers::wall_now() - WallTime::from_ns(drivers::host_now().ns);
    const std::int64_t shift_ns =
        (s.anchor_host.ns - s.anchor_log_ns) + live_offset.ns - recorded.wall_minus_host.ns;
    std::printf(
        "  time shift          %+.9f s: live wall time = recorded wall time + shift (first "
        "pass); posectl eval --offset %.9f compares live poses with the recording's truth\n",
        static_cast<double>(shift_ns) * 1e-9, -static_cast<double>(shift_ns) * 1e-9);
  }
  if (!options.faults.empty()) {
    std::string listed;
    for (const hil::HilFault& f : options.faults) {
      listed += (listed.empty() ? "" : ", ") + hil::to_string(f);
    }
    std::printf(
        "  faults              %s: %llu messages dropped, %llu corrupted, %llu duplicated, %llu "
        "delayed; pty unplugged %llu times\n",
        listed.c_str(), static_cast<unsigned long long>(s.faults.dropped),
        static_cast<unsigned long long>(s.faults.corrupted),
        static_cast<unsigned long long>(s.faults.duplicated),
        static_cast<unsigned long long>(s.faults.delayed),
        static_cast<unsigned long long>(s.faults.unplugged));
  }
  if (!replay.playlist().damage().empty()) {
    std::printf("  recording damaged   sent up to the damage: %s\n",
                replay.playlist().damage().c_str());
  }
  std::fflush(stdout);
  return failed ? 1 : 0;
}

}  // namespace posed::posectl
