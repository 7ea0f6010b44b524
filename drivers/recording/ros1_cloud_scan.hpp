#pragma once
// A decoded sensor_msgs/PointCloud2 straight into a LidarScan (core/measurements.hpp) in a
// PayloadPool buffer: no packets, no scan assembler. The layout is velodyne_pointcloud's
// PointXYZIRT (x y z intensity: float32, ring: uint16, time: float32 seconds relative to
// header.stamp), found by field name, so other field orders, padding and extra fields are fine,
// and x/y/z/intensity/time may be any numeric datatype.
//
//  - time: point times may be negative (velodyne_pointcloud versions that stamp the cloud with
//    its last packet); the scan starts at the earliest point, ends at the latest, and each
//    LidarPoint::offset_ns counts from the start. Without a time field every offset is 0 (no
//    deskew possible) and CloudScanInfo::has_time says so.
//  - ring: LidarPoint::ring is "beam index by elevation, 0 = lowest", which velodyne_pointcloud's
//    ring already is. Without a ring field it is derived from each point's elevation, as the
//    nearest of the configured beam elevations.
//  - points that are not finite (organized clouds fill gaps with NaN) or outside the range
//    limits are left out, as the packet decoder leaves out zero returns and out-of-range ones.
//
// Pure: no clock, no I/O, no allocation after construction; never throws.

#include <cstdint>
#include <string_view>
#include <vector>

#include "core/measurements.hpp"
#include "core/payload_pool.hpp"
#include "core/time.hpp"
#include "drivers/recording/ros1_messages.hpp"

namespace posed::drivers::recording::ros1 {

struct CloudScanConfig {
  float min_range_m = 0.5f;    ///< [m]
  float max_range_m = 120.0f;  ///< [m]
  /// Beam elevations by ring, ascending (0 = lowest) [rad], for clouds without a ring field.
  std::vector<double> ring_elevations_rad;
};

enum class CloudScanStatus : std::uint8_t {
  kOk,
  kNoXyz,        ///< no x, y or z field: not a point cloud posed can use
  kBigEndian,    ///< is_bigendian clouds are not decoded
  kNoBuffer,     ///< the pool had no free buffer: the scan is dropped (consumer too slow)
  kTimeTooLong,  ///< point times span more than 2 s (LidarPoint::offset_ns is int32 ns)
};

std::string_view to_string(CloudScanStatus s);

/// What one decode found beyond the scan.
struct CloudScanInfo {
  std::uint32_t points_in = 0;        ///< points in the message
  std::uint32_t points_out = 0;       ///< points in the scan
  std::uint32_t points_invalid = 0;   ///< not finite, or outside the range limits
  std::uint32_t points_overflow = 0;  ///< valid points that did not fit the pool buffer
  bool has_time = false;              ///< per-point times were present (deskew possible)
  bool derived_ring = false;          ///< rings came from elevations, not from a ring field
};

class CloudScanDecoder {
 public:
  CloudScanDecoder(PayloadPool& pool, CloudScanConfig config);

  /// Decodes `cloud` whose header.stamp is `stamp` on the host clock into `out` (points in a
  /// pool buffer, start/end stamps, sequence). kOk or a status; on kNoBuffer the sequence
  /// still advances, so the consumer sees the gap.
  CloudScanStatus decode(const PointCloud2& cloud, HostTime stamp, LidarScan& out,
                         CloudScanInfo& info);

 private:
  std::uint16_t ring_from_elevation(float x, float y, float z) const;

  PayloadPool& pool_;
  CloudScanConfig config_;
  std::uint64_t next_sequence_ = 0;
};

}  // namespace posed::drivers::recording::ros1
