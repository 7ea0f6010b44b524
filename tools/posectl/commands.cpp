#include "tools/posectl/commands.hpp"

#include <array>

namespace posed::posectl {

std::span<const Command> commands() {
  static const std::array kCommands = {
      Command{"bench", "run benchmarks; prints `NAME METRIC VALUE UNIT` lines", run_bench},
      Command{"inspect",
              "decode a raw sensor capture frame by frame, or list a recording (FILE.mcap)",
              run_inspect},
      Command{"echo", "print posed's DDS topics (odom, pose, status) with rate and latency",
              run_echo},
      Command{"initialpose",
              "send an initial pose on rt/initialpose as RViz's 2D Pose Estimate does",
              run_initialpose},
      Command{"eval", "ATE and RPE of an estimated trajectory against ground truth (TUM, KITTI)",
              run_eval},
      Command{"sim",
              "simulate the rig in a scenario: a recording with raw sensor data and ground truth",
              run_sim},
      Command{"export", "write an MCAP recording's poses (TUM) or its lidar map (PCD)", run_export},
      Command{"replay",
              "re-emit a recording onto UDP and a pty with its timing (hardware-in-the-loop)",
              run_replay},
      Command{"record", "record the raw bytes of the config's live Sources to MCAP (no fusion)",
              run_record},
      Command{"import", "turn a pcap capture, candump log or ROS 1 bag into a posed recording",
              run_import},
      Command{"unit-dropin",
              "print a posed.service drop-in narrowing its IP allow-list to the config's peers",
              run_unit_dropin},
      Command{"security", "make a DDS Security keystore (CA, governance, enclaves) for posed",
              run_security},
  };
  return kCommands;
}

}  // namespace posed::posectl
