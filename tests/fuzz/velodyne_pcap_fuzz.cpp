// libFuzzer target: the pcap/pcapng reader and the link/IP/UDP extraction must accept any bytes,
// never read outside the input, always terminate, and only return frames inside the file.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "drivers/recording/pcap_parser.hpp"
#include "drivers/recording/pcap_udp.hpp"

namespace rec = posed::drivers::recording;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = std::span(reinterpret_cast<const std::byte*>(data), size);
  rec::PcapParser parser(file);
  if (parser.open() != rec::PcapStatus::kOk) return 0;
  rec::PcapRecord record;
  std::uint64_t last_offset = 0;
  for (int n = 0; n < 100000 && parser.next(record) == rec::PcapStatus::kOk; ++n) {
    const auto* begin = record.frame.data();
    if (!record.frame.empty() &&
        (begin < file.data() || begin + record.frame.size() > file.data() + file.size())) {
      std::abort();
    }
    if (parser.offset() <= last_offset) std::abort();  // progress on every record
    last_offset = parser.offset();
    rec::UdpDatagram d;
    if (rec::extract_udp(record.link_type, record.frame, d) == rec::FrameStatus::kOk) {
      if (d.payload.data() < begin ||
          d.payload.data() + d.payload.size() > begin + record.frame.size()) {
        std::abort();
      }
    }
  }
  return 0;
}
