// End to end with an independent reader: the npm package @foxglove/ws-protocol's FoxgloveClient
// (tests/node/foxglove_client.mjs, run by Node) subscribes to every channel the server
// advertises; the messages, payload bytes, contents and log times it counts per channel must be
// exactly what was published. Node and the npm modules are test dependencies that
// tools/install-deps installs: when they are missing this test fails saying so, never skips.

#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "daemon/foxglove/server.hpp"

extern char** environ;

namespace posed::foxglove {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace std::chrono_literals;

fs::path source_dir() {
  const char* from_ctest = std::getenv("POSED_SOURCE_DIR");
  return from_ctest != nullptr ? fs::path(from_ctest) : fs::path(POSED_SOURCE_DIR_DEFAULT);
}

/// A child process with its stdout on a pipe.
struct Child {
  pid_t pid = -1;
  int stdout_fd = -1;
};

/// Starts `argv` (searched on PATH). Returns "" or why it could not start.
std::string spawn(const std::vector<std::string>& args, Child& child) {
  std::array<int, 2> pipe_fds{};
  if (::pipe(pipe_fds.data()) != 0) return std::string("pipe: ") + std::strerror(errno);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[0]);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[1]);
  std::vector<char*> argv;
  for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  const int rc = posix_spawnp(&child.pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipe_fds[1]);
  if (rc != 0) {
    ::close(pipe_fds[0]);
    return args[0] + ": " + std::strerror(rc);
  }
  child.stdout_fd = pipe_fds[0];
  return "";
}

/// Reads the child's stdout to its end and reaps it; returns the output and sets exit_status.
std::string finish(Child& child, int& exit_status) {
  std::string output;
  std::array<char, 4096> chunk{};
  for (;;) {
    const ssize_t n = ::read(child.stdout_fd, chunk.data(), chunk.size());
    if (n > 0) {
      output.append(chunk.data(), static_cast<std::size_t>(n));
    } else if (n == 0 || errno != EINTR) {
      break;
    }
  }
  ::close(child.stdout_fd);
  int status = 0;
  ::waitpid(child.pid, &status, 0);
  exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return output;
}

