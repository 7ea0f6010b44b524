#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "daemon/config/config_loader.hpp"
#include "daemon/config/config_schema.hpp"

namespace posed::config {
namespace {

LoadResult load(const std::string& text) { return load_config_text(text, "test.yaml"); }

// One error, and it says where and why.
void expect_single_error(const LoadResult& r, const std::string& key, int line,
                         const std::string& reason_part) {
  ASSERT_EQ(r.errors.size(), 1u) << r.error_text();
  EXPECT_EQ(r.errors[0].file, "test.yaml");
  EXPECT_EQ(r.errors[0].key, key);
  EXPECT_EQ(r.errors[0].line, line) << r.error_text();
  EXPECT_NE(r.errors[0].reason.find(reason_part), std::string::npos) << r.error_text();
}

TEST(Config, EveryDefaultPassesItsOwnValidation) {
  // Loading each default through the file path must produce no error: the table is consistent.
  for (const auto& f : schema()) {
    std::string yaml;
    std::string_view rest = f.key;
    int depth = 0;
    for (auto dot = rest.find('.'); dot != std::string_view::npos; dot = rest.find('.')) {
      yaml += std::string(2 * static_cast<std::size_t>(depth++), ' ') +
              std::string(rest.substr(0, dot)) + ":\n";
      rest = rest.substr(dot + 1);
    }
    yaml += std::string(2 * static_cast<std::size_t>(depth), ' ') + std::string(rest) + ": " +
            std::string(f.default_yaml) + "\n";
    const auto r = load(yaml);
    EXPECT_TRUE(r.ok()) << f.key << ": " << r.error_text();
    EXPECT_FALSE(f.description.empty()) << f.key;
  }
}

TEST(Config, KeysAreUnique) {
  const auto fields = schema();
  for (std::size_t i = 0; i < fields.size(); ++i) {
    for (std::size_t j = i + 1; j < fields.size(); ++j) EXPECT_NE(fields[i].key, fields[j].key);
  }
}

TEST(Config, DefaultsAreTheM2dgrRig) {
  const PosedConfig c = default_config();
  EXPECT_EQ(c.dds.map_frame, "map");
  EXPECT_EQ(c.dds.base_frame, "base_link");
  EXPECT_DOUBLE_EQ(c.imu.gravity_mps2, 9.805);
  // Intrinsics read from M2DGR's transposed matrix: cx, cy are in its last row.
  EXPECT_DOUBLE_EQ(c.visible_camera.cx, 327.710279392468);
  EXPECT_DOUBLE_EQ(c.thermal_camera.fx, 435.836180277211);
  EXPECT_DOUBLE_EQ(c.extrinsics.T_imu_lidar[3], 0.27255);
  // M2DGR has no depth: a D435's factory calibration, the stream off.
  EXPECT_FALSE(c.depth_camera.enabled);
  EXPECT_DOUBLE_EQ(c.depth_camera.fx, 390.431457519531);
  EXPECT_DOUBLE_EQ(c.depth_camera.depth_unit_m, 0.001);
  EXPECT_DOUBLE_EQ(c.extrinsics.T_cam_depth[3], 0.0143);
}

TEST(Config, EmptyFileMeansDefaults) {
  const auto r = load("");
  ASSERT_TRUE(r.ok()) << r.error_text();
  EXPECT_EQ(r.config.imu.source, "serial");
}

TEST(Config, ValuesOverrideDefaults) {
  const auto r = load("imu:\n  source: synthetic\n  rate_hz: 400\ndds:\n  domain_id: 7\n");
  ASSERT_TRUE(r.ok()) << r.error_text();
  EXPECT_EQ(r.config.imu.source, "synthetic");
  EXPECT_DOUBLE_EQ(r.config.imu.rate_hz, 400);
  EXPECT_EQ(r.config.dds.domain_id, 7);
}

TEST(Config, UnknownKeyNamesLineAndSuggests) {
  const auto r = load("imu:\n  source: synthetic\n  rate_hzz: 400\n");
  expect_single_error(r, "imu.rate_hzz", 3, "unknown key (did you mean 'imu.rate_hz'?)");
}

TEST(Config, AKeySetTwiceNamesBothLines) {
  // In one mapping, and in a section written twice: either way only one of them could count.
  expect_single_error(load("imu:\n  rate_hz: 400\n  source: synthetic\n  rate_hz: 200\n"),
                      "imu.rate_hz", 4, "set twice (first on line 2); keep one");
  expect_single_error(load("imu:\n  rate_hz: 400\ndds:\n  domain_id: 7\nimu:\n  rate_hz: 200\n"),
                      "imu.rate_hz", 6, "set twice (first on line 2); keep one");
}

TEST(Config, UnknownSection) {
  const auto r = load("camera:\n  fx: 1\n");
  expect_single_error(r, "camera", 1, "unknown key");
}

TEST(Config, WrongTypeNumber) {
  const auto r = load("imu:\n  rate_hz: fast\n");
  expect_single_error(r, "imu.rate_hz", 2, "expected a number, found 'fast'");
}

TEST(Config, WrongTypeMappingForScalar) {
  const auto r = load("imu:\n  rate_hz:\n    value: 3\n");
  expect_single_error(r, "imu.rate_hz", 3, "expected a number, found a mapping");
}

TEST(Config, WrongTypeBool) {
  const auto r = load("lidar:\n  enabled: maybe\n");
  expect_single_error(r, "lidar.enabled", 2, "expected true or false");
}

TEST(Config, OutOfRangeDouble) {
  const auto r = load("imu:\n  rate_hz: 5000\n");
  expect_single_error(r, "imu.rate_hz", 2, "5000 is out of range [1, 2000] Hz");
}

TEST(Config, OutOfRangeInt) {
  const auto r = load("threads:\n  fusion:\n    priority: 99\n");
  expect_single_error(r, "threads.fusion.priority", 3, "99 is out of range [0, 50]");
}

TEST(Config, FractionalInt) {
  const auto r = load("dds:\n  domain_id: 1.5\n");
  expect_single_error(r, "dds.domain_id", 2, "expected a whole number");
}

TEST(Config, ChoiceNotAllowed) {
  const auto r = load("imu:\n  source: usb\n");
  expect_single_error(r, "imu.source", 2, "'usb' is not one of: synthetic,serial,can");
}

TEST(Config, InitialPoseTopicDefaultsToRvizsAndMayBeEmptied) {
  EXPECT_EQ(default_config().dds.initialpose_topic, "rt/initialpose");
  const auto off = load("dds:\n  initialpose_topic: \"\"\n");
  ASSERT_TRUE(off.ok()) << off.error_text();
  EXPECT_EQ(off.config.dds.initialpose_topic, "");
  const auto other = load("dds:\n  initialpose_topic: rt/robot_1/initialpose\n");
  ASSERT_TRUE(other.ok()) << other.error_text();
  EXPECT_EQ(other.config.dds.initialpose_topic, "rt/robot_1/initialpose");
}

TEST(Config, InitialPoseTopicMustBeADdsName) {
  expect_single_error(load("dds:\n  domain_id: 3\n  initialpose_topic: /initialpose\n"),
                      "dds.initialpose_topic", 3, "its DDS name is rt/initialpose");
  for (const char* bad : {"initialpose", "rt/", "rt/initial pose", "rt//initialpose",
                          "rt/initialpose/", "rt/1robot/initialpose"}) {
    expect_single_error(load(std::string("dds:\n  initialpose_topic: \"") + bad + "\"\n"),
                        "dds.initialpose_topic", 2, "is not a ROS 2 topic's DDS name");
  }
}

TEST(Config, MatrixWrongSize) {
  const auto r = load("extrinsics:\n  T_imu_lidar: [1, 0, 0]\n");
  expect_single_error(r, "extrinsics.T_imu_lidar", 2, "expected a list of 16 numbers");
}

TEST(Config, MatrixNotARotation) {
  const auto r =
      load("extrinsics:\n  T_imu_lidar: [1, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n");
  expect_single_error(r, "extrinsics.T_imu_lidar", 2, "not a rotation");
}

TEST(Config, MatrixReflectionRejected) {
  const auto r =
      load("extrinsics:\n  T_imu_cam: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1]\n");
  expect_single_error(r, "extrinsics.T_imu_cam", 2, "det = -1");
}

TEST(Config, MatrixBadLastRow) {
  const auto r =
      load("extrinsics:\n  T_imu_cam: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1]\n");
  expect_single_error(r, "extrinsics.T_imu_cam", 2, "last row");
}

TEST(Config, MatrixElementNotANumber) {
  // M2DGR's thermal matrix has a full-width comma; it must be caught, not misread.
  const auto r = load("imu:\n  R_imu_sensor: [1, 0, \"0，0\", 0, 1, 0, 0, 0, 1]\n");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.errors[0].key, "imu.R_imu_sensor");
}

TEST(Config, InvalidYamlNamesLine) {
  const auto r = load("imu:\n  rate_hz: [1, 2\n");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_NE(r.errors[0].reason.find("not valid YAML"), std::string::npos);
  EXPECT_GT(r.errors[0].line, 0);
}

TEST(Config, TopLevelMustBeAMapping) {
  const auto r = load("- a\n- b\n");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_NE(r.errors[0].reason.find("mapping"), std::string::npos);
}

TEST(Config, AllErrorsReportedAtOnce) {
  const auto r = load("imu:\n  rate_hz: 0\n  source: usb\nbogus: 1\n");
  EXPECT_EQ(r.errors.size(), 3u) << r.error_text();
}

TEST(Config, CrossFieldCheck) {
  const auto r = load("lidar:\n  min_range_m: 5\n  max_range_m: 4\n");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].key, "lidar.min_range_m");
}

