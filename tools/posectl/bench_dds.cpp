// posectl bench dds: Publisher -> Subscriber latency for odometry at 400 Hz for 10 s, two
// participants in one process on the loopback Cyclone config (target p99 < 1 ms). Cyclone hands
// samples between participants of one process directly (no UDP), so this measures
// serialization, delivery, wake-up and deserialization; the cross-process path over the
// loopback interface is covered by the dds unit tests and `posectl echo`.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "daemon/dds/publisher.hpp"
#include "daemon/dds/subscriber.hpp"
#include "drivers/common/host_clock.hpp"
#include "tools/posectl/bench.hpp"

namespace posed::posectl {
namespace {

constexpr const char* kXmlName = "cyclonedds-loopback.xml";

/// config/cyclonedds-loopback.xml: $POSED_SOURCE_DIR/config, else a config/ (source tree) or
/// share/posed/ (installed) folder above the executable, else /etc/posed. Empty if none.
std::string find_loopback_xml(std::string& tried) {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates;
  if (const char* src = std::getenv("POSED_SOURCE_DIR")) {
    candidates.push_back(fs::path(src) / "config" / kXmlName);
  }
  std::error_code ec;
  fs::path dir = fs::read_symlink("/proc/self/exe", ec).parent_path();
  for (int up = 0; !ec && up < 6 && !dir.empty(); ++up, dir = dir.parent_path()) {
    candidates.push_back(dir / "config" / kXmlName);
    candidates.push_back(dir / "share" / "posed" / kXmlName);
    if (dir == dir.root_path()) break;
  }
  candidates.push_back(fs::path("/etc/posed") / kXmlName);
  for (const auto& c : candidates) {
    if (fs::is_regular_file(c, ec)) return c.string();
    tried += (tried.empty() ? "" : ", ") + c.string();
  }
  return {};
}

double percentile_sorted(const std::vector<double>& sorted, double p) {
  return sorted[static_cast<std::size_t>(p * static_cast<double>(sorted.size() - 1) + 0.5)];
}

}  // namespace

int bench_dds() {
  constexpr double kRateHz = 400.0;
  constexpr int kSamples = 4000;  // 10 s at 400 Hz

  std::string tried;
  dds::DdsConfig config;
  config.cyclonedds_xml_path = find_loopback_xml(tried);
  if (config.cyclonedds_xml_path.empty()) {
    std::fprintf(stderr, "posectl bench dds: %s not found (tried %s); set POSED_SOURCE_DIR\n",
                 kXmlName, tried.c_str());
    return 1;
  }
  // A domain of its own (tests use 100..200) so a running posed or test is not disturbed.
  std::random_device rd;
  config.domain_id = std::uniform_int_distribution<std::uint32_t>(201, 229)(rd);

  std::string error;
  auto publisher = dds::Publisher::create(config, error);
  if (!publisher) {
    std::fprintf(stderr, "posectl bench dds: publisher: %s\n", error.c_str());
    return 1;
  }
  const std::array topics = {dds::Topic::kOdom};
  auto subscriber = dds::Subscriber::create(config, topics, error);
  if (!subscriber) {
    std::fprintf(stderr, "posectl bench dds: subscriber: %s\n", error.c_str());
    return 1;
  }
  const HostTime match_deadline = drivers::host_now() + Duration::from_s(10);
  while (publisher->matched_subscribers(dds::Topic::kOdom) == 0) {
    if (drivers::host_now() > match_deadline) {
      std::fprintf(stderr, "posectl bench dds: subscriber not matched within 10 s\n");
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }

  std::atomic<bool> stop{false};
  std::vector<double> latency_us;
  latency_us.reserve(kSamples);
  std::thread receiver([&] {
    std::vector<dds::Received<dds::OdomMessage>> samples;
    samples.reserve(64);
    while (!stop.load(std::memory_order_acquire)) {
      if (!subscriber->wait(Duration::from_ms(50))) continue;
      samples.clear();
      subscriber->take_odom(samples);
      for (const auto& r : samples) {
        latency_us.push_back(static_cast<double>((r.received_wall - r.msg.stamp).ns) * 1e-3);
      }
    }
  });

  std::vector<double> publish_us;
  publish_us.reserve(kSamples);
  dds::OdomMessage msg;
  msg.v_base_mps = {1.0, 0.0, 0.0};
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / kRateHz));
  auto due = std::chrono::steady_clock::now();
  int sent = 0;
  for (int i = 0; i < kSamples; ++i) {
    due += period;
    std::this_thread::sleep_until(due);
    msg.p_map_base_m.x() = i * 0.0025;
    msg.stamp = drivers::wall_now();  // latency = receive wall time - this stamp
    const HostTime t0 = drivers::host_now();
    if (publisher->publish_odom(msg)) ++sent;
    publish_us.push_back((drivers::host_now() - t0).seconds() * 1e6);
  }
  // Stragglers: reliable delivery in-process completes within milliseconds.
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  stop.store(true, std::memory_order_release);
  receiver.join();

  report("dds", "sent", sent, "count");
  report("dds", "received", static_cast<double>(latency_us.size()), "count");
  report("dds", "write_failures", static_cast<double>(publisher->write_failures()), "count");
  if (latency_us.empty()) {
    std::fprintf(stderr, "posectl bench dds: nothing received\n");
    return 1;
  }
  std::sort(latency_us.begin(), latency_us.end());
  std::sort(publish_us.begin(), publish_us.end());
  report("dds", "latency_p50", percentile_sorted(latency_us, 0.50), "us");
  report("dds", "latency_p99", percentile_sorted(latency_us, 0.99), "us");
  report("dds", "latency_max", latency_us.back(), "us");
  report("dds", "publish_call_p50", percentile_sorted(publish_us, 0.50), "us");
  report("dds", "publish_call_p99", percentile_sorted(publish_us, 0.99), "us");
  return static_cast<int>(latency_us.size()) == sent ? 0 : 1;
}

}  // namespace posed::posectl
