// PtyEmitter on a real pseudo-terminal: the symlink, raw bytes through the line discipline
// untouched, bytes without a reader discarded (as a UART would), the reader coming and going,
// overrun when the reader does not read, and the symlink's life cycle.

#include "tools/hil/pty_emitter.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include "tests/unit/hil/recording_builder.hpp"

namespace posed::hil {
namespace pty_emitter_test {

/// Opens the device the way a serial driver does (non-blocking, no controlling tty).
int open_reader(const std::string& path) {
  return ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
}

/// Reads until `n` bytes arrived or 2 s passed without any.
std::vector<std::byte> read_bytes(int fd, std::size_t n) {
  std::vector<std::byte> out;
  while (out.size() < n) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 2000) != 1) break;
    std::byte buf[4096];
    const ssize_t got = ::read(fd, buf, sizeof buf);
    if (got <= 0) break;
    out.insert(out.end(), buf, buf + got);
  }
  return out;
}

TEST(PtyEmitter, BytesReachAReaderOfTheLinkUntouched) {
  test::TempDir dir("pty_raw");
  const std::string link = dir.file("a9");
  PtyEmitter pty(link);
  std::string error;
  ASSERT_TRUE(pty.open(error)) << error;
  ASSERT_TRUE(std::filesystem::is_symlink(link));
  EXPECT_EQ(std::filesystem::read_symlink(link).string(), pty.slave_path());
  EXPECT_EQ(pty.slave_path().rfind("/dev/pts/", 0), 0u) << pty.slave_path();

  const int fd = open_reader(link);
  ASSERT_GE(fd, 0);
  EXPECT_TRUE(pty.has_reader());
  termios tio{};
  ASSERT_EQ(::tcgetattr(fd, &tio), 0);
  // Raw before any reader configures it: no echo, no canonical lines, no CR/LF translation.
  EXPECT_EQ(tio.c_lflag & (ICANON | ECHO | ISIG), 0u);
  EXPECT_EQ(tio.c_iflag & (ICRNL | IXON), 0u);

  std::vector<std::byte> sent;
  for (std::uint32_t i = 0; i < 40; ++i) {
    const auto frame = test::payload(0, i, 49);  // CR, LF, ^C, XON, XOFF, DEL, ^D, ^Z in each
    ASSERT_TRUE(pty.write(frame)) << i;
    sent.insert(sent.end(), frame.begin(), frame.end());
  }
  EXPECT_EQ(read_bytes(fd, sent.size()), sent);
  const PtyCounters c = pty.counters();
  EXPECT_EQ(c.writes, 40u);
  EXPECT_EQ(c.bytes, sent.size());
  EXPECT_EQ(c.bytes_no_reader, 0u);
  EXPECT_EQ(c.bytes_overrun, 0u);
  ::close(fd);
}

TEST(PtyEmitter, WithoutAReaderBytesAreDiscardedNotKeptForLater) {
  test::TempDir dir("pty_noreader");
  PtyEmitter pty(dir.file("a9"));
  std::string error;
  ASSERT_TRUE(pty.open(error)) << error;
  EXPECT_FALSE(pty.has_reader());
  const auto early = test::payload(0, 1, 20);
  EXPECT_FALSE(pty.write(early));
  EXPECT_EQ(pty.counters().bytes_no_reader, 20u);

  // A reader that opens later gets what is written from then on, not the old bytes.
  const int fd = open_reader(dir.file("a9"));
  ASSERT_GE(fd, 0);
  const auto late = test::payload(0, 2, 20);
  ASSERT_TRUE(pty.write(late));
  EXPECT_EQ(read_bytes(fd, 20), late);
  ::close(fd);

  // Gone again: discarded again.
  EXPECT_FALSE(pty.has_reader());
  EXPECT_FALSE(pty.write(late));
  EXPECT_EQ(pty.counters().bytes_no_reader, 40u);
}

