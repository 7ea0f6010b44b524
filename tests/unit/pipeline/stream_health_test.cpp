// A stream's health between status reports (fill_stream_status): silent for a second is no_data,
// bad samples make it degraded for two seconds after the last one, and it comes back to ok.

#include <gtest/gtest.h>

#include "daemon/pipeline/stage_support.hpp"

namespace posed::pipeline {
namespace {

class SilentSource final : public drivers::Source {
 public:
  std::string_view name() const override { return "lidar"; }
  bool open(std::string&) override { return true; }
  drivers::ReadStatus read(drivers::RawChunk&, Duration) override {
    return drivers::ReadStatus::kEndOfStream;
  }
  void request_stop() override {}
  drivers::SourceCounters counters() const override { return {}; }
  bool live() const override { return true; }
  std::string_view wire_format(std::uint32_t) const override { return "velodyne-udp-data"; }
};

HostTime at(double s) { return HostTime::from_ns(static_cast<std::int64_t>(s * 1e9)); }

struct Stream {
  StreamCounters counters;
  SilentSource source;
  StreamHealthMemory memory;
  /// a sample decoded (arriving) at `t`, malformed ones besides
  void sample(double t, std::uint64_t malformed = 0) {
    counters.decoded.fetch_add(1);
    counters.malformed.fetch_add(malformed);
    ClockSyncStatus clock;
    clock.samples = counters.decoded.load();
    clock.state = SyncState::kLocked;
    clock.last_arrival = at(t);
    counters.publish_clock(clock);
  }
  /// Live without `newest`; a replay with it: the stream's newest stamp the merge took, and
  /// whether the merge has passed a bad sample within the last two seconds.
  std::string health(double now, std::optional<double> newest = std::nullopt,
                     bool merged_degraded = false) {
    StreamStatus s;
    s.name = "lidar";
    std::optional<MergedStreamHealth> merged;
    if (newest) merged = MergedStreamHealth{at(*newest), merged_degraded};
    fill_stream_status(s, counters, source, at(now), memory, merged);
    return s.health;
  }
};

TEST(StreamHealth, SilenceIsNoDataAfterASecondAndDataBringsItBack) {
  Stream stream;
  EXPECT_EQ(stream.health(0.5), "no_data");  // nothing decoded yet
  stream.sample(1.0);
  EXPECT_EQ(stream.health(1.5), "ok");
  EXPECT_EQ(stream.health(2.0), "ok");
  EXPECT_EQ(stream.health(2.1), "no_data");
  stream.sample(3.0);
  EXPECT_EQ(stream.health(3.1), "ok");
}

TEST(StreamHealth, BadSamplesDegradeForTwoSecondsAfterTheLastOne) {
  Stream stream;
  stream.sample(1.0);
  EXPECT_EQ(stream.health(1.0), "ok");
  stream.sample(1.5, 3);
  EXPECT_EQ(stream.health(1.5), "degraded");
  stream.sample(2.5);
  EXPECT_EQ(stream.health(2.5), "degraded");
  stream.sample(3.4);
  EXPECT_EQ(stream.health(3.4), "degraded");  // 1.9 s after the bad samples were counted
  stream.sample(3.6);
  EXPECT_EQ(stream.health(3.6), "ok");
  stream.counters.dropped.fetch_add(1);
  stream.sample(3.7);
  EXPECT_EQ(stream.health(3.7), "degraded");  // dropped counts as bad too
}

TEST(StreamHealth, AReplayIsJudgedByTheNewestStampTheMergeTookNotTheStagesArrivals) {
  Stream stream;
  stream.sample(10.0);                            // the stage read ahead to 10 s ...
  EXPECT_EQ(stream.health(4.0, 3.5), "ok");       // ... the merge is at 4 s, this stream's at 3.5
  EXPECT_EQ(stream.health(4.6, 3.5), "no_data");  // passed by more than a second
  EXPECT_EQ(stream.health(4.7, 4.7), "ok");
}

TEST(StreamHealth, AReplaysBadSamplesCountWhereTheMergeIsNotWhereTheStageReadTo) {
  // The stage read ahead to 10 s and counted malformed samples there; the merge, at 4 s, has not
  // reached them: ok, until the fusion stage says the merge has passed one.
  Stream stream;
  stream.sample(10.0, 5);
  EXPECT_EQ(stream.health(4.0, 4.0), "ok");
  EXPECT_EQ(stream.health(9.9, 9.9, true), "degraded");
  EXPECT_EQ(stream.health(12.0, 12.0), "ok");
}

}  // namespace
}  // namespace posed::pipeline
