// Checks on the shipped unit file itself (systemd/posed.service): that systemd accepts every line
// of it, and that its real-time limit agrees with what the configuration may ask for.

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <string>

#include "daemon/config/config_loader.hpp"

namespace posed {
namespace {

namespace fs = std::filesystem;

fs::path source_dir() {
  const char* dir = std::getenv("POSED_SOURCE_DIR");
  return dir != nullptr ? fs::path(dir) : fs::path(POSED_TEST_SOURCE_DIR);
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::optional<fs::path> find_in_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path != nullptr ? path : "/usr/bin:/bin");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const fs::path candidate = fs::path(dir) / program;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return std::nullopt;
}

/// A fresh directory under /tmp, removed with everything in it when the test ends.
class TempDir {
 public:
  TempDir() {
    char dir_template[] = "/tmp/posed-systemd-test-XXXXXX";
    if (::mkdtemp(dir_template) != nullptr) path_ = dir_template;
  }
  ~TempDir() {
    std::error_code ignored;
    if (!path_.empty()) fs::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

struct CommandResult {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
};

CommandResult run(const std::string& command) {
  CommandResult result;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) result.output += buffer;
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

TEST(SystemdUnit, PassesSystemdAnalyzeVerify) {
  const auto analyze = find_in_path("systemd-analyze");
  if (!analyze) {
    GTEST_SKIP() << "systemd-analyze is not installed (Debian package 'systemd'; "
                    "tools/install-deps installs it), so the unit file cannot be verified here";
  }
  const fs::path unit = source_dir() / "systemd" / "posed.service";
  const std::string text = read_file(unit);
  ASSERT_FALSE(text.empty()) << "cannot read " << unit;

  // verify checks that ExecStart's binary exists; posed is not installed on a build machine, so
  // a copy runs /bin/true with the same arguments. Everything else, User= included, is kept.
  const std::regex exec_start(R"(^ExecStart=/usr/bin/posed\b)", std::regex::multiline);
  ASSERT_TRUE(std::regex_search(text, exec_start)) << unit << " no longer starts /usr/bin/posed";
  const std::string copy_text = std::regex_replace(text, exec_start, "ExecStart=/bin/true");

  const TempDir dir;
  ASSERT_FALSE(dir.path().empty()) << "mkdtemp failed";
  const fs::path copy = dir.path() / "posed.service";  // verify names the unit after the file
  std::ofstream(copy) << copy_text;

  const CommandResult result =
      run("'" + analyze->string() + "' verify --man=no '" + copy.string() + "'");
  // verify exits 0 on unknown keys and bad values (it only warns), so any output is a failure.
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(result.output, "") << "systemd-analyze verify complained about " << unit;
}

// The unit's exposure as systemd rates it (`systemd-analyze security`). 2.0 is the ceiling the
// hardening was built to (docs/security.md): a setting removed or loosened raises the figure
// past it, and the failure message carries the report's open lines to say which.
TEST(SystemdUnit, ExposureScoreIsAtMostTwo) {
  const auto analyze = find_in_path("systemd-analyze");
  if (!analyze) {
    GTEST_SKIP() << "systemd-analyze is not installed (Debian package 'systemd'; "
                    "tools/install-deps installs it), so the unit cannot be rated here";
  }
  const fs::path unit = source_dir() / "systemd" / "posed.service";
  const CommandResult result =
      run("'" + analyze->string() + "' security --offline=yes --no-pager '" + unit.string() + "'");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  std::smatch score;
  ASSERT_TRUE(std::regex_search(
      result.output, score, std::regex(R"(Overall exposure level for posed\.service: (\d+\.\d))")))
      << result.output;
  EXPECT_LE(std::stod(score[1].str()), 2.0) << result.output;
}

// systemd-sysusers and systemd-tmpfiles both take --root, so the two files can be applied to an
// empty directory tree exactly as they would be on the robot, without touching this machine.
TEST(SystemdUnit, SysusersAndTmpfilesCreateTheUserAndRecordingsDirectory) {
  const auto sysusers = find_in_path("systemd-sysusers");
  const auto tmpfiles = find_in_path("systemd-tmpfiles");
  if (!sysusers || !tmpfiles) {
    GTEST_SKIP() << "systemd-sysusers/systemd-tmpfiles are not installed (Debian package "
                    "'systemd'), so posed.sysusers and posed.tmpfiles cannot be applied here";
  }
  const TempDir root_dir;
  ASSERT_FALSE(root_dir.path().empty()) << "mkdtemp failed";
  const fs::path& root = root_dir.path();
  fs::create_directories(root / "etc");
  const fs::path systemd_dir = source_dir() / "systemd";

  const CommandResult users = run("'" + sysusers->string() + "' --root='" + root.string() + "' '" +
                                  (systemd_dir / "posed.sysusers").string() + "'");
  EXPECT_EQ(users.exit_code, 0) << users.output;
  const std::string passwd = read_file(root / "etc" / "passwd");
  const std::string group = read_file(root / "etc" / "group");
  std::smatch user;
  ASSERT_TRUE(std::regex_search(
      passwd, user, std::regex(R"((?:^|\n)posed:x:(\d+):(\d+):posed daemon:/var/lib/posed:)")))
      << passwd;
  for (const char* member_of : {"dialout", "video", "plugdev"}) {
    EXPECT_TRUE(std::regex_search(
        group, std::regex(std::string("(?:^|\n)") + member_of + R"(:x:\d+:([^\n]*,)?posed\b)")))
        << "posed is not in group " << member_of << ":\n"
        << group;
  }

  const CommandResult dirs = run("'" + tmpfiles->string() + "' --root='" + root.string() +
                                 "' --create '" + (systemd_dir / "posed.tmpfiles").string() + "'");
  EXPECT_EQ(dirs.exit_code, 0) << dirs.output;
  const fs::path recordings = root / "var" / "lib" / "posed" / "recordings";
  struct stat st {};
  ASSERT_EQ(::stat(recordings.c_str(), &st), 0) << recordings << " was not created";
  EXPECT_TRUE(S_ISDIR(st.st_mode));
  EXPECT_EQ(st.st_mode & 07777, 0750u);
  EXPECT_EQ(std::to_string(st.st_uid), user[1].str()) << "recordings not owned by posed";
  EXPECT_EQ(std::to_string(st.st_gid), user[2].str()) << "recordings not group posed";
}

TEST(SystemdUnit, LimitRtprioMatchesTheConfigPriorityCap) {
  const fs::path unit = source_dir() / "systemd" / "posed.service";
  const std::string text = read_file(unit);
  std::smatch match;
  ASSERT_TRUE(std::regex_search(text, match, std::regex(R"((?:^|\n)LimitRTPRIO=(\d+))")))
      << unit << " has no LimitRTPRIO=";
  const int limit = std::stoi(match[1].str());

  // The shipped configuration stays within the limit...
  const fs::path config_path = source_dir() / "config" / "posed.yaml";
  const config::LoadResult shipped = config::load_config_file(config_path.string());
  ASSERT_TRUE(shipped.ok()) << shipped.error_text();
  const auto& threads = shipped.config.threads;
  const int highest =
      std::max({threads.imu_source.priority, threads.lidar_source.priority, threads.fusion.priority,
                threads.camera_source.priority, threads.camera_frontend.priority,
                threads.publisher.priority, threads.lidar_helper.priority});
  EXPECT_LE(highest, limit) << config_path << " asks for SCHED_FIFO " << highest << " but " << unit
                            << " allows " << limit;

  // ...and the schema's cap is exactly the limit: every priority the config accepts is one
  // systemd grants, and no priority systemd grants is refused by the config.
  const auto with_priority = [](int priority) {
    return config::load_config_text(
        "threads:\n  fusion:\n    priority: " + std::to_string(priority) + "\n", "test.yaml");
  };
  const config::LoadResult at_limit = with_priority(limit);
  EXPECT_TRUE(at_limit.ok()) << at_limit.error_text();
  EXPECT_FALSE(with_priority(limit + 1).ok())
      << "config accepts SCHED_FIFO " << limit + 1 << " but LimitRTPRIO=" << limit;
}

}  // namespace
}  // namespace posed