TEST(PtyEmitter, WaitForReaderReturnsOnceOneOpensOrWhenStopped) {
  test::TempDir dir("pty_wait");
  PtyEmitter pty(dir.file("a9"));
  std::string error;
  ASSERT_TRUE(pty.open(error)) << error;
  std::atomic<bool> stop{true};
  EXPECT_FALSE(pty.wait_for_reader(Duration::from_s(3600), stop));  // the flag, not the hour
  stop.store(false);
  const int fd = open_reader(dir.file("a9"));
  ASSERT_GE(fd, 0);
  EXPECT_TRUE(pty.wait_for_reader(Duration::from_s(3600), stop));
  ::close(fd);
}

TEST(PtyEmitter, AReaderThatDoesNotReadCausesCountedOverrunNotABlock) {
  test::TempDir dir("pty_overrun");
  PtyEmitter pty(dir.file("a9"));
  std::string error;
  ASSERT_TRUE(pty.open(error)) << error;
  const int fd = open_reader(dir.file("a9"));
  ASSERT_GE(fd, 0);
  const std::vector<std::byte> block(4096, std::byte{0x55});
  std::uint64_t offered = 0;
  // A pty holds some kB; a megabyte cannot fit, and write() must not block meanwhile.
  for (int i = 0; i < 256; ++i) {
    pty.write(block);
    offered += block.size();
  }
  const PtyCounters c = pty.counters();
  EXPECT_GT(c.bytes_overrun, 0u);
  EXPECT_EQ(c.bytes + c.bytes_overrun, offered);
  ::close(fd);
}

TEST(PtyEmitter, WhatTheReaderWritesIsDrained) {
  test::TempDir dir("pty_drain");
  PtyEmitter pty(dir.file("a9"));
  std::string error;
  ASSERT_TRUE(pty.open(error)) << error;
  const int fd = open_reader(dir.file("a9"));
  ASSERT_GE(fd, 0);
  const char command[] = "$CFG,RATE,150\r\n";
  ASSERT_EQ(::write(fd, command, sizeof command - 1), static_cast<ssize_t>(sizeof command - 1));
  for (int i = 0; i < 200 && pty.counters().bytes_from_reader < sizeof command - 1; ++i) {
    pty.has_reader();
    ::usleep(5000);
  }
  EXPECT_EQ(pty.counters().bytes_from_reader, sizeof command - 1);
  ::close(fd);
}

TEST(PtyEmitter, TheLinkReplacesAStaleLinkAndIsRemovedAtTheEnd) {
  test::TempDir dir("pty_link");
  const std::string link = dir.file("a9");
  std::filesystem::create_symlink("/dev/pts/stale", link);
  {
    PtyEmitter pty(link);
    std::string error;
    ASSERT_TRUE(pty.open(error)) << error;
    EXPECT_EQ(std::filesystem::read_symlink(link).string(), pty.slave_path());
  }
  EXPECT_FALSE(std::filesystem::is_symlink(link));
  EXPECT_FALSE(std::filesystem::exists(link));
}

TEST(PtyEmitter, ALinkTakenOverByAnotherReplayIsLeftAlone) {
  test::TempDir dir("pty_takeover");
  const std::string link = dir.file("a9");
  PtyEmitter second(link);
  {
    PtyEmitter first(link);
    std::string error;
    ASSERT_TRUE(first.open(error)) << error;
    ASSERT_TRUE(second.open(error)) << error;
  }
  ASSERT_TRUE(std::filesystem::is_symlink(link));
  EXPECT_EQ(std::filesystem::read_symlink(link).string(), second.slave_path());
}

TEST(PtyEmitter, AFileAtTheLinkPathIsNotReplaced) {
  test::TempDir dir("pty_file");
  const std::string path = dir.file("precious");
  std::ofstream(path) << "keep me";
  PtyEmitter pty(path);
  std::string error;
  EXPECT_FALSE(pty.open(error));
  EXPECT_NE(error.find("not a symlink"), std::string::npos) << error;
  EXPECT_NE(error.find(path), std::string::npos) << error;
  std::ifstream in(path);
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "keep me");
}

}  // namespace pty_emitter_test
}  // namespace posed::hil
