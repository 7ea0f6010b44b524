// Features on known geometry: a box-shaped room scanned by 32 rings from off-centre. Edges must
// lie on the room's corner lines, planar features on its faces away from the corners, and ground
// must be exactly the floor.

#include "core/lidar/feature_extractor.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace posed::lidar {
namespace {

// Room [-4, 4] x [-3, 3] x [0, 3] m; the sensor at (0.6, 0.4, 1.0).
const Eigen::Vector3d kLo(-4, -3, 0), kHi(4, 3, 3), kSensor(0.6, 0.4, 1.0);

std::vector<ScanPoint> scan_room(int columns) {
  std::vector<ScanPoint> points;
  for (int ring = 0; ring < 32; ++ring) {
    const double elevation = (-25.0 + 40.0 * ring / 31.0) * std::numbers::pi / 180.0;
    for (int c = 0; c < columns; ++c) {
      const double az = 2 * std::numbers::pi * (c + 0.5) / columns;
      const Eigen::Vector3d d(std::cos(elevation) * std::cos(az),
                              std::cos(elevation) * std::sin(az), std::sin(elevation));
      // Nearest exit through the box's faces.
      double t = 1e9;
      for (int a = 0; a < 3; ++a) {
        if (std::abs(d[a]) < 1e-12) continue;
        const double bound = d[a] > 0 ? kHi[a] : kLo[a];
        t = std::min(t, (bound - kSensor[a]) / d[a]);
      }
      ScanPoint p;
      p.p = (t * d).cast<float>();  // sensor frame = room axes, origin at the sensor
      p.range_m = static_cast<float>(t);
      p.ring = static_cast<std::uint16_t>(ring);
      p.column = static_cast<std::uint16_t>(c);
      points.push_back(p);
    }
  }
  return points;
}

/// Distance of a room-frame point to the nearest of the room's 12 edges.
double distance_to_room_edge(const Eigen::Vector3d& p) {
  double best = 1e9;
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    for (const double va : {kLo[a], kHi[a]})
      for (const double vb : {kLo[b], kHi[b]})
        best = std::min(best, std::hypot(p[a] - va, p[b] - vb));
  }
  return best;
}

double distance_to_room_face(const Eigen::Vector3d& p) {
  double best = 1e9;
  for (int a = 0; a < 3; ++a)
    best = std::min({best, std::abs(p[a] - kLo[a]), std::abs(p[a] - kHi[a])});
  return best;
}

TEST(FeatureExtractor, EdgesOnCornersPlanesOnFacesGroundOnTheFloor) {
  FeatureConfig config;
  config.columns = 1800;
  config.range_noise_m = 0.0;
  config.plane_voxel_m = 0.0;  // keep every planar pixel for this check
  config.edge_voxel_m = 0.0;
  FeatureExtractor extractor(config);
  const std::vector<ScanPoint> points = scan_room(config.columns);
  ScanFeatures f;
  extractor.extract(points, f);

  // Ground: the floor returns of the lower rings (the rings that reach it inside the room).
  std::size_t floor_points = 0;
  for (const ScanPoint& p : points) {
    if ((p.p.cast<double>() + kSensor).z() < 1e-4 && p.ring < config.ground_rows) ++floor_points;
  }
  // The lowest wall returns just above the floor look like ground too (a shallow step between
  // rings), as in LeGO-LOAM: a few percent at most.
  EXPECT_GT(f.ground_pixels, floor_points * 9 / 10);
  EXPECT_LE(f.ground_pixels, floor_points * 11 / 10);

  ASSERT_GT(f.edges.size(), 40u);
  for (const Eigen::Vector3f& e : f.edges) {
    EXPECT_LT(distance_to_room_edge(e.cast<double>() + kSensor), 0.35) << e.transpose();
  }
  // The four vertical corners are all found (rings cross each one).
  for (const double x : {kLo.x(), kHi.x()}) {
    for (const double y : {kLo.y(), kHi.y()}) {
      int near = 0;
      for (const Eigen::Vector3f& e : f.edges) {
        const Eigen::Vector3d w = e.cast<double>() + kSensor;
        near += std::hypot(w.x() - x, w.y() - y) < 0.35 ? 1 : 0;
      }
      EXPECT_GE(near, 5) << "corner " << x << ", " << y;
    }
  }
  ASSERT_GT(f.planes.size(), 10000u);
  std::size_t near_corners = 0;
  for (const Eigen::Vector3f& p : f.planes) {
    const Eigen::Vector3d w = p.cast<double>() + kSensor;
    EXPECT_LT(distance_to_room_face(w), 1e-3);
    for (const double x : {kLo.x(), kHi.x()})
      for (const double y : {kLo.y(), kHi.y()})
        near_corners += std::hypot(w.x() - x, w.y() - y) < 0.05;
  }
  // Planar pixels are the smooth ones: none sits on a vertical corner, where every ring kinks.
  EXPECT_EQ(near_corners, 0u);
}

TEST(FeatureExtractor, DownsamplingKeepsOnePointPerVoxel) {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 1000; ++i) points.emplace_back(0.001f * static_cast<float>(i), 0.f, 0.f);
  std::vector<std::uint64_t> keys;
  voxel_downsample(points, 0.1, keys);
  EXPECT_EQ(points.size(), 10u);  // x in [0, 1) m: ten 0.1 m voxels
}

}  // namespace
}  // namespace posed::lidar
