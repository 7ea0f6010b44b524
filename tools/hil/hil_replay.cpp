#include "tools/hil/hil_replay.hpp"

#include <cstdio>

#include "drivers/common/host_clock.hpp"

namespace posed::hil {

HilReplay::HilReplay(HilReplayOptions options)
    : options_(std::move(options)),
      pacer_(options_.rate > 0 ? options_.rate : 1.0),
      faults_(options_.faults) {}

std::size_t HilReplay::slot(HilOutput output) {
  for (std::size_t i = 0; i < kHilOutputs.size(); ++i) {
    if (kHilOutputs[i] == output) return i;
  }
  return 0;  // kNone never reaches send(): the playlist only yields sent channels
}

bool HilReplay::open(std::string& error) {
  if (!playlist_.open(options_.playlist, error)) return false;
  bool need_udp = false, need_pty = false;
  for (const HilChannel& c : playlist_.channels()) {
    if (!c.sent) continue;
    need_udp = need_udp || c.output == HilOutput::kUdpData || c.output == HilOutput::kUdpPosition;
    need_pty = need_pty || c.output == HilOutput::kSerial;
    if (c.output == HilOutput::kIio) {
      if (!iio_) iio_ = std::make_unique<IioEmitter>(options_.iio_dir);
      if (!iio_->add(c.wire_format, error)) return false;
    }
  }
  if (need_udp) {
    udp_ = std::make_unique<UdpEmitter>(options_.udp);
    if (!udp_->open(error)) return false;
  }
  if (need_pty) {
    pty_ = std::make_unique<PtyEmitter>(options_.pty_link);
    if (!pty_->open(error)) return false;
  }
  return true;
}

void HilReplay::send(const HilMessage& m) {
  switch (m.output) {
    case HilOutput::kUdpData:
      udp_->send(0, m.bytes);
      break;
    case HilOutput::kUdpPosition:
      udp_->send(1, m.bytes);
      break;
    case HilOutput::kSerial:
      pty_->write(m.bytes);
      break;
    case HilOutput::kIio:
      iio_->write(playlist_.channels()[m.channel].wire_format, m.bytes);
      break;
    case HilOutput::kNone:
      break;
  }
}

void HilReplay::send_faulted(HilMessage& m, double t_s) {
  const HilFaults::Verdict verdict = faults_.judge(t_s, m.output);
  if (verdict.drop) {
    std::lock_guard lock(mutex_);
    ++fault_counts_.dropped;
    return;
  }
  const bool corrupted = faults_.corrupt(t_s, m.output, m.bytes);
  if (verdict.delay) {
    held_.push_back(std::move(m));
    std::lock_guard lock(mutex_);
    fault_counts_.corrupted += corrupted ? 1 : 0;
    ++fault_counts_.delayed;
    return;
  }
  send(m);
  if (verdict.duplicate) send(m);
  std::lock_guard lock(mutex_);
  fault_counts_.corrupted += corrupted ? 1 : 0;
  fault_counts_.duplicated += verdict.duplicate ? 1 : 0;
}

void HilReplay::apply_faults(double t_s, bool flush) {
  if (pty_ && faults_.unplugged(t_s) != unplugged_ && !flush) {
    unplugged_ = !unplugged_;
    if (unplugged_) {
      pty_->close();
      std::lock_guard lock(mutex_);
      ++fault_counts_.unplugged;
    } else {
      std::string error;
      // Plugged back in: a new pty at the same link, as udev gives a re-enumerated adapter.
      if (!pty_->open(error))
        std::fprintf(stderr, "posectl replay: plugging back in: %s\n", error.c_str());
    }
  }
  std::size_t kept = 0;
  for (HilMessage& h : held_) {
    if (!flush && faults_.judge(t_s, h.output).delay) {
      held_[kept++] = std::move(h);
    } else if (!(h.output == HilOutput::kSerial && unplugged_)) {
      send(h);
    }
  }
  held_.resize(kept);
}

void HilReplay::run() {
  HilMessage m;
  while (!stop_.load(std::memory_order_relaxed) && playlist_.next(m)) {
    if (!started_) {
      std::lock_guard lock(mutex_);
      pacer_.anchor(drivers::host_now() + options_.lead, m.log_ns);
      started_ = true;
      end_log_ns_ = playlist_.end_log_ns();
      first_log_ns_ = m.log_ns;
    }
    const HostTime due = pacer_.due(m.log_ns);
    if (!Pacer::sleep_until(due, stop_)) break;
    // Lateness is taken when the send starts: what the schedule promised against when the
    // bytes were handed to the kernel.
    const Duration lateness = drivers::host_now() - due;
    const std::size_t out = slot(m.output);
    const std::int64_t log_ns = m.log_ns;
    if (faults_.empty()) {
      send(m);
    } else {
      const double t_s = static_cast<double>(m.log_ns - first_log_ns_) * 1e-9;
      apply_faults(t_s, false);
      send_faulted(m, t_s);
    }
    std::lock_guard lock(mutex_);
    ++messages_[out];
    lateness_[out].add(lateness);
    last_log_ns_ = log_ns;
    passes_ = playlist_.passes();
  }
  apply_faults(0, true);
  std::lock_guard lock(mutex_);
  finished_ = true;
}

HilReplayStatus HilReplay::status() const {
  HilReplayStatus s;
  if (udp_) {
    s.udp_data = udp_->counters(0);
    s.udp_position = udp_->counters(1);
  }
  if (pty_) s.pty = pty_->counters();
  if (iio_) s.iio = iio_->counters();
  std::lock_guard lock(mutex_);
  s.messages = messages_;
  s.lateness = lateness_;
  s.started = started_;
  s.anchor_host = pacer_.anchor_host();
  s.anchor_log_ns = pacer_.anchor_log_ns();
  s.last_log_ns = last_log_ns_;
  s.end_log_ns = end_log_ns_;
  s.passes = passes_;
  s.finished = finished_;
  s.faults = fault_counts_;
  return s;
}

}  // namespace posed::hil
