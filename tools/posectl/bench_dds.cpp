// posectl bench dds: rt/posed/odom at 400 Hz for 10 s from a Publisher to a Subscriber in
// another process (forked before either touches DDS) over the loopback Cyclone config, twice:
// plain DDS, and DDS Security as posed's keystore sets it up (authenticated, discovery and data
// encrypted, AES-GCM; a throw-away keystore from `posectl security init`). Each row reports the
// stamp-to-receive latency at the reader, the publish call, and the CPU both processes used
// [% of one core], so the difference is the price of encryption.

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

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
#include "tools/posectl/keystore.hpp"

namespace posed::posectl {
namespace {

constexpr const char* kXmlName = "cyclonedds-loopback.xml";
constexpr double kRateHz = 400.0;
constexpr int kSamples = 4000;  // 10 s at 400 Hz

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

/// CPU time this process has used [s].
double process_cpu_s() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
}

/// The reader's side, in the forked child: receives until kSamples arrived or the publisher is
/// gone, then writes its CPU time and each latency [us] (doubles) into `fd`.
[[noreturn]] void run_reader(const dds::DdsConfig& config, int fd) {
  std::string error;
  const std::array topics = {dds::Topic::kOdom};
  auto subscriber = dds::Subscriber::create(config, topics, error);
  std::vector<double> out = {0.0};  // [0]: CPU seconds while receiving
  if (subscriber) {
    const HostTime give_up = drivers::host_now() + Duration::from_s(60);
    while (subscriber->matched_publishers(dds::Topic::kOdom) == 0 &&
           drivers::host_now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    const double cpu0 = process_cpu_s();
    std::vector<dds::Received<dds::OdomMessage>> samples;
    HostTime quiet_since = drivers::host_now();
    while (out.size() < kSamples + 1 && drivers::host_now() - quiet_since < Duration::from_s(2)) {
      if (!subscriber->wait(Duration::from_ms(50))) continue;
      samples.clear();
      subscriber->take_odom(samples);
      if (!samples.empty()) quiet_since = drivers::host_now();
      for (const auto& r : samples) {
        out.push_back(static_cast<double>((r.received_wall - r.msg.stamp).ns) * 1e-3);
      }
    }
    out[0] = process_cpu_s() - cpu0;
  } else {
    std::fprintf(stderr, "posectl bench dds: reader: %s\n", error.c_str());
  }
  const char* bytes = reinterpret_cast<const char*>(out.data());
  std::size_t left = out.size() * sizeof(double);
  while (left > 0) {
    const ssize_t n = ::write(fd, bytes, left);
    if (n <= 0) break;
    bytes += n;
    left -= static_cast<std::size_t>(n);
  }
  ::close(fd);
  std::_Exit(subscriber ? 0 : 1);
}

struct Reader {
  pid_t pid = -1;
  int fd = -1;
};

Reader fork_reader(const dds::DdsConfig& config) {
  int fds[2];
  if (::pipe(fds) != 0) return {};
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    run_reader(config, fds[1]);
  }
  ::close(fds[1]);
  return {pid, fds[0]};
}

/// One row: publishes kSamples at kRateHz to the reader `reader` (already forked), prints
/// `dds ROW.METRIC VALUE UNIT`. False if it could not run or lost samples.
bool run_row(const std::string& row, const dds::DdsConfig& config, Reader reader) {
  std::string error;
  auto publisher = dds::Publisher::create(config, error);
  if (!publisher) {
    std::fprintf(stderr, "posectl bench dds: %s publisher: %s\n", row.c_str(), error.c_str());
    return false;
  }
  const HostTime match_deadline = drivers::host_now() + Duration::from_s(20);
  while (publisher->matched_subscribers(dds::Topic::kOdom) == 0) {
    if (drivers::host_now() > match_deadline) {
      std::fprintf(stderr, "posectl bench dds: %s: reader not matched within 20 s\n", row.c_str());
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  // Discovery's last handshakes (and, secured, the key exchange) settle before the clock runs.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));

  std::vector<double> publish_us;
  publish_us.reserve(kSamples);
  dds::OdomMessage msg;
  msg.v_base_mps = {1.0, 0.0, 0.0};
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / kRateHz));
  const double cpu0 = process_cpu_s();
  const HostTime started = drivers::host_now();
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
  const double elapsed_s = (drivers::host_now() - started).seconds();
  const double publisher_cpu_s = process_cpu_s() - cpu0;

  std::vector<double> in;
  double buffer[512];
  for (ssize_t n; (n = ::read(reader.fd, buffer, sizeof buffer)) > 0;) {
    in.insert(in.end(), buffer, buffer + n / static_cast<ssize_t>(sizeof(double)));
  }
  ::close(reader.fd);
  int status = 0;
  ::waitpid(reader.pid, &status, 0);
  publisher.reset();
  if (in.empty()) {
    std::fprintf(stderr, "posectl bench dds: %s: the reader reported nothing\n", row.c_str());
    return false;
  }
  const double reader_cpu_s = in.front();
  std::vector<double> latency_us(in.begin() + 1, in.end());
  report("dds", row + ".sent", sent, "count");
  report("dds", row + ".received", static_cast<double>(latency_us.size()), "count");
  if (latency_us.empty()) return false;
  std::sort(latency_us.begin(), latency_us.end());
  std::sort(publish_us.begin(), publish_us.end());
  report("dds", row + ".latency_p50", percentile_sorted(latency_us, 0.50), "us");
  report("dds", row + ".latency_p99", percentile_sorted(latency_us, 0.99), "us");
  report("dds", row + ".latency_max", latency_us.back(), "us");
  report("dds", row + ".publish_call_p50", percentile_sorted(publish_us, 0.50), "us");
  report("dds", row + ".publish_call_p99", percentile_sorted(publish_us, 0.99), "us");
  report("dds", row + ".publisher_cpu", 100.0 * publisher_cpu_s / elapsed_s, "%");
  report("dds", row + ".reader_cpu", 100.0 * reader_cpu_s / elapsed_s, "%");
  return static_cast<int>(latency_us.size()) == sent;
}

}  // namespace

