#pragma once
// Shared by the DDS tests: a DdsConfig on the loopback Cyclone config and a random domain id in
// 100..200, so tests running in parallel (ctest -j) rarely meet; tests that publish still check
// a per-run token so a stranger on the same domain cannot make them pass.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <random>
#include <string>
#include <thread>

#include "daemon/dds/messages.hpp"

namespace posed::dds::test {

inline std::string loopback_xml_path() {
  const char* source_dir = std::getenv("POSED_SOURCE_DIR");
  return std::string(source_dir != nullptr ? source_dir : POSED_TEST_SOURCE_DIR) +
         "/config/cyclonedds-loopback.xml";
}

inline std::uint32_t random_domain_id() {
  std::random_device rd;
  return std::uniform_int_distribution<std::uint32_t>(100, 200)(rd);
}

inline DdsConfig loopback_config() {
  DdsConfig config;
  config.domain_id = random_domain_id();
  config.cyclonedds_xml_path = loopback_xml_path();
  return config;
}

/// Polls `ready` until true or 10 s pass (discovery over loopback takes milliseconds).
template <class Ready>
bool eventually(Ready ready) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < deadline) {
    if (ready()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return ready();
}

}  // namespace posed::dds::test
