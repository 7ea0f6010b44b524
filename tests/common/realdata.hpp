#pragma once
// Where the shared real sensor data lives (never copied into the repository): $POSED_REALDATA,
// else ${POSED_SOURCE_DIR}/../shared/realdata (the environment, or the source tree the test was
// built from). Tests GTEST_SKIP() with the reason when it is absent.

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace posed::test {

/// The real-data folder; empty when there is none.
inline std::filesystem::path realdata_dir() {
  namespace fs = std::filesystem;
  if (const char* env = std::getenv("POSED_REALDATA"); env != nullptr && fs::is_directory(env)) {
    return env;
  }
  const char* src = std::getenv("POSED_SOURCE_DIR");
  const fs::path root = src != nullptr ? fs::path(src) : fs::path(POSED_SOURCE_DIR_DEFAULT);
  const fs::path p = root / ".." / "shared" / "realdata";
  return fs::is_directory(p) ? p : fs::path{};
}

/// `relative` inside the real-data folder; empty when it does not exist.
inline std::string realdata_path(const std::string& relative) {
  const std::filesystem::path dir = realdata_dir();
  if (dir.empty()) return {};
  const std::filesystem::path p = dir / relative;
  return std::filesystem::exists(p) ? p.string() : std::string{};
}

/// A whole file as bytes (empty when unreadable).
inline std::vector<std::uint8_t> read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The same as std::byte, for decoders that take std::span<const std::byte>.
inline std::vector<std::byte> read_std_bytes(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> u8 = read_bytes(path);
  std::vector<std::byte> out(u8.size());
  for (std::size_t i = 0; i < u8.size(); ++i) out[i] = static_cast<std::byte>(u8[i]);
  return out;
}

}  // namespace posed::test

/// Declares `var` as the path of `relative` in the real-data folder, or skips the test saying why.
#define POSED_REQUIRE_REALDATA(var, relative)                                                 \
  const std::string var = ::posed::test::realdata_path(relative);                             \
  if (var.empty()) {                                                                          \
    GTEST_SKIP() << "real data " << (relative)                                                \
                 << " not found (set POSED_REALDATA or put shared/realdata beside the repo)"; \
  }
