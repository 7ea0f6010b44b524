#pragma once
// The measurements that cross from drivers into the fusion core. Every field states its frame
// and unit; every stamp is on the host clock once ClockSync has run (DESIGN.md, Time).

#include <Eigen/Core>
#include <cstdint>
#include <string_view>

#include "core/payload_pool.hpp"
#include "core/time.hpp"

namespace posed {

/// One inertial sample in the IMU frame (x forward, y left, z up; ROS REP-103).
struct ImuSample {
  /// sample time on the host clock, after ClockSync
  HostTime stamp;
  /// the device's own stamp, unwrapped [ns]; 0 when the device has no clock
  DeviceTime device_stamp;
  /// angular rate of the IMU frame w.r.t. inertial space, in the IMU frame [rad/s]
  Eigen::Vector3d angular_velocity_radps = Eigen::Vector3d::Zero();
  /// specific force (accelerometer reading; +9.81 on z at rest, level) in the IMU frame [m/s^2]
  Eigen::Vector3d specific_force_mps2 = Eigen::Vector3d::Zero();
  /// measured by the rig's backup IMU (the D435i's) standing in for the primary (the A9): the
  /// estimator weighs it with the backup's own noise densities
  bool from_backup_imu = false;
};

/// One lidar return in the sensor frame (x forward, y left, z up).
struct LidarPoint {
  /// position [m]
  float x = 0.f, y = 0.f, z = 0.f;
  /// calibrated reflectivity [0..255]
  float intensity = 0.f;
  /// time of the firing relative to the scan's start stamp [ns]
  std::int32_t offset_ns = 0;
  /// beam index ordered by elevation, 0 = lowest
  std::uint16_t ring = 0;
  /// 0 strongest/last, 1 second return in dual mode
  std::uint16_t return_index = 0;
};

/// A lidar scan's points live in a pool buffer of LidarPoint; the scan carries the lease.
struct LidarScan {
  /// time of the first firing in the scan, host clock
  HostTime start_stamp;
  /// time of the last firing in the scan, host clock
  HostTime end_stamp;
  /// points, `point_count` of them valid
  PayloadPool::Lease points;
  std::uint32_t point_count = 0;
  /// scan sequence number per stream; a gap means scans were dropped
  std::uint64_t sequence = 0;
};

enum class PixelFormat : std::uint8_t {
  kMono8,   ///< 8-bit grey
  kMono16,  ///< 16-bit grey, host byte order (raw thermal counts)
  kBgr8,    ///< 8-bit B,G,R interleaved
  kRgb8,    ///< 8-bit R,G,B interleaved
  kDepth16  ///< Z16 depth in device units (see Image::depth_unit_m)
};

constexpr std::string_view to_string(PixelFormat f) {
  switch (f) {
    case PixelFormat::kMono8:
      return "mono8";
    case PixelFormat::kMono16:
      return "mono16";
    case PixelFormat::kBgr8:
      return "bgr8";
    case PixelFormat::kRgb8:
      return "rgb8";
    case PixelFormat::kDepth16:
      return "16UC1";
  }
  return "unknown";
}

constexpr int bytes_per_pixel(PixelFormat f) {
  switch (f) {
    case PixelFormat::kMono8:
      return 1;
    case PixelFormat::kMono16:
      return 2;
    case PixelFormat::kBgr8:
      return 3;
    case PixelFormat::kRgb8:
      return 3;
    case PixelFormat::kDepth16:
      return 2;
  }
  return 0;
}

/// An image whose pixels live in a pool buffer (no copy between driver and core).
struct Image {
  /// exposure midpoint on the host clock
  HostTime stamp;
  DeviceTime device_stamp;
  std::uint32_t width = 0;   ///< [px]
  std::uint32_t height = 0;  ///< [px]
  std::uint32_t stride = 0;  ///< bytes per row [B]
  PixelFormat format = PixelFormat::kMono8;
  /// metres per depth unit, for kDepth16 only [m]
  float depth_unit_m = 0.001f;
  std::uint64_t sequence = 0;
  PayloadPool::Lease pixels;
};

/// The cameras of the rig, as streams of the pipeline.
enum class CameraStream : std::uint8_t {
  kVisible,  ///< the D435i colour camera
  kThermal,  ///< the PLUG 617 thermal camera
  kDepth,    ///< the D435i's depth node (Z16 of its left IR imager): depth for camera features
};

constexpr std::string_view to_string(CameraStream s) {
  switch (s) {
    case CameraStream::kVisible:
      return "visible";
    case CameraStream::kThermal:
      return "thermal";
    case CameraStream::kDepth:
      return "depth";
  }
  return "unknown";
}

}  // namespace posed
