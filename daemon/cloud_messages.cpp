#include "daemon/cloud_messages.hpp"

#include <cstring>

namespace posed {
namespace {

using Field = dds::PointFieldMessage;

template <class T>
void put(std::uint8_t* at, T value) {
  std::memcpy(at, &value, sizeof value);  // packed layout: fields are not aligned
}

}  // namespace

void scan_cloud(const MatchedScan& scan, WallTime stamp, const std::string& frame_id,
                dds::CloudMessage& out) {
  out.stamp = stamp;
  out.frame_id = frame_id;
  if (out.fields.size() != 6) {
    out.fields = {{"x", 0, Field::kFloat32, 1},    {"y", 4, Field::kFloat32, 1},
                  {"z", 8, Field::kFloat32, 1},    {"intensity", 12, Field::kFloat32, 1},
                  {"ring", 16, Field::kUint16, 1}, {"time", 18, Field::kFloat32, 1}};
  }
  out.point_step = kScanPointStep;
  out.width = static_cast<std::uint32_t>(scan.points_lidar.size());
  out.data.resize(static_cast<std::size_t>(out.width) * kScanPointStep);
  out.is_dense = true;  // deskew drops non-finite points
  // Firing offsets count from the scan's start; the stamp is its end.
  const std::int64_t start_minus_end_ns = (scan.start_stamp - scan.stamp).ns;
  std::uint8_t* p = out.data.data();
  for (const lidar::ScanPoint& sp : scan.points_lidar) {
    put(p + 0, sp.p.x());
    put(p + 4, sp.p.y());
    put(p + 8, sp.p.z());
    put(p + 12, sp.intensity);
    put(p + 16, sp.ring);
    put(p + 18, static_cast<float>(static_cast<double>(start_minus_end_ns + sp.offset_ns) * 1e-9));
    p += kScanPointStep;
  }
}

void map_cloud(std::span<const Eigen::Vector3f> points_map_m, WallTime stamp,
               const std::string& frame_id, dds::CloudMessage& out) {
  out.stamp = stamp;
  out.frame_id = frame_id;
  if (out.fields.size() != 3) {
    out.fields = {
        {"x", 0, Field::kFloat32, 1}, {"y", 4, Field::kFloat32, 1}, {"z", 8, Field::kFloat32, 1}};
  }
  out.point_step = 12;
  out.width = static_cast<std::uint32_t>(points_map_m.size());
  out.data.resize(points_map_m.size() * 12);
  out.is_dense = true;
  std::uint8_t* p = out.data.data();
  for (const Eigen::Vector3f& q : points_map_m) {
    put(p + 0, q.x());
    put(p + 4, q.y());
    put(p + 8, q.z());
    p += 12;
  }
}

}  // namespace posed