TEST(Config, MissingFileSaysWhy) {
  const auto r = load_config_file("/nonexistent/posed.yaml");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_NE(r.errors[0].to_string().find("/nonexistent/posed.yaml: cannot open"),
            std::string::npos);
}

TEST(Config, ErrorTextFormat) {
  const auto r = load("imu:\n  rate_hz: 5000\n");
  EXPECT_EQ(r.errors.at(0).to_string(),
            "test.yaml:2:12: imu.rate_hz: 5000 is out of range [1, 2000] Hz");
}

TEST(Config, PrintedConfigLoadsBackIdentically) {
  auto r = load("imu:\n  source: synthetic\n  rate_hz: 123.25\ndds:\n  domain_id: 3\n");
  ASSERT_TRUE(r.ok());
  const std::string printed = print_config(r.config);
  EXPECT_NE(printed.find("rate_hz: 123.25  # [Hz] range [1, 2000]"), std::string::npos) << printed;
  const auto again = load(printed);
  ASSERT_TRUE(again.ok()) << again.error_text() << printed;
  EXPECT_EQ(print_config(again.config), printed);
}

TEST(Config, ShippedConfigsLoad) {
  const char* src = std::getenv("POSED_SOURCE_DIR");
  ASSERT_NE(src, nullptr) << "POSED_SOURCE_DIR is set by ctest";
  for (const char* name :
       {"/config/posed.yaml", "/config/demo.yaml", "/config/imu-can-example.yaml"}) {
    const auto r = load_config_file(std::string(src) + name);
    EXPECT_TRUE(r.ok()) << name << ":\n" << r.error_text();
  }
}

}  // namespace
}  // namespace posed::config

