// posectl record -o OUT.mcap --config posed.yaml: records the raw bytes of every live Source the
// config enables, with the same Recorder and the same channels and metadata as `posed --record`
// (pipeline::tap_sources), so `posed --replay` and `posectl replay` take the file. Nothing is
// decoded or fused: a recording box, or a robot whose estimator is being worked on, records the
// sensors alone. Progress once a second; SIGINT/SIGTERM (or --duration) close and index the file.
// Exit codes: 0 recorded, 1 the recording failed or nothing arrived, 2 bad arguments or config.

#include <CLI/CLI.hpp>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "daemon/config/config_loader.hpp"
#include "daemon/pipeline/recording_tap.hpp"
#include "daemon/pipeline/source_factory.hpp"
#include "daemon/pipeline/stage_support.hpp"
#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"
#include "drivers/recording/raw_channels.hpp"
#include "drivers/recording/recorder.hpp"
#include "tools/posectl/commands.hpp"
#include "tools/posectl/stop_signals.hpp"
#include "tools/posectl/terminal_progress.hpp"

namespace posed::posectl {
namespace {

namespace rec = drivers::recording;

/// One Source read on its own thread until it ends; the RecordingTap around it does the
/// recording, so the loop only keeps the Source moving (and logs losses, as the pipeline does).
struct Pump {
  explicit Pump(drivers::Source& s)
      : source(s), heartbeat(std::string(s.name())), reader(name, s, heartbeat, counters) {}
  drivers::Source& source;
  std::string name{source.name()};
  pipeline::Heartbeat heartbeat;
  pipeline::StreamCounters counters;
  pipeline::SourceReader reader;
  std::string open_error;
  std::thread thread;
  std::atomic<bool> ended{false};

