// libFuzzer target: the MCAP reader (and the inspection built on it) must accept any bytes:
// never read outside the input, never crash or hang, report problems as issues, return only
// messages on defined channels, and read a file the same way twice (rewind, replay loops).
// Decompressed chunks are capped at 1 MiB here: the reader's own 512 MiB cap is for real files,
// and a few fuzzed bytes claiming 512 MiB would only measure the allocator.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>

#include "drivers/recording/mcap_inspection.hpp"
#include "drivers/recording/mcap_reader.hpp"

namespace rec = posed::drivers::recording;

namespace {

/// Reads every message; returns how many, checking what each must satisfy.
std::uint64_t read_all(rec::McapReader& reader, std::size_t size) {
  rec::McapMessage m;
  std::uint64_t n = 0;
  while (reader.next(m)) {
    if (m.channel == nullptr) std::abort();
    if (reader.channels().find(m.channel->id) == reader.channels().end()) std::abort();
    if (m.record_offset >= size) std::abort();
    if (reader.offset() > size) std::abort();
    // Touch every byte: a span pointing outside the input or the chunk buffer trips ASan.
    volatile std::uint8_t sink = 0;
    for (const std::byte b : m.data) sink = sink ^ static_cast<std::uint8_t>(b);
    ++n;
  }
  return n;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = std::span(reinterpret_cast<const std::byte*>(data), size);
  for (const bool crcs : {true, false}) {
    rec::McapReaderOptions options;
    options.verify_crcs = crcs;
    options.max_chunk_bytes = 1u << 20;
    rec::McapReader reader;
    std::string error;
    if (!reader.open_bytes(file, error, options)) {
      if (error.empty()) std::abort();  // a refusal always says why
      return 0;
    }
    const std::uint64_t first = read_all(reader, size);
    if (!reader.complete() && reader.stop_reason().empty() && reader.issues().empty()) {
      std::abort();  // an incomplete read always says why
    }
    reader.rewind();
    if (read_all(reader, size) != first) std::abort();  // deterministic
  }
  rec::McapInspection inspection;
  std::string error;
  rec::McapInspectOptions options;
  if (rec::inspect_mcap_bytes(file, options, inspection, error)) {
    std::uint64_t total = 0;
    for (const auto& c : inspection.channels) {
      total += c.messages;
      if (c.largest_gaps.size() > options.max_gaps) std::abort();
    }
    if (total != inspection.messages) std::abort();
  }
  return 0;
}
