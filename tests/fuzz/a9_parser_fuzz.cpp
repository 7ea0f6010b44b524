// libFuzzer target for the A9 streaming decoder. Beyond "no crash", it checks the decoder's
// contracts on arbitrary bytes split arbitrarily:
//  - every delivered frame re-encodes to exactly the bytes at its stream offset,
//  - every input byte is either in a delivered frame or counted as skipped,
//  - splitting the input differently never changes which frames come out.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "drivers/imu/a9_protocol.hpp"

namespace {

namespace a9 = posed::drivers::a9;

struct Run {
  std::vector<std::uint64_t> offsets;
  a9::DecoderCounters counters;
  std::uint64_t frame_bytes = 0;
};

void check(bool ok) {
  if (!ok) __builtin_trap();
}

Run decode(std::span<const std::uint8_t> data, std::span<const std::uint8_t> cuts) {
  Run run;
  a9::A9Decoder d;
  auto on_frame = [&](const a9::A9Frame& f) {
    std::uint8_t buf[a9::kMaxFrameSize];
    const std::size_t n = f.kind == a9::FrameKind::kSensor
                              ? a9::encode_a9_sensor_frame(f.sensor, buf)
                              : a9::encode_a9_attitude_frame(f.attitude, buf);
    check(n > 0 && f.stream_offset + n <= data.size());
    check(std::memcmp(buf, data.data() + f.stream_offset, n) == 0);
    run.offsets.push_back(f.stream_offset);
    run.frame_bytes += n;
  };
  std::size_t at = 0;
  for (std::size_t i = 0; at < data.size(); ++i) {
    const std::size_t len =
        cuts.empty() ? data.size()
                     : std::min<std::size_t>(1 + cuts[i % cuts.size()], data.size() - at);
    d.feed(data.subspan(at, len), on_frame);
    at += len;
  }
  d.finish(on_frame);
  check(d.pending_bytes() == 0);
  check(d.stream_position() == data.size());
  run.counters = d.counters();
  return run;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  // The chunk lengths come from the data itself, so a real capture is a valid seed as it is.
  const std::span<const std::uint8_t> data(bytes, size);
  const Run whole = decode(data, {});
  const Run split = decode(data, data.first(std::min<std::size_t>(size, 16)));
  check(whole.offsets == split.offsets);
  check(whole.counters.frames_ok == split.counters.frames_ok);
  check(whole.counters.skipped_bytes == split.counters.skipped_bytes);
  check(whole.frame_bytes + whole.counters.skipped_bytes == data.size());
  return 0;
}