/// Whether the child has exited, leaving it to finish() to reap.
bool child_exited(const Child& child) {
  siginfo_t info{};
  return ::waitid(P_PID, static_cast<id_t>(child.pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 &&
         info.si_pid == child.pid;
}

/// FNV-1a, 32 bit, as foxglove_client.mjs computes it.
std::uint32_t fnv1a(std::uint32_t hash, const std::vector<std::byte>& bytes) {
  for (const std::byte b : bytes) {
    hash ^= std::to_integer<std::uint32_t>(b);
    hash *= 0x01000193u;
  }
  return hash;
}

struct Published {
  ChannelSpec spec;
  int messages = 0;
  std::size_t payload_bytes = 0;  ///< of each message [B]
  ChannelId id = 0;
  std::size_t total_bytes = 0;
  std::uint32_t hash = 0x811c9dc5u;
  std::int64_t first_ns = 0;
  std::int64_t last_ns = 0;
};

/// Known bytes: every message differs, so a lost, repeated or reordered one changes the hash.
std::vector<std::byte> payload_of(std::size_t channel_index, int message, std::size_t size) {
  std::vector<std::byte> bytes(size);
  for (std::size_t i = 0; i < size; ++i) {
    bytes[i] = static_cast<std::byte>(
        (channel_index * 31 + static_cast<std::size_t>(message) * 7 + i) & 0xFFu);
  }
  return bytes;
}

TEST(FoxgloveNodeClient, CountsBytesAndContentsPerChannelMatchWhatWasPublished) {
  const fs::path node_dir = source_dir() / "tests" / "node";
  ASSERT_TRUE(
      fs::exists(node_dir / "node_modules" / "@foxglove" / "ws-protocol" / "package.json") &&
      fs::exists(node_dir / "node_modules" / "ws" / "package.json"))
      << node_dir / "node_modules"
      << " lacks @foxglove/ws-protocol or ws: run tools/install-deps (npm ci in tests/node)";

  ServerOptions options;
  options.port = 0;
  std::string error;
  auto server = Server::start(options, error);
  ASSERT_NE(server, nullptr) << error;
  std::vector<Published> channels{
      {{"/posed/odom", "cdr", "nav_msgs/msg/Odometry", "ros2msg", "std_msgs/Header header\n"},
       300,
       720},
      {{"/posed/path", "cdr", "nav_msgs/msg/Path", "ros2msg", "std_msgs/Header header\n"},
       30,
       40000},
      {{"/diagnostics", "cdr", "diagnostic_msgs/msg/DiagnosticArray", "ros2msg",
        "std_msgs/Header header\n"},
       60,
       1500},
  };
  int total_messages = 0;
  for (Published& channel : channels) {
    channel.id = server->add_channel(channel.spec);
    total_messages += channel.messages;
  }

  const char* node_from_env = std::getenv("POSED_NODE");
  const std::string node = node_from_env != nullptr ? node_from_env : "node";
  Child child;
  const std::string spawn_error =
      spawn({node, (node_dir / "foxglove_client.mjs").string(),
             "ws://127.0.0.1:" + std::to_string(server->port()), "--messages",
             std::to_string(total_messages), "--seconds", "20"},
            child);
  ASSERT_EQ(spawn_error, "") << "cannot run Node.js (tools/install-deps installs it; POSED_NODE "
                                "names another binary)";

  // Node takes a few hundred milliseconds to start; publish once it subscribes to every channel.
  const auto deadline = std::chrono::steady_clock::now() + 15s;
  const auto all_subscribed = [&] {
    for (const Published& channel : channels) {
      if (!server->has_subscribers(channel.id)) return false;
    }
    return true;
  };
  while (!all_subscribed() && !child_exited(child) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(5ms);
  }
  const bool subscribed = all_subscribed();

  const auto start = std::chrono::steady_clock::now();
  const std::int64_t t0_ns = 1'700'000'000'000'000'000;
  for (int message = 0; subscribed && message < 300; ++message) {
    for (std::size_t c = 0; c < channels.size(); ++c) {
      Published& channel = channels[c];
      if (message >= channel.messages) continue;
      const std::vector<std::byte> payload = payload_of(c, message, channel.payload_bytes);
      const std::int64_t t_ns = t0_ns + message * 1'000'000 + static_cast<std::int64_t>(c);
      server->publish(channel.id, t_ns, payload);
      channel.total_bytes += payload.size();
      channel.hash = fnv1a(channel.hash, payload);
      if (message == 0) channel.first_ns = t_ns;
      channel.last_ns = t_ns;
    }
  }

  int exit_status = -1;
  const std::string output = finish(child, exit_status);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(subscribed) << "the Node client did not subscribe to every channel; it printed: "
                          << output;
  ASSERT_EQ(exit_status, 0) << output;
  const json report = json::parse(output, nullptr, false);
  ASSERT_FALSE(report.is_discarded()) << output;
  std::printf(
      "[ node ] %d messages on %zu channels received by @foxglove/ws-protocol in %.0f ms: %s\n",
      total_messages, channels.size(), ms, output.c_str());

  EXPECT_FALSE(report["timedOut"].get<bool>());
  EXPECT_EQ(report["serverInfo"]["name"], "posed");
  EXPECT_EQ(report["statuses"], json::array());
  // posed counts a message sent when its write completes, which may trail the reader a little.
  const auto counted_deadline = std::chrono::steady_clock::now() + 2s;
  const auto all_counted = [&] {
    const ServerStats now = server->stats();
    for (const Published& channel : channels) {
      if (now.channels.at(channel.id - 1).messages_sent !=
          static_cast<std::uint64_t>(channel.messages)) {
        return false;
      }
    }
    return true;
  };
  while (!all_counted() && std::chrono::steady_clock::now() < counted_deadline) {
    std::this_thread::sleep_for(1ms);
  }
  const ServerStats stats = server->stats();
  for (const Published& channel : channels) {
    SCOPED_TRACE(channel.spec.topic);
    ASSERT_TRUE(report["channels"].contains(channel.spec.topic));
    const json& seen = report["channels"][channel.spec.topic];
    EXPECT_EQ(seen["id"], channel.id);
    EXPECT_EQ(seen["encoding"], "cdr");
    EXPECT_EQ(seen["schemaName"], channel.spec.schema_name);
    EXPECT_EQ(seen["schemaEncoding"], "ros2msg");
    EXPECT_EQ(seen["schemaBytes"], channel.spec.schema.size());
    EXPECT_EQ(seen["messages"], channel.messages);
    EXPECT_EQ(seen["bytes"], channel.total_bytes);
    char hash[9];
    std::snprintf(hash, sizeof hash, "%08x", channel.hash);
    EXPECT_EQ(seen["fnv1a"], hash);
    EXPECT_EQ(seen["firstLogTimeNs"], std::to_string(channel.first_ns));
    EXPECT_EQ(seen["lastLogTimeNs"], std::to_string(channel.last_ns));

    // posed's own count agrees with the reader's.
    const ChannelStats& counted = stats.channels.at(channel.id - 1);
    EXPECT_EQ(counted.messages_published, static_cast<std::uint64_t>(channel.messages));
    EXPECT_EQ(counted.messages_sent, static_cast<std::uint64_t>(channel.messages));
    EXPECT_EQ(counted.messages_dropped, 0u);
    EXPECT_EQ(counted.bytes_sent, channel.total_bytes + channel.messages * kMessageDataHeaderBytes);
  }
}

}  // namespace
}  // namespace posed::foxglove
