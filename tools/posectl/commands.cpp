#include "tools/posectl/commands.hpp"

#include <array>

namespace posed::posectl {

std::span<const Command> commands() {
  static const std::array kCommands = {
      Command{"bench", "run benchmarks; prints `NAME METRIC VALUE UNIT` lines", run_bench},
  };
  return kCommands;
}

}  // namespace posed::posectl
