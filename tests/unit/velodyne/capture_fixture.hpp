#pragma once
// Loads the UDP payloads of a real capture (via the pcap parser under test elsewhere) so decoder
// and assembler tests work on real packets.

#include <cstdint>
#include <string>
#include <vector>

#include "drivers/recording/mapped_file.hpp"
#include "drivers/recording/pcap_parser.hpp"
#include "drivers/recording/pcap_udp.hpp"

namespace posed::test {

struct CapturedDatagram {
  std::vector<std::byte> payload;
  std::uint16_t dst_port = 0;
  std::int64_t timestamp_ns = 0;
};

inline std::vector<CapturedDatagram> load_datagrams(const std::string& path) {
  std::vector<CapturedDatagram> out;
  drivers::recording::MappedFile file;
  std::string error;
  if (!file.open(path, error, "pcap")) return out;
  drivers::recording::PcapParser parser(file.bytes());
  if (parser.open() != drivers::recording::PcapStatus::kOk) return out;
  drivers::recording::PcapRecord rec;
  while (parser.next(rec) == drivers::recording::PcapStatus::kOk) {
    drivers::recording::UdpDatagram d;
    if (drivers::recording::extract_udp(rec.link_type, rec.frame, d) !=
        drivers::recording::FrameStatus::kOk) {
      continue;
    }
    out.push_back({{d.payload.begin(), d.payload.end()}, d.dst_port, rec.timestamp_ns});
  }
  return out;
}

}  // namespace posed::test