  void run() {
    drivers::RawChunk chunk;
    while (reader.next(chunk)) {
    }
    ended.store(true);
  }
};

/// "lidar/1" for /posed/raw/lidar/1: the stream and, when not 0, the Source channel.
std::string short_name(const std::string& topic) {
  const std::string_view prefix = rec::raw::kTopicPrefix;
  return topic.rfind(prefix, 0) == 0 ? topic.substr(prefix.size()) : topic;
}

}  // namespace

int run_record(int argc, char** argv) {
  CLI::App app{
      "Records the raw bytes of every Source the config enables (A9 serial or the synthetic IMU, "
      "Velodyne UDP or pcap, and any other Source posed builds) to an MCAP file, exactly as "
      "`posed --record` does but without decoding or fusion: same channels, same metadata, so "
      "`posed --replay FILE` and `posectl replay FILE` take it.\n"
      "Prints progress once a second (per channel: messages, MB, rate, drops) and a summary. "
      "SIGINT/SIGTERM or --duration stop it; the file is then closed and indexed.",
      "posectl record"};
  std::string out_path, config_path = "/etc/posed/posed.yaml", compression_text = "lz4";
  double duration_s = 0, split_size_mb = 0, split_duration_s = 0;
  app.add_option("-o,--output", out_path,
                 "recording to write (MCAP); split files are OUT_001.mcap, OUT_002.mcap, ...")
      ->required();
  app.add_option("-c,--config", config_path, "posed configuration: which Sources, which devices")
      ->capture_default_str();
  app.add_option("--duration", duration_s, "stop after this long; 0 = until SIGINT/SIGTERM [s]")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--split-size", split_size_mb,
                 "start a new file once one reaches this size; 0 = never [MB, 10^6 B]")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--split-duration", split_duration_s,
                 "start a new file once one spans this much time; 0 = never [s]")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--compression", compression_text, "chunk compression: lz4, zstd or none")
      ->check(CLI::IsMember({"lz4", "zstd", "none"}))
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  const config::LoadResult loaded = config::load_config_file(config_path);
  if (!loaded.ok()) {
    std::fprintf(stderr, "posectl record: invalid configuration:\n%s", loaded.error_text().c_str());
    return 2;
  }
  const config::PosedConfig& config = loaded.config;
  // Before any thread exists, so every Source thread inherits the blocked mask.
  StopSignals signals;

  std::string error;
  pipeline::BuiltSources built = pipeline::make_sources(config, error);
  if (!error.empty() || !built.sources.imu) {
    std::fprintf(stderr, "posectl record: %s: %s\n", config_path.c_str(),
                 error.empty() ? "no Source to record" : error.c_str());
    return 2;
  }

  rec::RecorderOptions options;
  rec::parse_compression(compression_text == "none" ? "" : compression_text,
                         options.writer.compression);
  options.rotate_bytes = static_cast<std::uint64_t>(split_size_mb * 1e6);
  options.rotate_after = Duration::from_seconds(split_duration_s);
  rec::Recorder recorder;
  if (!recorder.open(out_path, options, error)) {
    std::fprintf(stderr, "posectl record: %s\n", error.c_str());
    return 1;
  }
  pipeline::tap_sources(built.sources, recorder, config);

  std::vector<std::unique_ptr<Pump>> pumps;
  built.sources.for_each([&](std::unique_ptr<drivers::Source>& source) {
    if (source) pumps.push_back(std::make_unique<Pump>(*source));
  });
  std::string names;
  for (auto& p : pumps) {
    names += (names.empty() ? "" : ", ") + p->name;
    // A device that is not there yet is retried by its Source on read(), as in posed.
    if (!p->source.open(p->open_error)) {
      POSED_LOG_WARN("%s: not open yet: %s; retrying", p->name.c_str(), p->open_error.c_str());
    }
  }
  char limit[64] = "";
  if (duration_s > 0) std::snprintf(limit, sizeof limit, " for %.1f s", duration_s);
  std::fprintf(stderr, "posectl record: recording %s to %s (%s chunks)%s\n", names.c_str(),
               out_path.c_str(), compression_text.c_str(), limit);
  for (auto& p : pumps) p->thread = std::thread([&p = *p] { p.run(); });

  const HostTime started = drivers::host_now();
  TerminalProgress progress;
  std::map<std::string, std::uint64_t> last_count;
  HostTime last_report = started;
  std::string stopped_by = "the end of every Source";
  bool stopping = false;
  for (;;) {
    bool all_ended = true;
    for (auto& p : pumps) all_ended = all_ended && p->ended.load();
    if (all_ended) break;
    const int sig = signals.wait(Duration::from_ms(200));
    const HostTime now = drivers::host_now();
    if (sig != 0) {
      if (stopping) {
        // The file stays readable up to its last complete chunk, only unindexed.
        std::fprintf(stderr, "\nposectl record: second %s: aborting without closing %s\n",
                     strsignal(sig), out_path.c_str());
        std::_Exit(128 + sig);
      }
      stopped_by = strsignal(sig);
    }
    const bool time_up = duration_s > 0 && (now - started).seconds() >= duration_s;
    if (!stopping && (sig != 0 || time_up)) {
      if (sig == 0) stopped_by = "--duration";
      stopping = true;
      for (auto& p : pumps) p->source.request_stop();
    }
    if (!stopping && now - last_report >= Duration::from_s(1)) {
      const double dt = (now - last_report).seconds();
      last_report = now;
      const rec::RecorderCounters c = recorder.counters();
      char head[128];
      std::snprintf(head, sizeof head, "posectl record: %.0f s, %.2f MB on disk",
                    (now - started).seconds(), megabytes(c.bytes_on_disk));
      std::string line = head;
      for (const auto& ch : c.channels) {
        const std::uint64_t before = last_count[ch.topic];
        last_count[ch.topic] = ch.recorded;
        char part[160];
        std::snprintf(part, sizeof part, " | %s %llu msgs %.2f MB %.0f Hz %llu dropped",
                      short_name(ch.topic).c_str(), static_cast<unsigned long long>(ch.recorded),
                      megabytes(ch.bytes), static_cast<double>(ch.recorded - before) / dt,
                      static_cast<unsigned long long>(ch.dropped));
        line += part;
      }
      progress.show(line);
    }
  }
  for (auto& p : pumps) {
    if (p->thread.joinable()) p->thread.join();
  }
  progress.finish();
  const double run_s = (drivers::host_now() - started).seconds();
  const bool closed = recorder.close();
  const rec::RecorderCounters c = recorder.counters();

  std::printf("\nposectl record summary\n");
  std::printf("  stopped by          %s\n", stopped_by.c_str());
  std::printf("  recorded for        %.1f s\n", run_s);
  for (const auto& ch : c.channels) {
    std::printf("  %-19s %llu messages, %.3f MB, %.1f Hz mean, %llu dropped\n",
                short_name(ch.topic).c_str(), static_cast<unsigned long long>(ch.recorded),
                megabytes(ch.bytes), run_s > 0 ? static_cast<double>(ch.recorded) / run_s : 0.0,
                static_cast<unsigned long long>(ch.dropped));
  }
  std::uint64_t total = 0;
  for (const auto& ch : c.channels) total += ch.recorded;
  for (const auto& p : pumps) {
    if (p->counters.received.load() == 0) {
      std::printf("  %-19s nothing arrived%s%s\n", p->name.c_str(),
                  p->open_error.empty() ? "" : ": ", p->open_error.c_str());
    }
  }
  const std::vector<std::string> files = recorder.files();
  std::printf("  files               %zu (%.3f MB on disk):", files.size(),
              megabytes(c.bytes_on_disk));
  for (const auto& f : files) std::printf(" %s", f.c_str());
  std::printf("\n  written             %llu messages, %llu dropped, %llu write errors\n",
              static_cast<unsigned long long>(c.messages_written),
              static_cast<unsigned long long>(c.dropped),
              static_cast<unsigned long long>(c.write_errors));
  std::fflush(stdout);
  if (!closed) {
    std::fprintf(stderr, "posectl record: %s\n", recorder.error().c_str());
    return 1;
  }
  if (total == 0) {
    std::fprintf(stderr, "posectl record: nothing was recorded (is any sensor connected?)\n");
    return 1;
  }
  return 0;
}

}  // namespace posed::posectl
