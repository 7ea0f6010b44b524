// posectl initialpose --x X --y Y [--yaw RAD]: sends one geometry_msgs/PoseWithCovarianceStamped
// on rt/initialpose as RViz's "2D Pose Estimate" tool does (stamped now, covariance x, y and yaw
// on the diagonal), for a robot without a screen. The topic is volatile, so it first waits for a
// reader (posed localising on a map) and says whether one matched; after the write it waits for
// the readers' acknowledgement, since exiting at once could take the sample with it.
// Exit codes: 0 a reader matched and acknowledged, 1 none matched or no acknowledgement (the pose
// was still written) or DDS failed, 2 a non-finite number or an empty frame (arguments CLI11
// cannot parse exit with its own codes, as in the other subcommands).

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <string>

#include "daemon/dds/initial_pose_writer.hpp"
#include "drivers/common/host_clock.hpp"
#include "tools/posectl/commands.hpp"

namespace posed::posectl {

int run_initialpose(int argc, char** argv) {
  CLI::App app{
      "Send one initial pose on rt/initialpose as RViz's 2D Pose Estimate does "
      "(geometry_msgs/PoseWithCovarianceStamped, reliable, volatile, keep-last 5), for posed's "
      "localisation on a map (--map). Waits for a reader first and says whether one matched.",
      "posectl initialpose"};
  double x = 0, y = 0, z = 0, yaw = 0;
  std::string frame = "map";
  // RViz's covariance: 0.5 m in x and y, pi/12 rad in yaw.
  double sigma_xy = 0.5, sigma_yaw = M_PI / 12.0;
  double wait_s = 2.0;
  std::uint32_t domain = 0;
  std::string topic = "rt/initialpose";
  std::string cyclone_config;
  std::string enclave;
  app.add_option("--x", x, "position of the base in FRAME [m]")->required();
  app.add_option("--y", y, "position of the base in FRAME [m]")->required();
  app.add_option("--z", z, "position of the base in FRAME [m] (RViz sends 0)")
      ->capture_default_str();
  app.add_option("--yaw", yaw, "heading about FRAME's z, counter-clockwise from x [rad]")
      ->capture_default_str();
  app.add_option("--frame", frame, "header.frame_id: the frame of the pose (posed's dds.map_frame)")
      ->capture_default_str();
  app.add_option("--sigma-xy", sigma_xy, "standard deviation of x and y [m]")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--sigma-yaw", sigma_yaw, "standard deviation of the yaw [rad]")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--wait", wait_s, "wait this long for a reader, then for its acknowledgement [s]")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--topic", topic,
                 "DDS topic (posed's dds.initialpose_topic); a ROS name /NAME means rt/NAME")
      ->capture_default_str();
  app.add_option("--domain,-d", domain, "DDS domain id (ROS_DOMAIN_ID)")->capture_default_str();
  app.add_option("--cyclonedds-config", cyclone_config,
                 "Cyclone XML file (e.g. config/cyclonedds-loopback.xml); default: CYCLONEDDS_URI "
                 "or Cyclone's built-in defaults");
  app.add_option("--enclave", enclave,
                 "DDS Security: an SROS2 enclave directory allowed to publish the topic")
      ->check(CLI::ExistingDirectory);
  CLI11_PARSE(app, argc, argv);

  for (const double v : {x, y, z, yaw, sigma_xy, sigma_yaw}) {
    if (!std::isfinite(v)) {
      std::fprintf(stderr, "posectl initialpose: every number must be finite\n");
      return 2;
    }
  }
  if (frame.empty()) {
    std::fprintf(stderr, "posectl initialpose: --frame must not be empty\n");
    return 2;
  }
  if (!topic.empty() && topic.front() == '/') topic = "rt" + topic;

  dds::DdsConfig config;
  config.domain_id = domain;
  config.cyclonedds_xml_path = cyclone_config;
  config.initial_pose_topic = topic;
  if (!enclave.empty()) config.security = dds::DdsSecurityFiles::from_enclave(enclave);
  std::string error;
  auto writer = dds::InitialPoseWriter::create(config, error);
  if (!writer) {
    std::fprintf(stderr, "posectl initialpose: %s\n", error.c_str());
    return 1;
  }

  const Duration wait = Duration::from_seconds(wait_s);
  const bool matched = writer->wait_for_reader(wait);
  if (matched) {
    std::printf("posectl initialpose: %u reader(s) matched on %s (domain %u)\n",
                writer->matched_subscribers(), topic.c_str(), domain);
  } else {
    std::printf(
        "posectl initialpose: no reader matched on %s (domain %u) in %.1f s; sending anyway, "
        "but nobody receives it (is posed running with --map, the same domain and Cyclone "
        "config?)\n",
        topic.c_str(), domain, wait_s);
  }

  dds::InitialPose pose;
  pose.stamp_ns = drivers::wall_now().ns;  // RViz stamps the click with the wall clock
  pose.frame_id = frame;
  pose.T_frame_base.translation() = Eigen::Vector3d(x, y, z);
  pose.T_frame_base.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.covariance[0] = sigma_xy * sigma_xy;     // x
  pose.covariance[7] = sigma_xy * sigma_xy;     // y
  pose.covariance[35] = sigma_yaw * sigma_yaw;  // rot z
  if (!writer->publish(pose, error)) {
    std::fprintf(stderr, "posectl initialpose: %s\n", error.c_str());
    return 1;
  }
  std::printf(
      "posectl initialpose: sent x %.3f m, y %.3f m, z %.3f m, yaw %.4f rad in %s "
      "(sigma xy %.3f m, yaw %.4f rad)\n",
      x, y, z, yaw, frame.c_str(), sigma_xy, sigma_yaw);
  if (!matched) return 1;
  if (!writer->wait_acknowledged(wait)) {
    std::printf("posectl initialpose: not acknowledged by every reader within %.1f s\n", wait_s);
    return 1;
  }
  std::printf("posectl initialpose: acknowledged\n");
  return 0;
}

}  // namespace posed::posectl
