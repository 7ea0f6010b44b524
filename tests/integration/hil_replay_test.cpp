// Hardware-in-the-loop replay as a user runs it (tests/integration/hil_drive.hpp): a live posed
// fed by `posectl replay` over a real UDP socket and a real pty tracks a simulated drive.

#include "tests/integration/hil_drive.hpp"

namespace posed::testing {
namespace hil_replay_test {

TEST(HilReplay, ALivePosedFedByPosectlReplayTracksTheSimulatedDrive) {
  hil_helpers::run_hil_drive({}, 15);
}

}  // namespace hil_replay_test
}  // namespace posed::testing
