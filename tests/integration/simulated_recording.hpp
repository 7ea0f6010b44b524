#pragma once
// A test's input recording, simulated by `posectl sim` with config/posed.yaml's rig: the block
// every replay test used to write out for itself.

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "tests/integration/posed_process.hpp"

namespace posed::testing {

/// What one simulation printed, and whether it succeeded.
struct Simulated {
  bool ok = false;
  std::string out;  ///< its stdout (the summary: what it drove, faults, streams)
};

/// `posectl sim --scenario SCENARIO --duration SECONDS --seed SEED --config config/posed.yaml
/// -o PATH ARGS...`; a failed run fails the test with the simulator's stderr (ok is then false:
/// ASSERT_TRUE(...ok) stops the test there).
inline Simulated simulate_recording(const TempDir& dir, const std::string& path,
                                    const std::string& scenario, int seconds, int seed,
                                    const std::vector<std::string>& args = {},
                                    std::chrono::seconds timeout = std::chrono::seconds(120)) {
  std::vector<std::string> argv{simulator(),  "sim",
                                "--scenario", scenario,
                                "--duration", std::to_string(seconds),
                                "--seed",     std::to_string(seed),
                                "--config",   source_dir() + "/config/posed.yaml",
                                "-o",         path};
  argv.insert(argv.end(), args.begin(), args.end());
  PosedProcess sim(argv, {}, dir);
  const std::optional<int> code = sim.wait_for_exit(timeout);
  Simulated s;
  s.ok = code == 0;
  s.out = sim.out();
  if (!s.ok) {
    ADD_FAILURE() << "posectl sim --scenario " << scenario << " -o " << path << ": "
                  << (code ? "exit " + std::to_string(*code) : std::string("timed out")) << "\n"
                  << sim.err();
  }
  return s;
}

}  // namespace posed::testing
