#include "drivers/recording/map_directory.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "core/mapping/loop_closer.hpp"
#include "tests/unit/mapping/deskewed_scan.hpp"

namespace posed::drivers::recording {
namespace {

namespace fs = std::filesystem;

/// A map with loops from the room's 60 s (its optimised poses, its edges of both kinds).
const mapping::KeyframeMap& room_map() {
  static const mapping::KeyframeMap map = [] {
    const sim::LidarImuRun& run = test::simulated("room", 60.0);
    mapping::LoopClosureConfig config;
    config.min_separation_s = 15.0;
    mapping::LoopCloser closer(config);
    std::vector<Eigen::Vector3f> points_base;
    for (const sim::DecodedScan& scan : run.scans) {
      test::deskewed_base(run, scan, points_base);
      closer.add(scan.end, run.T_map_base(scan.end), points_base);
    }
    return closer.snapshot();
  }();
  return map;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("posed_map_dir_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

TEST(MapDirectory, SaveThenLoadGivesTheSameMap) {
  const mapping::KeyframeMap& saved = room_map();
  ASSERT_GT(saved.keyframes.size(), 20u);
  ASSERT_GT(saved.edges.size(), saved.keyframes.size() - 1);  // a loop or more
  // and keyframes of the laps after the first, which left cloud and descriptor to the first's
  const auto mapped = std::count_if(
      saved.keyframes.begin(), saved.keyframes.end(), [](const mapping::MapKeyframe& kf) {
        return kf.points_base.size() == 0 && kf.context.bins.size() == 0;
      });
  EXPECT_GT(mapped, 5);
  const fs::path dir = fresh_dir("round_trip");
  std::string error;
  ASSERT_TRUE(write_map_directory(dir.string(), saved, error)) << error;
  mapping::KeyframeMap loaded;
  ASSERT_TRUE(read_map_directory(dir.string(), loaded, error)) << error;

  EXPECT_DOUBLE_EQ(loaded.voxel_m, saved.voxel_m);
  EXPECT_DOUBLE_EQ(loaded.max_range_m, saved.max_range_m);
  EXPECT_DOUBLE_EQ(loaded.scan_context.max_range_m, saved.scan_context.max_range_m);
  EXPECT_EQ(loaded.scan_context.rings, saved.scan_context.rings);
  EXPECT_EQ(loaded.scan_context.sectors, saved.scan_context.sectors);
  ASSERT_EQ(loaded.keyframes.size(), saved.keyframes.size());
  for (std::size_t i = 0; i < saved.keyframes.size(); ++i) {
    const mapping::MapKeyframe& a = saved.keyframes[i];
    const mapping::MapKeyframe& b = loaded.keyframes[i];
    EXPECT_EQ(a.stamp_ns, b.stamp_ns);
    EXPECT_LT((a.T_map_base.translation() - b.T_map_base.translation()).norm(), 1e-5);
    EXPECT_TRUE(a.T_map_base.linear().isApprox(b.T_map_base.linear(), 1e-7));
    ASSERT_EQ(a.points_base.size(), b.points_base.size()) << "keyframe " << i;
    for (std::size_t k = 0; k < a.points_base.size(); ++k) {
      // Through float32 in the map frame and back to the 4 mm steps a keyframe keeps: a
      // coordinate next to half a step may round to the neighbouring one.
      ASSERT_LE((a.points_base[k] - b.points_base[k]).cwiseAbs().maxCoeff(),
                mapping::CompactCloud::kResolutionM * 1.01f)
          << i << "/" << k;
    }
    ASSERT_EQ(a.context.bins.size(), b.context.bins.size()) << "keyframe " << i;
    EXPECT_EQ(a.context.bins, b.context.bins);
    EXPECT_EQ(a.context.ring_key, b.context.ring_key);
    EXPECT_EQ(a.context.sector_key, b.context.sector_key);
  }
  ASSERT_EQ(loaded.edges.size(), saved.edges.size());
  for (std::size_t i = 0; i < saved.edges.size(); ++i) {
    EXPECT_EQ(loaded.edges[i].from, saved.edges[i].from);
    EXPECT_EQ(loaded.edges[i].to, saved.edges[i].to);
    EXPECT_EQ(loaded.edges[i].loop, saved.edges[i].loop);
    EXPECT_TRUE(loaded.edges[i].T_from_to.isApprox(saved.edges[i].T_from_to, 1e-6));
  }
  fs::remove_all(dir);
}

TEST(MapDirectory, DamageIsNamedWithTheFileAndWhere) {
  const fs::path dir = fresh_dir("damage");
  std::string error;
  ASSERT_TRUE(write_map_directory(dir.string(), room_map(), error)) << error;
  mapping::KeyframeMap loaded;

  // A truncated cloud: the point and byte it ends at.
  const fs::path pcd = dir / "map.pcd";
  const auto full = fs::file_size(pcd);
  fs::resize_file(pcd, full - 10);
  EXPECT_FALSE(read_map_directory(dir.string(), loaded, error));
  EXPECT_NE(error.find("map.pcd: truncated at point"), std::string::npos) << error;

  // A point further from its keyframe than a keyframe keeps (an edited map): which, and where.
  ASSERT_TRUE(write_map_directory(dir.string(), room_map(), error)) << error;
  {
    std::fstream f(pcd, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(-16, std::ios::end);  // the last point: x y z keyframe
    const float x = 1000.0f;
    f.write(reinterpret_cast<const char*>(&x), sizeof x);
  }
  EXPECT_FALSE(read_map_directory(dir.string(), loaded, error));
  EXPECT_NE(error.find("map.pcd: point "), std::string::npos) << error;
  EXPECT_NE(error.find("m of itself on every axis"), std::string::npos) << error;

  // A bad keyframe line: the file and line.
  ASSERT_TRUE(write_map_directory(dir.string(), room_map(), error)) << error;
  {
    std::ofstream out(dir / "keyframes.tum", std::ios::app);
    out << "12.5 1 2 3 0 0 0\n";
  }
  EXPECT_FALSE(read_map_directory(dir.string(), loaded, error));
  const std::string where = (dir / "keyframes.tum").string() + ":" +
                            std::to_string(room_map().keyframes.size() + 2) + ": expected 8 fields";
  EXPECT_NE(error.find(where), std::string::npos) << error;

  // A manifest from before stop 55, without the clouds' range: they were kept to 60 m. One
  // whose range a keyframe could not hold: named.
  ASSERT_TRUE(write_map_directory(dir.string(), room_map(), error)) << error;
  const auto rewrite_range = [&](const std::string& replacement) {
    std::ifstream in(dir / "map.yaml");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t at = text.find("\nmax_range_m: ");
    ASSERT_NE(at, std::string::npos) << text;
    text.replace(at + 1, text.find('\n', at + 1) - at, replacement);
    std::ofstream(dir / "map.yaml", std::ios::trunc) << text;
  };
  rewrite_range("");
  ASSERT_TRUE(read_map_directory(dir.string(), loaded, error)) << error;
  EXPECT_DOUBLE_EQ(loaded.max_range_m, 60.0);
  ASSERT_TRUE(write_map_directory(dir.string(), room_map(), error)) << error;
  rewrite_range("max_range_m: 500\n");
  EXPECT_FALSE(read_map_directory(dir.string(), loaded, error));
  EXPECT_NE(error.find("map.yaml: max_range_m must be above 0 and at most 131 m"),
            std::string::npos)
      << error;

  // No manifest: not a (complete) map directory.
  fs::remove(dir / "map.yaml");
  EXPECT_FALSE(read_map_directory(dir.string(), loaded, error));
  EXPECT_NE(error.find("map.yaml: cannot open"), std::string::npos) << error;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace posed::drivers::recording
