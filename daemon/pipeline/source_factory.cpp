#include "daemon/pipeline/source_factory.hpp"

#include <linux/can.h>

#include <cmath>
#include <set>
#include <utility>

#include "daemon/pipeline/camera_stage.hpp"
#include "drivers/camera/aravis_source.hpp"
#include "drivers/camera/d4xx_video_source.hpp"
#include "drivers/camera/realsense_imu_source.hpp"
#include "drivers/camera/v4l2_source.hpp"
#include "drivers/imu/serial_source.hpp"
#include "drivers/imu/socketcan_source.hpp"
#include "drivers/recording/pcap_source.hpp"
#include "drivers/velodyne/udp_source.hpp"

namespace posed::pipeline {

drivers::SyntheticImuConfig synthetic_imu_config(const config::PosedConfig& config) {
  drivers::SyntheticImuConfig c;
  c.motion.radius_m = config.synthetic_imu.radius_m;
  c.motion.speed_mps = config.synthetic_imu.speed_mps;
  c.motion.static_s = config.synthetic_imu.static_s;
  c.motion.ramp_s = config.synthetic_imu.ramp_s;
  c.motion.gravity_mps2 = config.imu.gravity_mps2;
  c.rate_hz = config.synthetic_imu.rate_hz;
  c.gyro_noise_density = config.synthetic_imu.gyro_noise_density;
  c.accel_noise_density = config.synthetic_imu.accel_noise_density;
  c.seed = static_cast<std::uint64_t>(config.synthetic_imu.seed);
  c.hang_after_s = config.synthetic_imu.hang_after_s;
  return c;
}

namespace {

/// A SocketCAN Source on imu.can_interface that lets only the mapped frames through: the kernel
/// drops the rest of the bus before posed reads it (and before a recording stores it).
std::unique_ptr<drivers::Source> make_can_imu_source(const config::PosedConfig& config) {
  drivers::can::SocketCanConfig can;
  can.interface = config.imu.can_interface;
  can.name = "imu";  // the stream's name: recorded as /posed/raw/imu, replayed as the IMU
  std::set<std::pair<std::uint32_t, bool>> ids;
  for (const auto& f : config.imu.can_mapping.fields) ids.emplace(f.can_id, f.extended);
  for (const auto& [id, extended] : ids) {
    // Match the ID, its width (EFF) and data frames only (RTR clear).
    can.filters.push_back({extended ? (id | CAN_EFF_FLAG) : id,
                           (extended ? CAN_EFF_MASK : CAN_SFF_MASK) | CAN_EFF_FLAG | CAN_RTR_FLAG});
  }
  return std::make_unique<drivers::can::SocketCanSource>(std::move(can));
}

/// The live Source of an enabled camera: GenICam through Aravis (device = camera id) or V4L2.
bool make_camera_source(const config::PosedConfig& config, CameraStream stream,
                        PipelineSources& sources, std::string& error) {
  const config::CameraSection& section = camera_section(config, stream);
  if (!section.enabled) return true;
  const std::string name(to_string(stream));
  const auto format = drivers::camera::wire_format_from_string(section.format);
  if (!format) {
    // The schema admits only known names; this guards a new one not wired here.
    error = name + "_camera.format '" + section.format + "' has no decoder";
    return false;
  }
  if (section.source == "aravis") {
    drivers::camera::AravisConfig a;
    a.camera_id = section.device;
    if (*format == drivers::camera::WireFormat::kY8) {
      a.pixel_format = "Mono8";
    } else if (*format == drivers::camera::WireFormat::kY16) {
      a.pixel_format = "Mono16";
    } else {
      error = name + "_camera.format '" + section.format +
              "' is not a GenICam format posed reads (y8 = Mono8, y16 = Mono16)";
      return false;
    }
    a.width = static_cast<std::uint32_t>(section.width);
    a.height = static_cast<std::uint32_t>(section.height);
    a.frame_rate_hz = section.rate_hz;
    sources.camera(stream) = std::make_unique<drivers::camera::AravisSource>(name, std::move(a));
    return true;
  }
  if (section.device.empty()) {
    error = name + "_camera.enabled is true but " + name + "_camera.device is empty";
    return false;
  }
  drivers::camera::V4l2CaptureConfig v;
  v.device = section.device;
  v.format = *format;
  v.width = static_cast<std::uint32_t>(section.width);
  v.height = static_cast<std::uint32_t>(section.height);
  v.fps = static_cast<std::uint32_t>(std::lround(section.rate_hz));
  if (stream == CameraStream::kVisible || stream == CameraStream::kDepth) {
    // The D435i: the colour (or depth) node with its uvcvideo metadata node, whose hardware
    // timestamps the camera stage's clock prefers (frames still flow when the metadata node is
    // missing).
    drivers::camera::D4xxVideoConfig d4xx;
    d4xx.video = std::move(v);
    sources.camera(stream) = std::make_unique<drivers::camera::D4xxVideoSource>(
        name, drivers::camera::system_v4l2_device(), std::move(d4xx));
    return true;
  }
  sources.camera(stream) = std::make_unique<drivers::camera::V4l2Source>(
      name, drivers::camera::system_v4l2_device(), std::move(v));
  return true;
}

}  // namespace

BuiltSources make_sources(const config::PosedConfig& config, std::string& error) {
  BuiltSources built;
  if (config.imu.source == "synthetic") {
    auto source = std::make_unique<drivers::SyntheticImuSource>(synthetic_imu_config(config));
    built.synthetic = source.get();
    built.sources.imu = std::move(source);
  } else if (config.imu.source == "serial") {
    drivers::SerialConfig serial;
    serial.path = config.imu.serial_device;
    serial.baud = config.imu.serial_baud;
    built.sources.imu = std::make_unique<drivers::SerialSource>(std::move(serial));
  } else if (config.imu.source == "can") {
    // The loader refuses imu.source can without a mapping; this guards configs built in code.
    if (config.imu.can_mapping.fields.empty()) {
      error = "imu.source is can but imu.can_mapping is empty";
    } else {
      built.sources.imu = make_can_imu_source(config);
    }
  } else {
    // The schema only admits the values above; this guards against a new one not wired here.
    error = "imu.source '" + config.imu.source + "' has no Source in make_sources()";
  }
  if (!error.empty()) return built;
  for (const CameraStream stream :
       {CameraStream::kVisible, CameraStream::kThermal, CameraStream::kDepth}) {
    if (!make_camera_source(config, stream, built.sources, error)) {
      built.sources = {};
      return built;
    }
  }
  if (config.realsense_imu.enabled) {
    drivers::camera::RealsenseImuSourceConfig rs;
    rs.accel.sampling_frequency_hz = config.realsense_imu.accel_rate_hz;
    rs.gyro.sampling_frequency_hz = config.realsense_imu.gyro_rate_hz;
    for (drivers::camera::IioHidDeviceConfig* d : {&rs.accel, &rs.gyro}) {
      d->sysfs_root = config.realsense_imu.sysfs_root;
      d->dev_dir = config.realsense_imu.dev_dir;
    }
    built.sources.realsense_imu =
        std::make_unique<drivers::camera::RealsenseImuSource>("realsense_imu", std::move(rs));
  }
  if (!config.lidar.enabled) return built;
  if (config.lidar.source == "udp") {
    drivers::velodyne::UdpSourceConfig udp;
    udp.sensor_address = config.lidar.address;
    udp.data_port = static_cast<std::uint16_t>(config.lidar.data_port);
    udp.position_port = static_cast<std::uint16_t>(config.lidar.position_port);
    built.sources.lidar = std::make_unique<drivers::velodyne::UdpSource>(std::move(udp));
  } else if (config.lidar.source == "pcap") {
    if (config.lidar.pcap_file.empty()) {
      error = "lidar.source is pcap but lidar.pcap_file is empty";
      built.sources = {};
      return built;
    }
    drivers::recording::PcapSourceConfig pcap;
    pcap.path = config.lidar.pcap_file;
    pcap.ports = {static_cast<std::uint16_t>(config.lidar.data_port),
                  static_cast<std::uint16_t>(config.lidar.position_port)};
    pcap.speed = config.lidar.pcap_speed;
    built.sources.lidar = std::make_unique<drivers::recording::PcapSource>(std::move(pcap));
  }
  return built;
}

}  // namespace posed::pipeline