namespace posed::config {
namespace {

TEST(Config, RelativePathsResolveAgainstTheConfigFile) {
  const char* src = std::getenv("POSED_SOURCE_DIR");
  ASSERT_NE(src, nullptr);
  const auto r = load_config_file(std::string(src) + "/config/demo.yaml");
  ASSERT_TRUE(r.ok()) << r.error_text();
  EXPECT_EQ(r.config.dds.cyclonedds_config, std::string(src) + "/config/cyclonedds-loopback.xml");
  EXPECT_EQ(r.config.lidar.calibration, "");  // empty stays empty
}

}  // namespace
}  // namespace posed::config

// imu.can_mapping: a list of CAN fields, parsed at load and checked by the decoder's validate().
namespace posed::config {
namespace {

const std::string kCanImu =
    "imu:\n"                                                                         // 1
    "  source: can\n"                                                                // 2
    "  can_interface: vcan0\n"                                                       // 3
    "  can_mapping:\n"                                                               // 4
    "    complete_on_id: 0x182\n"                                                    // 5
    "    fields:\n"                                                                  // 6
    "      - {id: 0x180, field: counter, byte: 0, type: u32}\n"                      // 7
    "      - {id: 0x181, field: gyro_x, byte: 0, type: i16, scale: 0.001}\n"         // 8
    "      - {id: 0x181, field: gyro_y, byte: 2, type: i16, scale: 0.001}\n"         // 9
    "      - {id: 0x181, field: gyro_z, byte: 4, type: i16, scale: 0.001}\n"         // 10
    "      - {id: 0x182, field: accel_x, byte: 0, type: i16, byte_order: motorola,"  // 11
    " scale: 0.01, offset: -0.5}\n"
    "      - {id: 0x182, field: accel_y, byte: 2, type: i16, scale: 0.01}\n"   // 12
    "      - {id: 0x182, field: accel_z, byte: 4, type: i16, scale: 0.01}\n";  // 13

/// kCanImu with line `line` (1-based) replaced by `text`.
std::string with_line(int line, const std::string& text) {
  std::string out;
  std::size_t start = 0;
  for (int i = 1; start < kCanImu.size(); ++i) {
    const std::size_t end = kCanImu.find('\n', start);
    out += (i == line ? text : kCanImu.substr(start, end - start)) + "\n";
    start = end + 1;
  }
  return out;
}

TEST(ConfigCanImu, AMappingLoadsIntoTheDecodersStruct) {
  const auto r = load(kCanImu);
  ASSERT_TRUE(r.ok()) << r.error_text();
  const drivers::can::CanImuMapping& m = r.config.imu.can_mapping;
  EXPECT_EQ(r.config.imu.source, "can");
  EXPECT_EQ(r.config.imu.can_interface, "vcan0");
  ASSERT_EQ(m.fields.size(), 7u);
  EXPECT_EQ(m.complete_on_id, 0x182u);
  EXPECT_FALSE(m.complete_on_extended);
  EXPECT_EQ(m.fields[0].field, drivers::can::ImuField::kCounter);
  EXPECT_EQ(m.fields[0].type, drivers::can::FieldType::kU32);
  EXPECT_DOUBLE_EQ(m.fields[0].scale, 1.0);  // defaults: scale 1, offset 0, intel, standard ID
  EXPECT_FALSE(m.fields[0].big_endian);
  EXPECT_EQ(m.fields[2].field, drivers::can::ImuField::kGyroY);
  EXPECT_EQ(m.fields[2].can_id, 0x181u);
  EXPECT_EQ(m.fields[2].byte_offset, 2);
  EXPECT_DOUBLE_EQ(m.fields[2].scale, 0.001);
  EXPECT_TRUE(m.fields[4].big_endian);
  EXPECT_DOUBLE_EQ(m.fields[4].offset, -0.5);
  std::string why;
  EXPECT_TRUE(drivers::can::validate(m, why)) << why;
}

TEST(ConfigCanImu, ExtendedIdsAndTheCompletingWidthIsInferred) {
  std::string yaml = "imu:\n  can_mapping:\n    complete_on_id: 0x18FF0001\n    fields:\n";
  const char* axes[] = {"gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"};
  for (int i = 0; i < 6; ++i) {
    yaml += "      - {id: 0x18FF0001, extended: true, field: " + std::string(axes[i]) +
            ", byte: " + std::to_string(4 * i) + ", type: f32}\n";
  }
  const auto r = load(yaml);
  ASSERT_TRUE(r.ok()) << r.error_text();
  EXPECT_TRUE(r.config.imu.can_mapping.complete_on_extended);
  EXPECT_EQ(r.config.imu.can_mapping.fields[5].can_id, 0x18FF0001u);
  EXPECT_EQ(r.config.imu.source, "serial") << "a mapping alone does not change the source";
}

TEST(ConfigCanImu, PrintedMappingLoadsBackIdentically) {
  const auto r = load(kCanImu);
  ASSERT_TRUE(r.ok()) << r.error_text();
  const std::string printed = print_config(r.config);
  EXPECT_NE(printed.find("can_mapping: {complete_on_id: 0x182, complete_on_extended: false, "
                         "fields: [{id: 0x180, extended: false, field: counter, byte: 0, type: "
                         "u32, byte_order: intel, scale: 1, offset: 0}, "),
            std::string::npos)
      << printed;
  const auto again = load(printed);
  ASSERT_TRUE(again.ok()) << again.error_text() << printed;
  EXPECT_EQ(print_config(again.config), printed);
  EXPECT_NE(print_config(default_config()).find("can_mapping: {}  #"), std::string::npos);
}

TEST(ConfigCanImu, EachMistakeIsNamedWithItsLineAndKey) {
  // A bad value in a field entry: its own key, the entry's line.
  expect_single_error(load(with_line(9,
                                     "      - {id: 0x181, field: gyro_y, byte: 2, type: "
                                     "i17, scale: 0.001}")),
                      "imu.can_mapping.fields[2].type", 9, "'i17' is not one of: u8,i8,");
  expect_single_error(load(with_line(8, "      - {id: 0x181, field: gyro_q, byte: 0, type: i16}")),
                      "imu.can_mapping.fields[1].field", 8, "'gyro_q' is not one of");
  expect_single_error(load(with_line(8, "      - {id: 0x981, field: gyro_x, byte: 0, type: i16}")),
                      "imu.can_mapping.fields[1].id", 8, "out of range for an 11-bit ID");
  expect_single_error(load(with_line(8, "      - {id: 0x181, field: gyro_x, byte: 64, type: i16}")),
                      "imu.can_mapping.fields[1].byte", 8, "expected a byte offset 0..63");
  expect_single_error(
      load(with_line(8, "      - {id: 0x181, field: gyro_x, byte: 0, type: i16, sclae: 2}")),
      "imu.can_mapping.fields[1].sclae", 8, "unknown key");
  expect_single_error(load(with_line(8, "      - {id: 0x181, field: gyro_x, type: i16}")),
                      "imu.can_mapping.fields[1].byte", 8, "missing");
  expect_single_error(
      load(with_line(11,
                     "      - {id: 0x182, field: accel_x, byte: 0, type: i16, byte_order: "
                     "big}")),
      "imu.can_mapping.fields[4].byte_order", 11, "not one of: intel,motorola");
  // What validate() finds: the entry it names, or the mapping's own keys.
  expect_single_error(load(with_line(9, "      - {id: 0x181, field: gyro_x, byte: 2, type: i16}")),
                      "imu.can_mapping.fields[2]", 9, "gyro_x mapped twice");
  expect_single_error(load(with_line(8, "      - {id: 0x181, field: gyro_x, byte: 62, type: i32}")),
                      "imu.can_mapping.fields[1]", 8, "exceed 64");
  expect_single_error(load(with_line(5, "    complete_on_id: 0x183")),
                      "imu.can_mapping.complete_on_id", 5, "not one of the mapped IDs");
  expect_single_error(load(with_line(13, "")), "imu.can_mapping.fields", 7, "missing: accel_z");
  // imu.source can needs a mapping.
  expect_single_error(load("imu:\n  source: can\n"), "imu.can_mapping", 2,
                      "imu.source is can but no imu.can_mapping");
  expect_single_error(load("imu:\n  can_mapping: [1, 2]\n"), "imu.can_mapping", 2,
                      "expected a mapping");
  // A counter ClockSync would unwrap at the wrong place.
  const std::string u16_counter =
      with_line(7, "      - {id: 0x180, field: counter, byte: 0, type: u16, scale: 100}");
  expect_single_error(load(u16_counter), "imu.can_mapping.fields[0]", 7,
                      "needs a microsecond counter that wraps at 2^32");
  EXPECT_TRUE(load(u16_counter + "  clock_kind: none\n").ok());
}

}  // namespace
}  // namespace posed::config
