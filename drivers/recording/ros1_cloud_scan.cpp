#include "drivers/recording/ros1_cloud_scan.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace posed::drivers::recording::ros1 {

std::string_view to_string(CloudScanStatus s) {
  switch (s) {
    case CloudScanStatus::kOk:
      return "ok";
    case CloudScanStatus::kNoXyz:
      return "no x/y/z fields";
    case CloudScanStatus::kBigEndian:
      return "big-endian cloud";
    case CloudScanStatus::kNoBuffer:
      return "no free scan buffer";
    case CloudScanStatus::kTimeTooLong:
      return "point times span more than 2 s";
  }
  return "unknown";
}

namespace {

/// Where one scalar lives in a point, and how to read it.
struct Accessor {
  std::uint32_t offset = 0;
  std::uint8_t datatype = 0;
  bool present = false;

  static Accessor of(const PointCloud2& cloud, std::string_view name) {
    Accessor a;
    if (const PointField* f = cloud.field(name); f != nullptr && f->count >= 1) {
      a = {f->offset, f->datatype, true};
    }
    return a;
  }

  double read(const std::byte* point) const {
    switch (static_cast<PointFieldType>(datatype)) {
      case PointFieldType::kInt8:
        return load<std::int8_t>(point);
      case PointFieldType::kUint8:
        return load<std::uint8_t>(point);
      case PointFieldType::kInt16:
        return load<std::int16_t>(point);
      case PointFieldType::kUint16:
        return load<std::uint16_t>(point);
      case PointFieldType::kInt32:
        return load<std::int32_t>(point);
      case PointFieldType::kUint32:
        return load<std::uint32_t>(point);
      case PointFieldType::kFloat32:
        return load<float>(point);
      case PointFieldType::kFloat64:
        return load<double>(point);
    }
    return 0.0;
  }

  template <class T>
  double load(const std::byte* point) const {
    T v;
    std::memcpy(&v, point + offset, sizeof v);
    return static_cast<double>(v);
  }
};

// LidarPoint::offset_ns is int32 [ns]: about 2.1 s.
constexpr double kMaxSpanS = 2.0;

}  // namespace

CloudScanDecoder::CloudScanDecoder(PayloadPool& pool, CloudScanConfig config)
    : pool_(pool), config_(std::move(config)) {
  std::sort(config_.ring_elevations_rad.begin(), config_.ring_elevations_rad.end());
}

std::uint16_t CloudScanDecoder::ring_from_elevation(float x, float y, float z) const {
  const auto& e = config_.ring_elevations_rad;
  if (e.empty()) return 0;
  const double elevation = std::atan2(static_cast<double>(z), std::hypot(x, y));
  const auto it = std::lower_bound(e.begin(), e.end(), elevation);
  std::size_t ring = static_cast<std::size_t>(it - e.begin());
  if (ring == e.size() || (ring > 0 && elevation - e[ring - 1] < e[ring] - elevation)) --ring;
  return static_cast<std::uint16_t>(ring);
}

CloudScanStatus CloudScanDecoder::decode(const PointCloud2& cloud, HostTime stamp, LidarScan& out,
                                         CloudScanInfo& info) {
  info = {};
  info.points_in = static_cast<std::uint32_t>(
      std::min<std::size_t>(cloud.point_count(), std::numeric_limits<std::uint32_t>::max()));
  const Accessor x = Accessor::of(cloud, "x"), y = Accessor::of(cloud, "y"),
                 z = Accessor::of(cloud, "z");
  if (!x.present || !y.present || !z.present) return CloudScanStatus::kNoXyz;
  if (cloud.is_bigendian) return CloudScanStatus::kBigEndian;
  const Accessor intensity = Accessor::of(cloud, "intensity");
  const Accessor ring = Accessor::of(cloud, "ring");
  const Accessor time = Accessor::of(cloud, "time");
  info.has_time = time.present;
  info.derived_ring = !ring.present;

  out.sequence = next_sequence_++;
  out.points = pool_.acquire();
  out.point_count = 0;
  if (!out.points) return CloudScanStatus::kNoBuffer;
  const std::span<LidarPoint> points = out.points.as<LidarPoint>();

  // First pass: the points kept and their time span (the scan starts at the earliest).
  double min_t = std::numeric_limits<double>::infinity();
  double max_t = -std::numeric_limits<double>::infinity();
  const float min_r2 = config_.min_range_m * config_.min_range_m;
  const float max_r2 = config_.max_range_m * config_.max_range_m;
  std::uint32_t n = 0;
  for (std::size_t i = 0; i < cloud.point_count(); ++i) {
    const std::byte* p = cloud.point(i).data();
    LidarPoint lp;
    lp.x = static_cast<float>(x.read(p));
    lp.y = static_cast<float>(y.read(p));
    lp.z = static_cast<float>(z.read(p));
    const float r2 = lp.x * lp.x + lp.y * lp.y + lp.z * lp.z;
    if (!std::isfinite(r2) || r2 < min_r2 || r2 > max_r2) {
      ++info.points_invalid;
      continue;
    }
    if (n == points.size()) {
      ++info.points_overflow;
      continue;
    }
    lp.intensity = intensity.present ? static_cast<float>(intensity.read(p)) : 0.f;
    lp.ring = ring.present ? static_cast<std::uint16_t>(std::clamp(ring.read(p), 0.0, 65535.0))
                           : ring_from_elevation(lp.x, lp.y, lp.z);
    if (time.present) {
      const double t = time.read(p);
      if (std::isfinite(t)) {
        min_t = std::min(min_t, t);
        max_t = std::max(max_t, t);
      }
    }
    points[n++] = lp;
  }
  out.point_count = n;
  info.points_out = n;
  if (!time.present || n == 0 || !std::isfinite(min_t)) {
    out.start_stamp = out.end_stamp = stamp;
    return CloudScanStatus::kOk;
  }
  CloudScanStatus status = CloudScanStatus::kOk;
  if (max_t - min_t > kMaxSpanS) {
    status = CloudScanStatus::kTimeTooLong;
    max_t = min_t + kMaxSpanS;
  }
  // Second pass over the same points (the first n valid ones) for their offsets from the start,
  // which the first pass could not know yet.
  out.start_stamp = stamp + Duration::from_ns(std::llround(min_t * 1e9));
  out.end_stamp = stamp + Duration::from_ns(std::llround(max_t * 1e9));
  std::uint32_t k = 0;
  for (std::size_t i = 0; i < cloud.point_count() && k < n; ++i) {
    const std::byte* p = cloud.point(i).data();
    const float px = static_cast<float>(x.read(p)), py = static_cast<float>(y.read(p)),
                pz = static_cast<float>(z.read(p));
    const float r2 = px * px + py * py + pz * pz;
    if (!std::isfinite(r2) || r2 < min_r2 || r2 > max_r2) continue;
    double t = time.read(p);
    if (!std::isfinite(t)) t = min_t;
    points[k++].offset_ns =
        static_cast<std::int32_t>(std::llround((std::clamp(t, min_t, max_t) - min_t) * 1e9));
  }
  return status;
}

}  // namespace posed::drivers::recording::ros1
