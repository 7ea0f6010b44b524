// Calibration loaders: the three formats of the VLP-32C table (plus the one shipped with the
// capture) must agree, match the manual's nominal table, and reject bad files with context.

#include "drivers/velodyne/calibration.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "drivers/velodyne/calibration_loader.hpp"
#include "tests/common/realdata.hpp"

namespace posed::drivers::velodyne {
namespace {

Calibration load_or_fail(const std::string& path) {
  Calibration c;
  std::string error;
  EXPECT_TRUE(load_calibration(path, c, error)) << error;
  return c;
}

void expect_same_table(const Calibration& a, const Calibration& b, double tol_rad) {
  ASSERT_EQ(a.lasers.size(), b.lasers.size()) << a.source << " vs " << b.source;
  for (std::size_t i = 0; i < a.lasers.size(); ++i) {
    SCOPED_TRACE(a.source + " vs " + b.source + ", laser " + std::to_string(i));
    EXPECT_NEAR(a.lasers[i].vert_correction_rad, b.lasers[i].vert_correction_rad, tol_rad);
    EXPECT_NEAR(a.lasers[i].rot_correction_rad, b.lasers[i].rot_correction_rad, tol_rad);
    EXPECT_NEAR(a.lasers[i].dist_correction_m, b.lasers[i].dist_correction_m, 1e-9);
    EXPECT_NEAR(a.lasers[i].vert_offset_m, b.lasers[i].vert_offset_m, 1e-9);
    EXPECT_NEAR(a.lasers[i].horiz_offset_m, b.lasers[i].horiz_offset_m, 1e-9);
  }
}

TEST(VelodyneCalibration, ThreeFormatsAndTheCaptureFileAgree) {
  POSED_REQUIRE_REALDATA(xml, "velodyne_calib/VLP-32c.xml");
  POSED_REQUIRE_REALDATA(ros, "velodyne_calib/ros-drivers_VeloView-VLP-32C.yaml");
  POSED_REQUIRE_REALDATA(vd, "velodyne_calib/velodyne_decoder_VLP-32C.yml");
  POSED_REQUIRE_REALDATA(nebula, "velodyne_vlp32c/calibration_VLP32.yaml");
  const Calibration a = load_or_fail(xml), b = load_or_fail(ros), c = load_or_fail(vd),
                    d = load_or_fail(nebula);
  ASSERT_EQ(a.lasers.size(), 32u);  // the XML lists 64 entries, 32 enabled
  // The XML stores 3 decimals of a degree, the YAMLs 7-16 significant digits of a radian.
  expect_same_table(a, b, 1e-6);
  expect_same_table(a, c, 1e-6);
  expect_same_table(a, d, 1e-6);
  for (const Calibration* cal : {&a, &b, &c, &d}) {
    EXPECT_NEAR(cal->distance_resolution_m, 0.004, 1e-12) << cal->source;
  }
  // Spot values (VLP-32C manual table 9-2): laser 0 at -25°, azimuth offset +1.4°.
  EXPECT_NEAR(a.lasers[0].vert_correction_rad * 180 / std::numbers::pi, -25.0, 1e-9);
  EXPECT_NEAR(a.lasers[0].rot_correction_rad * 180 / std::numbers::pi, -1.4, 1e-9);
  EXPECT_NEAR(b.lasers[29].vert_correction_rad * 180 / std::numbers::pi, 15.0, 1e-6);
}

TEST(VelodyneCalibration, BuiltinTablesMatchTheFiles) {
  POSED_REQUIRE_REALDATA(ros, "velodyne_calib/ros-drivers_VeloView-VLP-32C.yaml");
  POSED_REQUIRE_REALDATA(hdl, "velodyne_hdl32e/HDL-32.xml");
  expect_same_table(builtin_calibration(ProductId::kVlp32c), load_or_fail(ros), 1e-6);
  const Calibration hdl_file = load_or_fail(hdl);
  EXPECT_NEAR(hdl_file.distance_resolution_m, 0.002, 1e-12);
  // HDL-32.xml stores float-rounded degrees (-9.3299999): agree to 1e-6 deg ≈ 2e-8 rad.
  expect_same_table(builtin_calibration(ProductId::kHdl32e), hdl_file, 1e-7);
}

TEST(VelodyneCalibration, BuiltinVlp16IsInterleaved) {
  const Calibration c = builtin_calibration(ProductId::kVlp16);
  ASSERT_EQ(c.lasers.size(), 16u);
  EXPECT_NEAR(c.lasers[0].vert_correction_rad * 180 / std::numbers::pi, -15.0, 1e-9);
  EXPECT_NEAR(c.lasers[1].vert_correction_rad * 180 / std::numbers::pi, 1.0, 1e-9);
  EXPECT_NEAR(c.lasers[14].vert_correction_rad * 180 / std::numbers::pi, -1.0, 1e-9);
  EXPECT_NEAR(c.lasers[15].vert_correction_rad * 180 / std::numbers::pi, 15.0, 1e-9);
  const auto rings = rings_by_elevation(c);
  EXPECT_EQ(rings[0], 0);
  EXPECT_EQ(rings[15], 15);
  EXPECT_EQ(rings[1], 8);  // +1° is the ninth lowest of -15..15 step 2
}

TEST(VelodyneCalibration, RingsFollowElevation) {
  const Calibration c = builtin_calibration(ProductId::kVlp32c);
  const auto rings = rings_by_elevation(c);
  EXPECT_EQ(rings[0], 0);    // -25°
  EXPECT_EQ(rings[29], 31);  // +15°
  for (std::size_t i = 0; i < 32; ++i) {
    for (std::size_t j = 0; j < 32; ++j) {
      if (c.lasers[i].vert_correction_rad < c.lasers[j].vert_correction_rad) {
        EXPECT_LT(rings[i], rings[j]) << i << " " << j;
      }
    }
  }
}

TEST(VelodyneCalibration, RejectsWrongLaserCountWithLine) {
  std::string yaml = "lasers:\n";
  for (int i = 0; i < 31; ++i) {
    yaml += "  - {laser_id: " + std::to_string(i) + ", rot_correction: 0, vert_correction: 0}\n";
  }
  yaml += "num_lasers: 31\n";
  Calibration c;
  std::string error;
  EXPECT_FALSE(parse_calibration_yaml(yaml, "bad.yaml", c, error));
  EXPECT_NE(error.find("bad.yaml line 33"), std::string::npos) << error;
  EXPECT_NE(error.find("expected 16 or 32 lasers, found 31"), std::string::npos) << error;
}

TEST(VelodyneCalibration, RejectsDeclaredCountMismatchDuplicatesAndGaps) {
  std::string base;
  for (int i = 0; i < 16; ++i) {
    base += "  - {laser_id: " + std::to_string(i) + ", vert_correction: 0.1}\n";
  }
  Calibration c;
  std::string error;
  EXPECT_FALSE(parse_calibration_yaml("lasers:\n" + base + "num_lasers: 32\n", "f", c, error));
  EXPECT_NE(error.find("num_lasers says 32, the table has 16"), std::string::npos) << error;
  EXPECT_FALSE(parse_calibration_yaml(
      "lasers:\n" + base + "  - {laser_id: 3, vert_correction: 0.1}\n", "f", c, error));
  EXPECT_NE(error.find("listed twice"), std::string::npos) << error;
  std::string gap = "lasers:\n";
  for (int i = 0; i < 16; ++i) {
    gap += "  - {laser_id: " + std::to_string(i == 7 ? 20 : i) + ", vert_correction: 0.1}\n";
  }
  EXPECT_FALSE(parse_calibration_yaml(gap, "f", c, error));
  EXPECT_NE(error.find("laser ids must be 0..15"), std::string::npos) << error;
  EXPECT_FALSE(parse_calibration_yaml("lasers: [1, 2", "f", c, error));
  EXPECT_NE(error.find("calibration file f"), std::string::npos) << error;
  EXPECT_FALSE(parse_calibration_yaml("lasers:\n  - {laser_id: x}\n", "f", c, error));
  // Angles must be radians: degrees by mistake are out of range.
  std::string degrees = "lasers:\n";
  for (int i = 0; i < 16; ++i) {
    degrees += "  - {laser_id: " + std::to_string(i) + ", vert_correction: -25}\n";
  }
  EXPECT_FALSE(parse_calibration_yaml(degrees, "f", c, error));
  EXPECT_NE(error.find("out of range"), std::string::npos) << error;
}

TEST(VelodyneCalibration, RejectsBadXml) {
  Calibration c;
  std::string error;
  EXPECT_FALSE(parse_calibration_xml("<a><b></a>", "x.xml", c, error));
  EXPECT_NE(error.find("x.xml"), std::string::npos) << error;
  EXPECT_FALSE(parse_calibration_xml("<root/>", "x.xml", c, error));
  EXPECT_NE(error.find("not a VeloView calibration"), std::string::npos) << error;
  EXPECT_FALSE(load_calibration("/nonexistent/calib.yaml", c, error));
  EXPECT_NE(error.find("/nonexistent/calib.yaml"), std::string::npos) << error;
}

}  // namespace
}  // namespace posed::drivers::velodyne
