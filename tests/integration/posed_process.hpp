#pragma once
// Runs the posed executable as a separate process, the way systemd or a user would, with its
// output captured to files and signals delivered for real.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace posed::testing {

inline std::string source_dir() {
  const char* s = std::getenv("POSED_SOURCE_DIR");
  return s ? s : POSED_SOURCE_DIR_DEFAULT;
}
/// Cyclone DDS on loopback only, as every test runs it (no test talks to the network).
inline std::string loopback_xml() { return source_dir() + "/config/cyclonedds-loopback.xml"; }
/// posed.yaml's `dds:` section for a test: a domain of its own, Cyclone on loopback.
inline std::string loopback_dds_yaml(int domain_id) {
  return "dds:\n  domain_id: " + std::to_string(domain_id) +
         "\n  cyclonedds_config: " + loopback_xml() + "\n";
}
inline std::string build_dir() {
  const char* s = std::getenv("POSED_BUILD_DIR");
  return s ? s : POSED_BUILD_DIR_DEFAULT;
}

/// The posectl that simulates a test's input: this build's, or POSED_SIMULATOR's. The
/// simulator makes the input, it is not under test; tools/sanitize-pipeline points this at a
/// release build, since the renderer under ThreadSanitizer runs at a twentieth of real time.
inline std::string simulator() {
  const char* s = std::getenv("POSED_SIMULATOR");
  return s ? s : build_dir() + "/tools/posectl/posectl";
}

/// A fresh directory under /tmp, removed with its files when the object dies.
class TempDir {
 public:
  TempDir() {
    char pattern[] = "/tmp/posed-test-XXXXXX";
    path_ = ::mkdtemp(pattern);
  }
  ~TempDir() { std::system(("rm -rf '" + path_ + "'").c_str()); }
  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(file(name)) << text;
    return file(name);
  }

 private:
  std::string path_;
};

inline std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class PosedProcess {
 public:
  /// Starts `argv` (argv[0] a path) with extra environment; `set_watchdog_pid` puts the child's
  /// own pid in WATCHDOG_PID, as systemd does.
  PosedProcess(const std::vector<std::string>& argv, const std::vector<std::string>& env,
               const TempDir& dir, bool set_watchdog_pid = false)
      : stdout_path_(dir.file("stdout.txt")), stderr_path_(dir.file("stderr.txt")) {
    // The child's freopen() flushes what it inherited in stdio's buffers to the test's own
    // output: empty them first, or the test's lines appear once per child.
    std::fflush(nullptr);
    pid_ = ::fork();
    if (pid_ == 0) {
      for (const auto& e : env) ::putenv(const_cast<char*>(e.c_str()));
      if (set_watchdog_pid) ::setenv("WATCHDOG_PID", std::to_string(::getpid()).c_str(), 1);
      std::freopen(stdout_path_.c_str(), "w", stdout);
      std::freopen(stderr_path_.c_str(), "w", stderr);
      std::vector<char*> args;
      for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      ::execv(args[0], args.data());
      std::_Exit(127);
    }
  }
  ~PosedProcess() {
    if (pid_ > 0 && !exited_) {
      ::kill(pid_, SIGKILL);
      int status = 0;
      ::waitpid(pid_, &status, 0);
    }
  }

  pid_t pid() const { return pid_; }
  void signal(int sig) const { ::kill(pid_, sig); }

  /// The exit code once the process ended within `timeout`; -1 for death by a signal.
  std::optional<int> wait_for_exit(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return std::nullopt;
  }

  std::string out() const { return read_file(stdout_path_); }
  std::string err() const { return read_file(stderr_path_); }

 private:
  std::string stdout_path_;
  std::string stderr_path_;
  pid_t pid_ = -1;
  bool exited_ = false;
};

}  // namespace posed::testing
