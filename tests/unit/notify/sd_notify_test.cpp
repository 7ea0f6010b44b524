#include "daemon/notify/sd_notify.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

#include "tests/unit/notify/fake_notify_socket.hpp"

namespace posed::notify {
namespace {

using testing::FakeNotifySocket;
using testing::ScopedEnv;

class SdNotifyOverSocket : public ::testing::TestWithParam<FakeNotifySocket::Kind> {};

TEST_P(SdNotifyOverSocket, MessagesArriveExactlyAsSent) {
  FakeNotifySocket fake(GetParam());
  const ScopedEnv socket_env("NOTIFY_SOCKET", fake.address().c_str());
  SdNotifier notifier;  // reads the environment, as the daemon does
  ASSERT_TRUE(notifier.under_systemd());
  EXPECT_EQ(notifier.socket_address(), fake.address());

  for (const std::string& message :
       {ready_message(), status_message("aligning: imu 150 Hz; lidar waiting"), watchdog_message(),
        stopping_message()}) {
    const NotifyResult result = notifier.notify(message);
    EXPECT_EQ(result.status, NotifyStatus::kSent) << result.error;
    EXPECT_EQ(fake.receive(), message);
  }
  EXPECT_EQ(fake.receive(), std::nullopt) << "one datagram per notify()";
}

TEST_P(SdNotifyOverSocket, SeveralLinesTravelAsOneDatagram) {
  FakeNotifySocket fake(GetParam());
  SdNotifier notifier(fake.address(), std::nullopt);
  const std::string message = ready_message() + "\n" + status_message("running");
  EXPECT_EQ(notifier.notify(message).status, NotifyStatus::kSent);
  EXPECT_EQ(fake.receive(), "READY=1\nSTATUS=running");
  EXPECT_EQ(fake.receive(), std::nullopt);
}

INSTANTIATE_TEST_SUITE_P(PathAndAbstract, SdNotifyOverSocket,
                         ::testing::Values(FakeNotifySocket::Kind::kPath,
                                           FakeNotifySocket::Kind::kAbstract),
                         [](const auto& param_info) {
                           return param_info.param == FakeNotifySocket::Kind::kPath ? "Path"
                                                                                    : "Abstract";
                         });

TEST(SdNotify, DoesNothingWithoutNotifySocket) {
  FakeNotifySocket fake(FakeNotifySocket::Kind::kPath);  // listening, but nobody names it
  const ScopedEnv socket_env("NOTIFY_SOCKET", nullptr);
  const ScopedEnv usec_env("WATCHDOG_USEC", nullptr);
  SdNotifier notifier;
  EXPECT_FALSE(notifier.under_systemd());
  EXPECT_EQ(notifier.watchdog_interval(), std::nullopt);
  for (const std::string& message : {ready_message(), watchdog_message(), status_message("x")}) {
    const NotifyResult result = notifier.notify(message);
    EXPECT_EQ(result.status, NotifyStatus::kNotUnderSystemd);
    EXPECT_FALSE(result.failed());
    EXPECT_TRUE(result.error.empty());
  }
  EXPECT_EQ(fake.receive(), std::nullopt);
}

TEST(SdNotify, RelativeAddressIsAnErrorNamingIt) {
  SdNotifier notifier("run/notify", std::nullopt);
  const NotifyResult result = notifier.notify(ready_message());
  EXPECT_EQ(result.status, NotifyStatus::kFailed);
  EXPECT_NE(result.error.find("run/notify"), std::string::npos) << result.error;
}

TEST(SdNotify, TooLongAddressIsAnError) {
  SdNotifier notifier("/" + std::string(200, 'x'), std::nullopt);
  const NotifyResult result = notifier.notify(ready_message());
  EXPECT_EQ(result.status, NotifyStatus::kFailed);
  EXPECT_NE(result.error.find("longer than"), std::string::npos) << result.error;
}

TEST(SdNotify, MissingReceiverIsAnErrorWithPathAndErrnoText) {
  std::string missing;
  {
    FakeNotifySocket gone(FakeNotifySocket::Kind::kPath);
    missing = gone.address();
  }  // the socket file and its directory are removed here
  SdNotifier notifier(missing, std::nullopt);
  const NotifyResult result = notifier.notify(watchdog_message());
  EXPECT_EQ(result.status, NotifyStatus::kFailed);
  EXPECT_NE(result.error.find(missing), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("No such file"), std::string::npos) << result.error;
}

TEST(SdNotify, EmptyMessageIsRefused) {
  FakeNotifySocket fake(FakeNotifySocket::Kind::kAbstract);
  SdNotifier notifier(fake.address(), std::nullopt);
  EXPECT_EQ(notifier.notify("").status, NotifyStatus::kFailed);
  EXPECT_EQ(fake.receive(), std::nullopt);
}

TEST(WatchdogEnvironment, ParsesUsecAndChecksPid) {
  const pid_t self = 4242;
  EXPECT_EQ(parse_watchdog_timeout("5000000", nullptr, self), Duration::from_s(5));
  EXPECT_EQ(parse_watchdog_timeout("5000000", "4242", self), Duration::from_s(5));
  EXPECT_EQ(parse_watchdog_timeout("1", "4242", self), Duration::from_us(1));
  // Inherited by a child: not ours to feed.
  EXPECT_EQ(parse_watchdog_timeout("5000000", "4243", self), std::nullopt);
  EXPECT_EQ(parse_watchdog_timeout("5000000", "", self), std::nullopt);
  EXPECT_EQ(parse_watchdog_timeout("5000000", "42x", self), std::nullopt);
  // No watchdog, or garbage.
  EXPECT_EQ(parse_watchdog_timeout(nullptr, nullptr, self), std::nullopt);
  EXPECT_EQ(parse_watchdog_timeout("0", nullptr, self), std::nullopt);
  EXPECT_EQ(parse_watchdog_timeout("", nullptr, self), std::nullopt);
  EXPECT_EQ(parse_watchdog_timeout("-5", nullptr, self), std::nullopt);
  EXPECT_EQ(parse_watchdog_timeout("5s", nullptr, self), std::nullopt);
  EXPECT_EQ(parse_watchdog_timeout("99999999999999999999", nullptr, self), std::nullopt);
}

TEST(WatchdogEnvironment, NotifierReadsItFromTheEnvironment) {
  const std::string self = std::to_string(::getpid());
  const ScopedEnv socket_env("NOTIFY_SOCKET", "@posed-unused");
  const ScopedEnv usec_env("WATCHDOG_USEC", "4000000");
  {
    const ScopedEnv pid_env("WATCHDOG_PID", self.c_str());
    EXPECT_EQ(SdNotifier().watchdog_interval(), Duration::from_s(4));
  }
  {
    const ScopedEnv pid_env("WATCHDOG_PID", "1");
    EXPECT_EQ(SdNotifier().watchdog_interval(), std::nullopt);
  }
}

TEST(SdNotifyMessages, SpellingMatchesSdNotify) {
  EXPECT_EQ(ready_message(), "READY=1");
  EXPECT_EQ(watchdog_message(), "WATCHDOG=1");
  EXPECT_EQ(stopping_message(), "STOPPING=1");
  EXPECT_EQ(status_message("fusion stalled"), "STATUS=fusion stalled");
  EXPECT_EQ(monotonic_usec_message(HostTime::from_ns(1'234'567'891)), "MONOTONIC_USEC=1234567");
  EXPECT_EQ(reloading_message(HostTime::from_ns(2'000'000'999)),
            "RELOADING=1\nMONOTONIC_USEC=2000000");
  EXPECT_EQ(errno_message(5), "ERRNO=5");
}

}  // namespace
}  // namespace posed::notify
