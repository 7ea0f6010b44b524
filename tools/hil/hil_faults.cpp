#include "tools/hil/hil_faults.hpp"

#include "tools/faults/fault_text.hpp"

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
  return text + faults::window_text({fault.start_s, fault.duration_s});
}

bool parse_hil_fault(std::string_view text, HilFault& out, std::string& error) {
  std::string_view kind;
  faults::FaultWindow window;
  if (!faults::parse_fault_text(text, "KIND[:OUTPUT]@START+DURATION (seconds), e.g. drop:lidar@5+2",
                                kind, window, error)) {
    return false;
  }
  out.start_s = window.start_s;
  out.duration_s = window.duration_s;
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
  faults::flip_random_bits(bytes, random_);
  return true;
}

}  // namespace posed::hil