int bench_dds() {
  std::string tried;
  dds::DdsConfig plain;
  plain.cyclonedds_xml_path = find_loopback_xml(tried);
  if (plain.cyclonedds_xml_path.empty()) {
    std::fprintf(stderr, "posectl bench dds: %s not found (tried %s); set POSED_SOURCE_DIR\n",
                 kXmlName, tried.c_str());
    return 1;
  }
  // Domains of their own (tests use 1..200) so a running posed or test is not disturbed.
  std::random_device rd;
  plain.domain_id = std::uniform_int_distribution<std::uint32_t>(201, 228)(rd);
  dds::DdsConfig secure = plain;
  secure.domain_id = plain.domain_id + 1;  // <= 230, the most governance can name

  char dir_template[] = "/tmp/posed-bench-dds-XXXXXX";
  if (::mkdtemp(dir_template) == nullptr) {
    std::fprintf(stderr, "posectl bench dds: mkdtemp failed\n");
    return 1;
  }
  const std::string keystore = dir_template;
  KeystoreSpec spec;
  spec.dir = keystore;
  spec.domain_id = static_cast<int>(secure.domain_id);
  spec.enclaves = {{"posed", kPosedTopics, {}}, {"posectl", {}, kPosedTopics}};
  std::string error;
  if (!create_keystore(spec, error)) {
    std::fprintf(stderr, "posectl bench dds: keystore: %s\n", error.c_str());
    return 1;
  }
  dds::DdsConfig secure_reader = secure;
  secure.security = dds::DdsSecurityFiles::from_enclave(keystore + "/enclaves/posed");
  secure_reader.security = dds::DdsSecurityFiles::from_enclave(keystore + "/enclaves/posectl");

  // Both readers fork before this process touches DDS (a fork of a running Cyclone is unsafe).
  const Reader plain_reader = fork_reader(plain);
  const Reader secured_reader = fork_reader(secure_reader);
  const bool ok =
      run_row("plain", plain, plain_reader) && run_row("secure", secure, secured_reader);
  std::error_code ignored;
  std::filesystem::remove_all(keystore, ignored);
  return ok ? 0 : 1;
}

}  // namespace posed::posectl
