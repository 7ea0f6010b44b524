#pragma once
// Faults on what `posectl replay` re-emits to a live posed (`--fault KIND[:OUTPUT]@T+D`, issue
// 22): the transport failures a robot's links have, laid over a recording on its way out. T and
// D are seconds of the recording's time since its first message sent.
//   drop       the messages are not sent (a cable shaken loose, a dead switch port)
//   corrupt    1 byte in 64 of each message flipped (seeded: the same bytes every run)
//   duplicate  every message sent twice
//   delay      the messages are held and sent together, in order, when the window ends (a
//              stalled USB or NIC queue that then flushes)
//   unplug     the pty goes away (the A9's USB-serial adapter pulled: the reader gets a hang-up
//              and the link disappears) and comes back as a new pty at the same link; only the
//              pty's bytes are lost meanwhile
// OUTPUT: lidar (both UDP ports), imu (the pty) or all (the default; unplug is always the pty's).

#include <cstdint>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tools/hil/hil_playlist.hpp"

namespace posed::hil {

enum class HilFaultKind : std::uint8_t { kDrop, kCorrupt, kDuplicate, kDelay, kUnplug };
enum class HilFaultTarget : std::uint8_t { kAll, kLidar, kImu };

struct HilFault {
  HilFaultKind kind = HilFaultKind::kDrop;
  HilFaultTarget target = HilFaultTarget::kAll;
  /// since the first message sent, in the recording's time [s]
  double start_s = 0;
  /// [s]
  double duration_s = 0;

  bool active(double t_s) const { return t_s >= start_s && t_s < start_s + duration_s; }
  bool applies(HilOutput output) const;
};

/// "drop:lidar@5+2"
std::string to_string(const HilFault& fault);
/// Parses "KIND[:OUTPUT]@T+D". False with `error` saying what is wrong.
bool parse_hil_fault(std::string_view text, HilFault& out, std::string& error);

/// What the faults did [messages, unplugs].
struct HilFaultCounts {
  std::uint64_t dropped = 0;
  std::uint64_t corrupted = 0;
  std::uint64_t duplicated = 0;
  std::uint64_t delayed = 0;
  std::uint64_t unplugged = 0;
};

/// The faults in force for one message at a time; pure (the replay does the sending).
class HilFaults {
 public:
  explicit HilFaults(std::vector<HilFault> faults, std::uint64_t seed = 22)
      : faults_(std::move(faults)), random_(seed) {}

  /// What happens to a message of `output` at `t_s` (recording time since the first message).
  struct Verdict {
    bool drop = false;
    bool duplicate = false;
    bool delay = false;
  };
  Verdict judge(double t_s, HilOutput output) const;
  /// Whether the pty is unplugged at `t_s`.
  bool unplugged(double t_s) const;
  /// Flips 1 byte in 64 of `bytes` (at least one) when a corrupt fault covers it; true if so.
  bool corrupt(double t_s, HilOutput output, std::span<std::byte> bytes);

  bool empty() const { return faults_.empty(); }
  const std::vector<HilFault>& faults() const { return faults_; }

 private:
  std::vector<HilFault> faults_;
  std::mt19937_64 random_;
};

}  // namespace posed::hil
