#include "drivers/recording/pcap_source.hpp"

#include <chrono>
#include <cmath>

#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"

namespace posed::drivers::recording {

PcapSource::PcapSource(PcapSourceConfig config) : config_(std::move(config)) {}

bool PcapSource::open(std::string& error) {
  if (opened_) return true;
  if (!(config_.speed >= 0.0) || !std::isfinite(config_.speed)) {
    error = "pcap " + config_.path + ": speed must be ≥ 0 (0 = as fast as possible)";
    return false;
  }
  if (!file_.open(config_.path, error, "pcap")) return false;
  parser_ = PcapParser(file_.bytes());
  const PcapStatus s = parser_.open();
  if (s != PcapStatus::kOk) {
    error = "pcap " + config_.path + ": " + parser_.describe_error();
    return false;
  }
  opened_ = true;
  return true;
}

bool PcapSource::fetch_next() {
  while (!ended_) {
    const PcapStatus s = parser_.next(record_);
    if (s == PcapStatus::kEnd) {
      ended_ = true;
      break;
    }
    if (s != PcapStatus::kOk) {
      ended_ = true;
      std::lock_guard lock(error_mutex_);
      file_error_ = "pcap " + config_.path + ": " + parser_.describe_error();
      POSED_LOG_WARN("%s; replay stops here", file_error_.c_str());
      break;
    }
    records_.fetch_add(1, std::memory_order_relaxed);
    const FrameStatus f = extract_udp(record_.link_type, record_.frame, datagram_);
    if (f == FrameStatus::kTruncated || f == FrameStatus::kMalformed) {
      counts_.rejected.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    if (f != FrameStatus::kOk) {
      not_udp_.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    bool found = false;
    for (std::size_t i = 0; i < config_.ports.size() && !found; ++i) {
      if (config_.ports[i] == datagram_.dst_port) {
        channel_ = static_cast<std::uint32_t>(i);
        found = true;
      }
    }
    if (!found) {
      other_ports_.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    have_next_ = true;
    return true;
  }
  return false;
}

ReadStatus PcapSource::read(RawChunk& chunk, Duration timeout) {
  if (stop_.load(std::memory_order_acquire) || !opened_) return ReadStatus::kEndOfStream;
  if (!have_next_ && !fetch_next()) return ReadStatus::kEndOfStream;

  if (config_.speed > 0.0) {
    if (!started_) {
      started_ = true;
      first_capture_ns_ = record_.timestamp_ns;
      first_host_ = host_now();
    }
    // Due time on the host clock; a stamp earlier than the first is due at once.
    const double since_first = static_cast<double>(record_.timestamp_ns - first_capture_ns_);
    const HostTime due =
        first_host_ + Duration::from_ns(static_cast<std::int64_t>(since_first / config_.speed));
    const HostTime now = host_now();
    if (due > now) {
      const Duration wait = std::min(due - now, timeout);
      std::unique_lock lock(wait_mutex_);
      wait_cv_.wait_for(lock, std::chrono::nanoseconds(wait.ns),
                        [&] { return stop_.load(std::memory_order_acquire); });
      if (stop_.load(std::memory_order_acquire)) return ReadStatus::kEndOfStream;
      if (host_now() < due) return ReadStatus::kTimeout;
    }
  }
  have_next_ = false;
  chunk.bytes = datagram_.payload;
  chunk.host_receive = HostTime::from_ns(record_.timestamp_ns);
  chunk.channel = channel_;
  counts_.count_chunk(datagram_.payload.size());
  return ReadStatus::kData;
}

void PcapSource::request_stop() {
  {
    std::lock_guard lock(wait_mutex_);
    stop_.store(true, std::memory_order_release);
  }
  wait_cv_.notify_all();
}

SourceCounters PcapSource::counters() const { return counts_.snapshot(); }

PcapSourceStats PcapSource::stats() const {
  PcapSourceStats s;
  s.records = records_.load(std::memory_order_relaxed);
  s.not_udp = not_udp_.load(std::memory_order_relaxed);
  s.other_ports = other_ports_.load(std::memory_order_relaxed);
  s.damaged = counts_.rejected.load(std::memory_order_relaxed);
  return s;
}

std::string PcapSource::file_error() const {
  std::lock_guard lock(error_mutex_);
  return file_error_;
}

}  // namespace posed::drivers::recording
