// posed writes its map.pcd with its own writer (posed does not link pcl_io: it would load VTK,
// OpenNI and libpcap at run time). PCL's reader, which CloudCompare-, Open3D- and ROS-side tools
// share the format with, must open it as written: this is the one place posed uses pcl_io.

#include <gtest/gtest.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>
#include <unistd.h>

#include <filesystem>

#include "drivers/recording/map_directory.hpp"
#include "tests/unit/mapping/synthetic_scene.hpp"

namespace posed::drivers::recording {
namespace {

TEST(PclReadsMap, PclsReaderOpensMapPcdWithItsFieldsAndPoints) {
  // Two keyframes of a room, the second moved and turned: map.pcd holds both in the map frame.
  mapping::KeyframeMap map;
  const std::vector<Eigen::Vector3f> room = test::sample_boxes(test::furnished_room(), 0.5f);
  for (int i = 0; i < 2; ++i) {
    mapping::MapKeyframe kf;
    kf.stamp_ns = 1'700'000'000'000'000'000 + i * 100'000'000;
    kf.T_map_base = test::pose(1.5 * i, 0.5 * i, 0, 0.3 * i);
    kf.points_base = room;
    kf.context.bins = Eigen::MatrixXf::Zero(map.scan_context.rings, map.scan_context.sectors);
    kf.context.ring_key = Eigen::VectorXf::Zero(map.scan_context.rings);
    kf.context.sector_key = Eigen::VectorXf::Zero(map.scan_context.sectors);
    map.keyframes.push_back(kf);
  }
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("posed_pcl_map_" + std::to_string(::getpid()));
  std::string error;
  ASSERT_TRUE(write_map_directory(dir.string(), map, error)) << error;

  pcl::PCLPointCloud2 cloud;
  ASSERT_EQ(pcl::io::loadPCDFile((dir / "map.pcd").string(), cloud), 0);
  ASSERT_EQ(cloud.fields.size(), 4u);
  EXPECT_EQ(cloud.fields[0].name, "x");
  EXPECT_EQ(cloud.fields[3].name, "keyframe");
  EXPECT_EQ(cloud.fields[3].datatype, pcl::PCLPointField::UINT32);
  EXPECT_EQ(cloud.width * cloud.height, 2 * room.size());

  pcl::PointCloud<pcl::PointXYZ> xyz;
  ASSERT_EQ(pcl::io::loadPCDFile((dir / "map.pcd").string(), xyz), 0);
  ASSERT_EQ(xyz.size(), 2 * room.size());
  for (std::size_t k = 0; k < room.size(); k += 97) {
    for (std::size_t i = 0; i < 2; ++i) {
      // The point as the keyframe keeps it (to 4 mm), in the map frame.
      const Eigen::Vector3f expected =
          map.keyframes[i].T_map_base.cast<float>() * map.keyframes[i].points_base[k];
      const pcl::PointXYZ& p = xyz[i * room.size() + k];
      EXPECT_LT((Eigen::Vector3f(p.x, p.y, p.z) - expected).norm(), 1e-5f) << i << "/" << k;
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace posed::drivers::recording
