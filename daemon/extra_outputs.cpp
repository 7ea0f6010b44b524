#include "daemon/extra_outputs.hpp"

#include <chrono>
#include <vector>

#include "daemon/build_info.hpp"
#include "daemon/dds/publisher.hpp"
#include "daemon/foxglove/server.hpp"
#include "drivers/common/log.hpp"

namespace posed {

ExtraOutputs::ExtraOutputs() = default;

ExtraOutputs::~ExtraOutputs() { stop(); }

bool ExtraOutputs::open(const config::PosedConfig& config, dds::Publisher* publisher,
                        drivers::recording::Recorder* recorder, const ExtraOutputsSetup& setup,
                        std::string& error) {
  if (publisher == nullptr) {
    if (config.foxglove.enabled) {
      POSED_LOG_NOTICE("foxglove.enabled, but this run publishes nothing: no Foxglove server");
    }
    return true;
  }
  // The DDS outputs beside DDS: into the recording as ros2msg channels.
  std::vector<dds::Topic> record_outputs;
  if (recorder != nullptr && !parse_record_outputs(setup.record_outputs, record_outputs, error)) {
    return false;
  }
  // Foxglove Studio live: every topic DDS carries, on the WebSocket server's own thread.
  std::vector<dds::Topic> served;
  if (config.foxglove.enabled) {
    foxglove::ServerOptions options;
    options.address = config.foxglove.address;
    options.port = static_cast<std::uint16_t>(config.foxglove.port);
    options.name = std::string(version_string());
    options.max_queued_bytes_per_client =
        static_cast<std::size_t>(config.foxglove.max_queued_mb * 1e6);
    foxglove_ = foxglove::Server::start(options, error);
    if (!foxglove_) {
      error += " (foxglove.address, foxglove.port";
      error += setup.config_path != nullptr ? " in " + *setup.config_path + ")" : ")";
      return false;
    }
    for (dds::Topic t : dds::kAllTopics) {
      if (publisher->has_writer(t)) served.push_back(t);
    }
    POSED_LOG_INFO("foxglove: serving %zu topics on ws://%s:%u", served.size(),
                   config.foxglove.address.c_str(), foxglove_->port());
  }
  tap_ = std::make_unique<OutputTap>(recorder, record_outputs, foxglove_.get(), served);
  publisher->set_tap(tap_.get());
  // Clouds and the image are built off the fusion thread, each only with a sensor to make it.
  if (setup.have_lidar && (config.publish.cloud || config.publish.map)) {
    clouds_ = std::make_unique<CloudOutput>(config, *publisher, setup.to_wall);
  }
  if (setup.have_lidar && setup.have_camera && config.publish.image) {
    images_ = std::make_unique<ImageOutput>(config, *publisher, setup.to_wall);
  }
  return true;
}

void ExtraOutputs::stop() {
  if (clouds_) clouds_->stop();
  if (images_) images_->stop();
  // The last messages (the final status after the pipeline drained, the last cloud) are still
  // queued for the Foxglove clients: written before the summary counts them and the server's
  // end discards the rest. A client that stopped reading costs at most this second.
  if (foxglove_ && !foxglove_->flush(std::chrono::seconds(1))) {
    POSED_LOG_NOTICE("foxglove: a client did not take its last messages within 1 s");
  }
}

bool ExtraOutputs::foxglove_reader() const {
  return foxglove_ && tap_ && (tap_->wants(dds::Topic::kOdom) || tap_->wants(dds::Topic::kPose));
}

}  // namespace posed
