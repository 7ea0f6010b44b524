// posectl eval as a user runs it: exit codes and messages. Needs the posectl executable of
// this build; skipped, saying so, when it has not been built.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "eval_test_util.hpp"

namespace posed::eval {
namespace {

namespace fs = std::filesystem;

fs::path posectl_path() {
  const char* env = std::getenv("POSED_BUILD_DIR");
  const fs::path build = env != nullptr ? fs::path(env) : fs::path(POSED_BUILD_DIR_DEFAULT);
  return build / "tools" / "posectl" / "posectl";
}

struct CliRun {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

CliRun run(const std::string& args) {
  CliRun r;
  const std::string cmd = posectl_path().string() + " eval " + args + " 2>&1";
  std::FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) r.output.append(buf.data(), n);
  const int status = ::pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

class EvalCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(posectl_path())) {
      GTEST_SKIP() << posectl_path() << " not built (ninja posectl)";
    }
    dir_ = fs::temp_directory_path() / ("posed_eval_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    std::ofstream gt(dir_ / "gt.txt");
    for (int i = 0; i < 20; ++i) {
      gt << 1.0 + 0.1 * i << ' ' << std::cos(0.3 * i) << ' ' << std::sin(0.3 * i) << ' '
         << 0.01 * i * i << " 0 0 0 1\n";
    }
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(EvalCli, IdenticalFilesWithAlignNoneScoreZero) {
  const CliRun r = run("--gt " + file("gt.txt") + " --est " + file("gt.txt") + " --align none");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(std::regex_search(
      r.output, std::regex(R"(ATE translation \[m\] +20 +0\.000000 +0\.000000 +0\.000000)")))
      << r.output;
  const CliRun j = run("--gt " + file("gt.txt") + " --est " + file("gt.txt") + " --json");
  EXPECT_EQ(j.exit_code, 0) << j.output;
  EXPECT_EQ(j.output.front(), '{') << j.output;
}

TEST_F(EvalCli, DataErrorsExitWithTwoAndSayWhere) {
  const CliRun missing = run("--gt " + file("nope.txt") + " --est " + file("gt.txt"));
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.output.find("nope.txt: cannot open"), std::string::npos) << missing.output;

  std::ofstream(dir_ / "bad.txt") << "# header\n1.0 0 0 0 0 0 0 1\n1.1 0 0 0 0 0 1\n";
  const CliRun bad = run("--gt " + file("gt.txt") + " --est " + file("bad.txt"));
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.output.find("bad.txt:3: expected 8 fields"), std::string::npos) << bad.output;

  const CliRun apart = run("--gt " + file("gt.txt") + " --est " + file("gt.txt") + " --offset 100");
  EXPECT_EQ(apart.exit_code, 2);
  EXPECT_NE(apart.output.find("only 0 associated poses"), std::string::npos) << apart.output;
}

}  // namespace
}  // namespace posed::eval
