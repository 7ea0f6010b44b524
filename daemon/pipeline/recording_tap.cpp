#include "daemon/pipeline/recording_tap.hpp"

namespace posed::pipeline {

RecordingTap::RecordingTap(std::unique_ptr<drivers::Source> inner,
                           drivers::recording::Recorder& recorder,
                           const std::map<std::string, std::string>& metadata)
    : inner_(std::move(inner)), recorder_(recorder) {
  for (std::uint32_t i = 0; i < channel_ids_.size(); ++i) {
    const std::string_view wire_format = inner_->wire_format(i);
    channel_ids_[i] = wire_format.empty()
                          ? drivers::recording::Recorder::kInvalidChannel
                          : recorder_.add_raw_channel(inner_->name(), wire_format, metadata, i);
  }
}

drivers::ReadStatus RecordingTap::read(drivers::RawChunk& chunk, Duration timeout) {
  const drivers::ReadStatus rs = inner_->read(chunk, timeout);
  if (rs == drivers::ReadStatus::kData && chunk.channel < channel_ids_.size() &&
      channel_ids_[chunk.channel] != drivers::recording::Recorder::kInvalidChannel) {
    // A refused record is counted by the Recorder; the Source goes on regardless.
    recorder_.record(channel_ids_[chunk.channel], chunk);
  }
  return rs;
}

}  // namespace posed::pipeline
