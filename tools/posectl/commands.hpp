#pragma once
// posectl's subcommands. Each lives in its own cmd_*.cpp and is listed once in commands.cpp.

#include <span>
#include <string_view>

namespace posed::posectl {

struct Command {
  std::string_view name;
  std::string_view summary;
  /// argv[0] is the subcommand name; returns the process exit code.
  int (*run)(int argc, char** argv);
};

std::span<const Command> commands();

int run_bench(int argc, char** argv);
int run_inspect(int argc, char** argv);
int run_inspect_velodyne(int argc, char** argv);
int run_inspect_camera(int argc, char** argv);
int run_echo(int argc, char** argv);
int run_initialpose(int argc, char** argv);
int run_eval(int argc, char** argv);
int run_sim(int argc, char** argv);
int run_inspect_mcap(int argc, char** argv);
int run_inspect_frontend(int argc, char** argv);
int run_export(int argc, char** argv);
int run_record(int argc, char** argv);
int run_replay(int argc, char** argv);
int run_import(int argc, char** argv);
int run_unit_dropin(int argc, char** argv);
int run_security(int argc, char** argv);

}  // namespace posed::posectl
