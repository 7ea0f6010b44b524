#pragma once
// The recorder's tap (DESIGN.md, Recordings): a Source that passes every read through unchanged
// and hands a copy of the bytes to the Recorder, before any decoding, so a replay exercises
// decoding, clock sync and fusion exactly as on the robot. Recording never blocks the Source:
// the Recorder's queues drop (and count) when the disk falls behind.
//
// tap_sources() is the one place that decides what a recording's raw channels carry; `posed
// --record` and `posectl record` both call it, so their files are the same and replay the same.

#include <array>
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include "daemon/config/posed_config.hpp"
#include "daemon/pipeline/pipeline.hpp"
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

/// The metadata a recording stores with every raw channel of `stream`: the effective
/// configuration (`posed.config`, the text of `posed --print-config`) on every stream, plus what
/// a reader of that stream needs to know about the device (IMU source and device path; lidar
/// address, calibration path and the calibration file's text).
std::map<std::string, std::string> recording_metadata(const config::PosedConfig& config,
                                                      std::string_view stream);

/// Wraps every Source in `sources` (whatever PipelineSources::for_each visits) in a RecordingTap
/// with recording_metadata() for its stream name.
void tap_sources(PipelineSources& sources, drivers::recording::Recorder& recorder,
                 const config::PosedConfig& config);

}  // namespace posed::pipeline
