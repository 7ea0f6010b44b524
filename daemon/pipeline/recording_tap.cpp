#include "daemon/pipeline/recording_tap.hpp"

#include <fstream>
#include <sstream>

#include "daemon/config/config_loader.hpp"
#include "drivers/recording/raw_channels.hpp"

namespace posed::pipeline {

namespace raw = drivers::recording::raw;

namespace {

/// A file's contents for the recording's metadata ("" when unset or unreadable).
std::string read_text_file(const std::string& path) {
  if (path.empty()) return {};
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

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

std::map<std::string, std::string> recording_metadata(const config::PosedConfig& config,
                                                      std::string_view stream) {
  // Every channel carries the effective configuration: a recording says how it was made.
  std::map<std::string, std::string> md{
      {std::string(raw::kConfigKey), config::print_config(config)}};
  if (stream == "imu") {
    md["posed.imu.source"] = config.imu.source;
    if (config.imu.source == "can") {
      // The interface, and the mapping the frames were read with (also in posed.config).
      md["posed.imu.device"] = config.imu.can_interface;
      md["posed.imu.can_mapping"] = config::can_mapping_yaml(config.imu.can_mapping);
    } else {
      md["posed.imu.device"] = config.imu.serial_device;
    }
  } else if (stream == "lidar") {
    md["posed.lidar.address"] = config.lidar.address;
    md[std::string(raw::kLidarCalibrationKey)] = config.lidar.calibration;
    md[std::string(raw::kLidarCalibrationTextKey)] = read_text_file(config.lidar.calibration);
  } else if (stream == "visible" || stream == "thermal" || stream == "depth") {
    const config::CameraSection& camera = stream == "visible"   ? config.visible_camera
                                          : stream == "thermal" ? config.thermal_camera
                                                                : config.depth_camera;
    const std::string prefix = "posed." + std::string(stream) + ".";
    md[prefix + "device"] = camera.device;
    md[prefix + "source"] = camera.source;
    md[prefix + "format"] = camera.format;
  }
  return md;
}

void tap_sources(PipelineSources& sources, drivers::recording::Recorder& recorder,
                 const config::PosedConfig& config) {
  sources.for_each([&](std::unique_ptr<drivers::Source>& source) {
    if (!source) return;
    const std::string stream(source->name());
    source = std::make_unique<RecordingTap>(std::move(source), recorder,
                                            recording_metadata(config, stream));
  });
}

}  // namespace posed::pipeline
