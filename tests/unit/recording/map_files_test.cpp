#include "drivers/recording/map_files.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace posed::drivers::recording {
namespace map_files_test {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

class MapFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/posed-mapfiles-XXXXXX";
    dir_ = ::mkdtemp(pattern);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string dir_;
};

TEST_F(MapFiles, PcdIsVersion07BinaryWithTheExactPoints) {
  const std::vector<Eigen::Vector3f> points = {{1.5f, -2.25f, 0.125f}, {100.0f, 0.0f, -3.5f}};
  std::string error;
  const std::string path = dir_ + "/map.pcd";
  ASSERT_TRUE(write_pcd(path, points, error)) << error;
  const std::string file = slurp(path);
  const std::string header =
      "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n"
      "TYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\n"
      "DATA binary\n";
  ASSERT_EQ(file.substr(0, header.size()), header);
  ASSERT_EQ(file.size(), header.size() + 24);
  float xyz[6];
  std::memcpy(xyz, file.data() + header.size(), sizeof xyz);
  EXPECT_EQ(xyz[0], 1.5f);
  EXPECT_EQ(xyz[1], -2.25f);
  EXPECT_EQ(xyz[2], 0.125f);
  EXPECT_EQ(xyz[3], 100.0f);
  EXPECT_EQ(xyz[5], -3.5f);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
}

TEST_F(MapFiles, TumLinesCarryNanosecondStampsAndUnitQuaternions) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translate(Eigen::Vector3d(1, 2, 3));
  T.rotate(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  std::string error;
  const std::string path = dir_ + "/kf.tum";
  ASSERT_TRUE(write_tum(path, {{WallTime::from_ns(1'700'000'000'123'456'789), T}}, error)) << error;
  std::istringstream in(slurp(path));
  std::string comment, line;
  std::getline(in, comment);
  EXPECT_EQ(comment[0], '#');
  std::getline(in, line);
  EXPECT_EQ(line.rfind("1700000000.123456789 1 2 3 0 0 0.70710678", 0), 0u) << line;
  EXPECT_EQ(tum_line(-500'000'000, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()),
            "-0.500000000 0 0 0 0 0 0 1\n");
}

TEST_F(MapFiles, AFileThatCannotBeWrittenIsAnErrorNamingIt) {
  std::string error;
  EXPECT_FALSE(write_pcd(dir_ + "/missing/dir/map.pcd", {}, error));
  EXPECT_NE(error.find("missing/dir/map.pcd"), std::string::npos) << error;
  EXPECT_NE(error.find("No such file"), std::string::npos) << error;
}

}  // namespace map_files_test
}  // namespace posed::drivers::recording
