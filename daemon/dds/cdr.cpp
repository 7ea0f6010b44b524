#include "daemon/dds/cdr.hpp"

#include <dds/ddsi/ddsi_cdrstream.h>
#include <dds/ddsi/q_protocol.h>

#include <cstring>

#include "daemon/dds/participant.hpp"

namespace posed::dds::detail {

void encode_cdr(Topic topic, const void* sample, std::vector<std::byte>& out) {
  constexpr std::byte kCdrLe[4] = {std::byte{0x00}, std::byte{0x01}, std::byte{0x00},
                                   std::byte{0x00}};
  dds_ostreamLE_t os;
  // Start at the previous size: Cyclone grows the buffer by reallocating, and messages of one
  // topic are about the same size every time.
  dds_ostreamLE_init(&os, static_cast<std::uint32_t>(out.capacity()), CDR_ENC_VERSION_1);
  dds_stream_writeLE(&os, static_cast<const char*>(sample), descriptor(topic).m_ops);
  out.resize(sizeof kCdrLe + os.x.m_index);
  std::memcpy(out.data(), kCdrLe, sizeof kCdrLe);
  if (os.x.m_index > 0) std::memcpy(out.data() + sizeof kCdrLe, os.x.m_buffer, os.x.m_index);
  dds_ostreamLE_fini(&os);
}

}  // namespace posed::dds::detail
