#pragma once
// What posed publishes besides odometry, poses and status, wired from the config in one place
// (run_daemon keeps only the order of start and stop): the tap that hands every DDS message to
// the recording and the Foxglove server, the server itself, and the threads that build point
// clouds and the front end's image off the fusion thread.

#include <memory>
#include <string>

#include "core/time.hpp"
#include "daemon/cloud_output.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/image_output.hpp"
#include "daemon/output_tap.hpp"

namespace posed {

namespace dds {
class Publisher;
}
namespace foxglove {
class Server;
}
namespace drivers::recording {
class Recorder;
}

struct ExtraOutputsSetup {
  const std::string* config_path = nullptr;  ///< named in a Foxglove bind error
  /// --record-outputs (parse_record_outputs), used with a recorder
  std::string record_outputs;
  bool have_lidar = false;   ///< a lidar Source: clouds and the map can be made
  bool have_camera = false;  ///< a camera Source: the front end's image can be made
  HostToWall to_wall{Duration::from_ns(0)};
};

class ExtraOutputs {
 public:
  ExtraOutputs();
  ~ExtraOutputs();  ///< stops the cloud and image threads first, the server last
  ExtraOutputs(const ExtraOutputs&) = delete;
  ExtraOutputs& operator=(const ExtraOutputs&) = delete;

  /// Starts what `config` asks for. `publisher` null (an offline run): nothing; `recorder` null:
  /// nothing recorded. false with `error` set on a bad --record-outputs or a Foxglove server
  /// that cannot listen. The publisher and recorder must outlive this object.
  bool open(const config::PosedConfig& config, dds::Publisher* publisher,
            drivers::recording::Recorder* recorder, const ExtraOutputsSetup& setup,
            std::string& error);
  /// Writes the clouds and image still waiting and ends their threads (before the recording
  /// closes, so they reach it), then gives the Foxglove clients up to 1 s to take what is queued
  /// for them. Idempotent.
  void stop();

  /// Whether a Foxglove client subscribes to rt/posed/odom or pose (--wait-subscribers).
  bool foxglove_reader() const;
  /// For the run's pipeline (PipelineOutputs); null when off.
  pipeline::ScanObserver* scan_observer() { return clouds_.get(); }
  fusion::FrontendObserver* frontend_observer() { return images_.get(); }
  /// For the summary; null when off.
  const CloudOutput* clouds() const { return clouds_.get(); }
  const ImageOutput* images() const { return images_.get(); }
  const foxglove::Server* foxglove() const { return foxglove_.get(); }

 private:
  // Declared in the order they start; destroyed in reverse.
  std::unique_ptr<foxglove::Server> foxglove_;
  std::unique_ptr<OutputTap> tap_;
  std::unique_ptr<CloudOutput> clouds_;
  std::unique_ptr<ImageOutput> images_;
};

}  // namespace posed
