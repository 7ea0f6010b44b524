#include "tools/eval/trajectory_io.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "tools/eval/eval_error.hpp"

namespace posed::eval {
namespace {

/// The EvalError message of parsing `text` as file `name`, or "" when it parses.
std::string parse_error(const std::string& text, const std::string& name = "traj.txt",
                        TrajectoryFormat format = TrajectoryFormat::kAuto) {
  try {
    parse_trajectory(text, name, format);
  } catch (const EvalError& e) {
    return e.what();
  }
  return "";
}

TEST(TrajectoryIo, TumWithCommentsBlankLinesAndCommasIsReadExactly) {
  const Trajectory t = parse_trajectory(
      "# timestamp tx ty tz qx qy qz qw\n"
      "\n"
      "1305031102.160407 1.5 -2 3 0 0 0 1\n"
      "1305031102.194330,1,2,3,0,0,0.7071067811865476,0.7071067811865476\r\n",
      "a.txt");
  EXPECT_EQ(t.format, TrajectoryFormat::kTum);
  ASSERT_EQ(t.size(), 2u);
  // Stamps to the ns, without the rounding of a double holding 1.3e9 s.
  EXPECT_EQ(t.stamps[0].ns, 1305031102160407000);
  EXPECT_EQ(t.stamps[1].ns, 1305031102194330000);
  EXPECT_EQ(t.p_world_m[0], Eigen::Vector3d(1.5, -2, 3));
  EXPECT_TRUE(t.has_orientation);
  // 90 degrees about z: x -> y.
  EXPECT_NEAR((t.R_world_body[1] * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0.0,
              1e-12);
}

TEST(TrajectoryIo, KittiRowMajorMatrixIsTakenAsWritten) {
  const Trajectory t = parse_trajectory(
      "1 0 0 1.5 0 1 0 2.5 0 0 1 3.5\n"
      "0 -1 0 4 1 0 0 5 0 0 1 6\n",
      "k.txt");
  EXPECT_EQ(t.format, TrajectoryFormat::kKitti);
  EXPECT_FALSE(t.has_stamps());
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t.p_world_m[0], Eigen::Vector3d(1.5, 2.5, 3.5));
  EXPECT_EQ(t.p_world_m[1], Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(t.R_world_body[1](0, 1), -1.0);
  EXPECT_EQ(t.R_world_body[1](1, 0), 1.0);
}

TEST(TrajectoryIo, ZeroQuaternionsMeanPositionsOnly) {
  const Trajectory t = parse_trajectory("1.0 1 2 3 0 0 0 0\n2.0 1 2 4 0 0 0 0\n", "m2dgr.txt");
  EXPECT_FALSE(t.has_orientation);
  EXPECT_EQ(parse_error("1.0 1 2 3 0 0 0 0\n2.0 1 2 4 0 0 0 1\n"),
            "traj.txt:2: quaternion given, but earlier lines are positions only (qx qy qz qw = 0)");
}

TEST(TrajectoryIo, ErrorsNameFileAndLine) {
  EXPECT_EQ(parse_error("# c\n1 2 3 4 5 6 7\n"),
            "traj.txt:2: cannot tell the format: expected 8 fields (TUM: stamp x y z qx qy qz "
            "qw) or 12 (KITTI: 3x4 [R|t] row-major), found 7");
  EXPECT_EQ(parse_error("1.0 1 2 3 0 0 0 1\n\n2.0 1 2 3 0 0 1\n"),
            "traj.txt:3: expected 8 fields (TUM: stamp x y z qx qy qz qw), found 7");
  EXPECT_EQ(parse_error("1.0 1 2 3 0 0 0 1\n2.0 1 two 3 0 0 0 1\n", "est.txt"),
            "est.txt:2: field 3 'two' is not a finite number");
  EXPECT_EQ(parse_error("1.0 1 2 3 0 0 0 1\n2.0 1 nan 3 0 0 0 1\n"),
            "traj.txt:2: field 3 'nan' is not a finite number");
  EXPECT_EQ(parse_error("1.0 1 2 3 0 0 0 1\nx1 1 2 3 0 0 0 1\n"),
            "traj.txt:2: stamp 'x1' is not a number [s]");
  EXPECT_EQ(parse_error("2.0 1 2 3 0 0 0 1\n1.5 1 2 3 0 0 0 1\n"),
            "traj.txt:2: stamp 1.5 s is not after the previous one: TUM stamps must increase");
  EXPECT_EQ(parse_error("1 0 0 1 0 1 0 2 0 0 1 3\n", "k.txt", TrajectoryFormat::kTum),
            "k.txt:1: expected 8 fields (TUM: stamp x y z qx qy qz qw), found 12");
  EXPECT_EQ(parse_error("# only a comment\n\n"),
            "traj.txt: no poses (only blank or '#' comment lines)");
}

TEST(TrajectoryIo, MissingFileSaysSo) {
  const std::string path = "/nonexistent-posed-eval/gt.txt";
  try {
    read_trajectory(path);
    FAIL() << "no error for a missing file";
  } catch (const EvalError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": cannot open: No such file or directory");
  }
}

TEST(TrajectoryIo, ReadsAFile) {
  const auto path = std::filesystem::temp_directory_path() / "posed_eval_io_test.txt";
  {
    std::ofstream out(path);
    out << "1 0 0 1 0 1 0 2 0 0 1 3\n1 0 0 4 0 1 0 5 0 0 1 6\n";
  }
  const Trajectory t = read_trajectory(path.string());
  std::filesystem::remove(path);
  EXPECT_EQ(t.source, path.string());
  EXPECT_EQ(t.size(), 2u);
}

TEST(TrajectoryIo, StampParsing) {
  TrajectoryTime t;
  ASSERT_TRUE(parse_stamp("0.0000000015", t));  // rounded to the nearest ns
  EXPECT_EQ(t.ns, 2);
  ASSERT_TRUE(parse_stamp("-1.25", t));
  EXPECT_EQ(t.ns, -1'250'000'000);
  ASSERT_TRUE(parse_stamp("1.3e9", t));
  EXPECT_EQ(t.ns, 1'300'000'000'000'000'000);
  ASSERT_TRUE(parse_stamp("17", t));
  EXPECT_EQ(t.ns, 17'000'000'000);
  EXPECT_FALSE(parse_stamp("1.2.3", t));
  EXPECT_FALSE(parse_stamp("", t));
  EXPECT_FALSE(parse_stamp(".", t));
  EXPECT_FALSE(parse_stamp("99999999999", t));  // would overflow int64 ns
}

}  // namespace
}  // namespace posed::eval
