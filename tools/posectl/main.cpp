// posectl: the companion tool of posed (echo, inspect, record, replay, sim, eval, bench ...).

#include <cstdio>
#include <cstring>
#include <exception>
#include <string_view>

#include "drivers/common/log.hpp"
#include "tools/posectl/commands.hpp"

namespace {

void print_usage(std::FILE* out) {
  std::fprintf(out,
               "usage: posectl <command> [options]\n"
               "       posectl <command> --help\n\n"
               "The companion tool of posed, the driver-to-pose daemon.\n\ncommands:\n");
  for (const auto& c : posed::posectl::commands()) {
    std::fprintf(out, "  %-10.*s %.*s\n", static_cast<int>(c.name.size()), c.name.data(),
                 static_cast<int>(c.summary.size()), c.summary.data());
  }
}

}  // namespace

int main(int argc, char** argv) noexcept try {
  posed::log::set_program_name("posectl");
  if (argc < 2) {
    print_usage(stderr);
    return 2;
  }
  const std::string_view name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    print_usage(stdout);
    return 0;
  }
  for (const auto& c : posed::posectl::commands()) {
    if (c.name == name) return c.run(argc - 1, argv + 1);
  }
  std::fprintf(stderr, "posectl: unknown command '%s'\n\n", argv[1]);
  print_usage(stderr);
  return 2;
} catch (const std::exception& e) {
  std::fprintf(stderr, "posectl: error: %s\n", e.what());
  return 1;
} catch (...) {
  std::fprintf(stderr, "posectl: error: unknown exception\n");
  return 1;
}
