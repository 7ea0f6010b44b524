#pragma once
// Where the shared real sensor data lives (never copied into the repo): $POSED_REALDATA, else
// ${POSED_SOURCE_DIR}/../shared/realdata. Tests GTEST_SKIP() with the reason when it is absent.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace posed::test {

inline std::string realdata_path(const std::string& relative) {
  std::filesystem::path base;
  if (const char* env = std::getenv("POSED_REALDATA")) {
    base = env;
  } else if (const char* src = std::getenv("POSED_SOURCE_DIR")) {
    base = std::filesystem::path(src) / ".." / "shared" / "realdata";
  } else {
    base = std::filesystem::path(__FILE__).parent_path() / ".." / ".." / ".." / ".." / "shared" /
           "realdata";
  }
  const auto p = base / relative;
  return std::filesystem::exists(p) ? p.string() : std::string{};
}

inline std::vector<std::byte> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<char> chars((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::byte> out(chars.size());
  for (std::size_t i = 0; i < chars.size(); ++i) out[i] = static_cast<std::byte>(chars[i]);
  return out;
}

}  // namespace posed::test

#define POSED_REQUIRE_REALDATA(var, relative)                                                 \
  const std::string var = ::posed::test::realdata_path(relative);                             \
  if (var.empty()) {                                                                          \
    GTEST_SKIP() << "real data " << (relative)                                                \
                 << " not found (set POSED_REALDATA or put shared/realdata beside the repo)"; \
  }
