#pragma once
// Locates the shared real-data folder for tests: $POSED_REALDATA, else
// ${POSED_SOURCE_DIR}/../shared/realdata. Empty when neither exists (tests then GTEST_SKIP).

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace posed::test {

inline std::filesystem::path realdata_dir() {
  namespace fs = std::filesystem;
  if (const char* env = std::getenv("POSED_REALDATA"); env != nullptr && fs::is_directory(env)) {
    return env;
  }
  if (const char* src = std::getenv("POSED_SOURCE_DIR"); src != nullptr) {
    const fs::path p = fs::path(src) / ".." / "shared" / "realdata";
    if (fs::is_directory(p)) return p;
  }
  return {};
}

inline std::vector<std::uint8_t> read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace posed::test
