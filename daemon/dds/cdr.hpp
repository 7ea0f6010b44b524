#pragma once
// Internal to daemon/dds (and its tests): an idlc-generated sample as the CDR bytes a ROS 2 node
// would send, through Cyclone's own serialiser (its type ops), so the bytes cannot drift from
// what goes on the DDS wire.

#include <cstddef>
#include <vector>

#include "daemon/dds/messages.hpp"

namespace posed::dds::detail {

/// Replaces `out` with the encapsulation header 00 01 00 00 (CDR_LE) and `sample` (a sample of
/// the type `topic` carries) in XCDR1 little endian. `out` keeps its capacity between calls.
void encode_cdr(Topic topic, const void* sample, std::vector<std::byte>& out);

}  // namespace posed::dds::detail
