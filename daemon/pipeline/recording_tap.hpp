#pragma once
// The recorder's tap (DESIGN.md, Recordings): a Source that passes every read through unchanged
// and hands a copy of the bytes to the Recorder, before any decoding, so a replay exercises
// decoding, clock sync and fusion exactly as on the robot. Recording never blocks the Source:
// the Recorder's queues drop (and count) when the disk falls behind.

#include <array>
#include <map>
#include <memory>
#include <string>

#include "drivers/common/source.hpp"
#include "drivers/recording/recorder.hpp"

namespace posed::pipeline {

class RecordingTap final : public drivers::Source {
 public:
  /// Records every channel the inner Source names a wire format for (channels 0 and 1: data and
  /// e.g. the Velodyne position port); `metadata` (sensor config, calibration) goes into every
  /// channel's record.
  RecordingTap(std::unique_ptr<drivers::Source> inner, drivers::recording::Recorder& recorder,
               const std::map<std::string, std::string>& metadata);

  std::string_view name() const override { return inner_->name(); }
  bool open(std::string& error) override { return inner_->open(error); }
  drivers::ReadStatus read(drivers::RawChunk& chunk, Duration timeout) override;
  void request_stop() override { inner_->request_stop(); }
  drivers::SourceCounters counters() const override { return inner_->counters(); }
  bool live() const override { return inner_->live(); }
  std::string_view wire_format(std::uint32_t channel) const override {
    return inner_->wire_format(channel);
  }

 private:
  std::unique_ptr<drivers::Source> inner_;
  drivers::recording::Recorder& recorder_;
  std::array<std::uint16_t, 2> channel_ids_;
};

}  // namespace posed::pipeline
