// posectl unit-dropin --config /etc/posed/posed.yaml [--dds-peer ADDR[/PREFIX]]...: prints a
// systemd drop-in for posed.service that narrows what the shipped unit allows to what this
// configuration uses. The shipped unit allows loopback, link-local, the private ranges and
// multicast (any LAN a robot may have); the drop-in allows loopback, multicast (DDS discovery),
// the lidar's address (lidar.source udp), the DDS peers named in the config's Cyclone XML
// (<Peer address=...>) and on the command line, and adds AF_CAN when imu.source is can.
//   posectl unit-dropin --config /etc/posed/posed.yaml |
//     sudo tee /etc/systemd/system/posed.service.d/50-network.conf
// Exit codes: 0 printed, 2 bad arguments or config.

#include <arpa/inet.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "daemon/config/config_loader.hpp"
#include "tools/posectl/commands.hpp"

namespace posed::posectl {
namespace {

/// "192.168.1.201", "10.0.0.0/8" or "fd00::/8": an address systemd's IPAddressAllow= takes.
bool valid_address(const std::string& text) {
  const auto slash = text.find('/');
  const std::string address = text.substr(0, slash);
  unsigned char buffer[16];
  const bool v4 = ::inet_pton(AF_INET, address.c_str(), buffer) == 1;
  const bool v6 = !v4 && ::inet_pton(AF_INET6, address.c_str(), buffer) == 1;
  if (!v4 && !v6) return false;
  if (slash == std::string::npos) return true;
  const std::string prefix = text.substr(slash + 1);
  if (prefix.empty() || prefix.find_first_not_of("0123456789") != std::string::npos) return false;
  return std::stoi(prefix) <= (v4 ? 32 : 128);
}

/// The addresses of <Peer address="..."/> in a Cyclone DDS XML file ("localhost" kept as is).
std::vector<std::string> cyclone_peers(const std::string& xml_path, std::string& error) {
  std::ifstream in(xml_path);
  if (!in) {
    error = "cyclonedds config " + xml_path + ": cannot open";
    return {};
  }
  std::stringstream text;
  text << in.rdbuf();
  const std::string xml = text.str();
  std::vector<std::string> peers;
  const std::regex peer(R"re(<Peer\s+[^>]*address\s*=\s*"([^"]+)")re");
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), peer); it != std::sregex_iterator();
       ++it) {
    std::string address = (*it)[1].str();
    // Cyclone peers may carry a port ("10.0.0.5:7410"); the allow-list takes the address.
    if (std::count(address.begin(), address.end(), ':') == 1) address.resize(address.find(':'));
    peers.push_back(address);
  }
  return peers;
}

}  // namespace

int run_unit_dropin(int argc, char** argv) {
  CLI::App app{
      "Print a systemd drop-in for posed.service that narrows its IP allow-list and address "
      "families to what CONFIG uses (install as "
      "/etc/systemd/system/posed.service.d/50-network.conf, then systemctl daemon-reload)",
      "posectl unit-dropin"};
  std::string config_path;
  std::vector<std::string> extra_peers;
  app.add_option("--config", config_path, "posed's configuration (/etc/posed/posed.yaml)")
      ->required();
  app.add_option("--dds-peer", extra_peers,
                 "an address or ADDR/PREFIX of hosts whose DDS participants read posed's topics "
                 "(repeatable); the config's Cyclone XML peers are added by themselves");
  CLI11_PARSE(app, argc, argv);

  const config::LoadResult loaded = config::load_config_file(config_path);
  if (!loaded.ok()) {
    std::fprintf(stderr, "posectl unit-dropin: invalid configuration:\n%s\n",
                 loaded.error_text().c_str());
    return 2;
  }
  const config::PosedConfig& cfg = loaded.config;

  struct Allowed {
    std::string address;
    std::string why;
  };
  std::vector<Allowed> allowed = {{"localhost", "posectl, tools and DDS readers on this host"},
                                  {"multicast", "DDS discovery (SPDP, 239.255.0.1)"}};
  if (cfg.lidar.enabled && cfg.lidar.source == "udp") {
    if (!valid_address(cfg.lidar.address)) {
      std::fprintf(stderr, "posectl unit-dropin: %s: lidar.address '%s' is not an IP address\n",
                   config_path.c_str(), cfg.lidar.address.c_str());
      return 2;
    }
    allowed.push_back({cfg.lidar.address, "lidar.address (the VLP-32C's UDP packets)"});
  }
  if (!cfg.dds.cyclonedds_config.empty()) {
    std::string error;
    for (const std::string& peer : cyclone_peers(cfg.dds.cyclonedds_config, error)) {
      if (peer == "localhost" || peer == "127.0.0.1") continue;
      if (!valid_address(peer)) {
        std::fprintf(stderr,
                     "posectl unit-dropin: %s: peer '%s' is not an IP address (a host name "
                     "cannot go into IPAddressAllow=; give its address with --dds-peer)\n",
                     cfg.dds.cyclonedds_config.c_str(), peer.c_str());
        return 2;
      }
      allowed.push_back({peer, "a DDS peer in " + cfg.dds.cyclonedds_config});
    }
    if (!error.empty()) {
      std::fprintf(stderr, "posectl unit-dropin: %s\n", error.c_str());
      return 2;
    }
  }
  for (const std::string& peer : extra_peers) {
    if (!valid_address(peer)) {
      std::fprintf(stderr, "posectl unit-dropin: --dds-peer '%s' is not ADDR or ADDR/PREFIX\n",
                   peer.c_str());
      return 2;
    }
    allowed.push_back({peer, "--dds-peer"});
  }

  std::printf("# posed.service drop-in written by `posectl unit-dropin --config %s`.\n",
              config_path.c_str());
  std::printf(
      "# Install: /etc/systemd/system/posed.service.d/50-network.conf; systemctl daemon-reload.\n"
      "# Write it again when the lidar's address, the DDS peers or imu.source change.\n"
      "[Service]\n"
      "# An empty assignment drops the shipped unit's LAN-wide list; IPAddressDeny=any stays.\n"
      "IPAddressAllow=\n");
  for (const Allowed& a : allowed) {
    std::printf("# %s\nIPAddressAllow=%s\n", a.why.c_str(), a.address.c_str());
  }
  if (cfg.imu.source == "can") {
    std::printf(
        "# imu.source is can: SocketCAN sockets (the list merges with the unit's)\n"
        "RestrictAddressFamilies=AF_CAN\n");
  }
  return 0;
}

}  // namespace posed::posectl
