#include "tools/hil/hil_faults.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace posed::hil {
namespace {

constexpr std::pair<HilFaultKind, std::string_view> kKinds[] = {
    {HilFaultKind::kDrop, "drop"},           {HilFaultKind::kCorrupt, "corrupt"},
    {HilFaultKind::kDuplicate, "duplicate"}, {HilFaultKind::kDelay, "delay"},
    {HilFaultKind::kUnplug, "unplug"},
};
constexpr std::pair<HilFaultTarget, std::string_view> kTargets[] = {
    {HilFaultTarget::kAll, "all"},
    {HilFaultTarget::kLidar, "lidar"},
    {HilFaultTarget::kImu, "imu"}};

bool parse_seconds(std::string_view text, double& out) {
  const auto r = std::from_chars(text.data(), text.data() + text.size(), out);
  return r.ec == std::errc{} && r.ptr == text.data() + text.size() && std::isfinite(out);
}

}  // namespace

bool HilFault::applies(HilOutput output) const {
  if (kind == HilFaultKind::kUnplug) return output == HilOutput::kSerial;
  switch (target) {
    case HilFaultTarget::kAll:
      return output != HilOutput::kNone;
    case HilFaultTarget::kLidar:
      return output == HilOutput::kUdpData || output == HilOutput::kUdpPosition;
    case HilFaultTarget::kImu:
      return output == HilOutput::kSerial;
  }
  return false;
}

std::string to_string(const HilFault& fault) {
  std::string text;
  for (const auto& [k, name] : kKinds) {
    if (k == fault.kind) text = name;
  }
  if (fault.kind != HilFaultKind::kUnplug && fault.target != HilFaultTarget::kAll) {
    for (const auto& [t, name] : kTargets) {
      if (t == fault.target) text += ":" + std::string(name);
    }
  }
  char window[64];
  std::snprintf(window, sizeof window, "@%g+%g", fault.start_s, fault.duration_s);
  return text + window;
}

bool parse_hil_fault(std::string_view text, HilFault& out, std::string& error) {
  const auto at = text.find('@');
  const auto plus = text.find('+', at == std::string_view::npos ? 0 : at);
  if (at == std::string_view::npos || plus == std::string_view::npos) {
    error = "fault '" + std::string(text) +
            "': expected KIND[:OUTPUT]@START+DURATION (seconds), e.g. drop:lidar@5+2";
    return false;
  }
  std::string_view kind = text.substr(0, at);
  std::string_view target = "all";
  if (const auto colon = kind.find(':'); colon != std::string_view::npos) {
    target = kind.substr(colon + 1);
    kind = kind.substr(0, colon);
  }
  bool known_kind = false, known_target = false;
  for (const auto& [k, name] : kKinds) {
    if (name == kind) out.kind = k, known_kind = true;
  }
  for (const auto& [t, name] : kTargets) {
    if (name == target) out.target = t, known_target = true;
  }
  if (!known_kind) {
    error = "fault '" + std::string(text) + "': unknown kind '" + std::string(kind) +
            "' (kinds: drop, corrupt, duplicate, delay, unplug)";
    return false;
  }
  if (!known_target) {
    error = "fault '" + std::string(text) + "': unknown output '" + std::string(target) +
            "' (outputs: lidar, imu, all)";
    return false;
  }
  if (!parse_seconds(text.substr(at + 1, plus - at - 1), out.start_s) || out.start_s < 0 ||
      !parse_seconds(text.substr(plus + 1), out.duration_s) || out.duration_s <= 0) {
    error = "fault '" + std::string(text) +
            "': start and duration must be seconds, start >= 0 and duration > 0";
    return false;
  }
  return true;
}

HilFaults::Verdict HilFaults::judge(double t_s, HilOutput output) const {
  Verdict v;
  for (const HilFault& f : faults_) {
    if (!f.active(t_s) || !f.applies(output)) continue;
    v.drop = v.drop || f.kind == HilFaultKind::kDrop || f.kind == HilFaultKind::kUnplug;
    v.duplicate = v.duplicate || f.kind == HilFaultKind::kDuplicate;
    v.delay = v.delay || f.kind == HilFaultKind::kDelay;
  }
  return v;
}

bool HilFaults::unplugged(double t_s) const {
  for (const HilFault& f : faults_) {
    if (f.kind == HilFaultKind::kUnplug && f.active(t_s)) return true;
  }
  return false;
}

bool HilFaults::corrupt(double t_s, HilOutput output, std::span<std::byte> bytes) {
  bool covered = false;
  for (const HilFault& f : faults_) {
    covered = covered || (f.kind == HilFaultKind::kCorrupt && f.active(t_s) && f.applies(output));
  }
  if (!covered || bytes.empty()) return false;
  std::uniform_int_distribution<std::size_t> where(0, bytes.size() - 1);
  std::uniform_int_distribution<int> bit(0, 7);
  for (std::size_t k = 0; k < std::max<std::size_t>(1, bytes.size() / 64); ++k) {
    bytes[where(random_)] ^= static_cast<std::byte>(1u << bit(random_));
  }
  return true;
}

}  // namespace posed::hil
