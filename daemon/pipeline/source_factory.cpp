#include "daemon/pipeline/source_factory.hpp"

#include "drivers/imu/serial_source.hpp"
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
  } else {
    // The schema only admits the values above; this guards against a new one not wired here.
    error = "imu.source '" + config.imu.source + "' has no Source in make_sources()";
  }
  if (!error.empty() || !config.lidar.enabled) return built;
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
