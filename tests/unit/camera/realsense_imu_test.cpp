// The D435i IMU through Linux IIO HID: scan element types and record layout, the pure decoder
// (librealsense's scaling and axes), and the Source against a fake sysfs tree in a temp dir
// with FIFOs standing in for /dev/iio:deviceN, carrying records in the kernel's layout.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <vector>

#include "drivers/camera/iio_scan.hpp"
#include "drivers/camera/realsense_imu_decoder.hpp"
#include "drivers/camera/realsense_imu_source.hpp"
#include "drivers/common/wire_format.hpp"

namespace posed::drivers::camera {
namespace {

namespace fs = std::filesystem;

TEST(IioScanType, ParsesSysfsTypeStrings) {
  IioScanType t;
  ASSERT_TRUE(parse_iio_scan_type("le:s16/32>>0\n", t));
  EXPECT_FALSE(t.big_endian);
  EXPECT_TRUE(t.is_signed);
  EXPECT_EQ(t.realbits, 16u);
  EXPECT_EQ(t.storagebits, 32u);
  EXPECT_EQ(t.shift, 0u);
  ASSERT_TRUE(parse_iio_scan_type("be:u12/16>>4", t));
  EXPECT_TRUE(t.big_endian);
  EXPECT_FALSE(t.is_signed);
  EXPECT_EQ(t.shift, 4u);
  ASSERT_TRUE(parse_iio_scan_type("le:s16/16X3>>0", t));
  EXPECT_EQ(t.repeat, 3u);
  EXPECT_EQ(to_string(t), "le:s16/16X3>>0");
  for (const char* bad : {"", "xe:s16/32>>0", "le:q16/32>>0", "le:s16/24>>0", "le:s40/32>>0",
                          "le:s16/16>>4", "le:s16/32", "le:s16/32>>0 junk", "le:s/32>>0"}) {
    EXPECT_FALSE(parse_iio_scan_type(bad, t)) << bad;
  }
}

std::vector<IioScanElement> d435i_accel_elements(const char* axis_type) {
  std::vector<IioScanElement> e(4);
  const char* names[4] = {"in_timestamp", "in_accel_z", "in_accel_x", "in_accel_y"};
  const std::uint32_t index[4] = {3, 2, 0, 1};
  for (int i = 0; i < 4; ++i) {
    e[i].name = names[i];
    e[i].index = index[i];
    EXPECT_TRUE(parse_iio_scan_type(i == 0 ? "le:s64/64>>0" : axis_type, e[i].type));
  }
  return e;
}

TEST(IioScanLayout, KernelLayoutOfTheD435iRecord) {
  IioScanLayout layout;
  std::string error;
  ASSERT_TRUE(layout_iio_scan(d435i_accel_elements("le:s16/32>>0"), layout, error)) << error;
  // x, y, z at 0, 4, 8; the 64-bit timestamp aligned to 16; 24 bytes (librealsense reads the
  // timestamp at p_raw_data[16]).
  ASSERT_EQ(layout.elements.size(), 4u);
  EXPECT_EQ(layout.elements[0].name, "in_accel_x");
  EXPECT_EQ(layout.find("in_accel_y")->offset, 4u);
  EXPECT_EQ(layout.find("in_accel_z")->offset, 8u);
  EXPECT_EQ(layout.find("in_timestamp")->offset, 16u);
  EXPECT_EQ(layout.record_bytes, 24u);

  const std::string wire = describe_iio_layout(wire::kIioAccel3d, layout);
  EXPECT_EQ(wire,
            "iio-hid-accel-3d;in_accel_x:le:s16/32>>0;in_accel_y:le:s16/32>>0;"
            "in_accel_z:le:s16/32>>0;in_timestamp:le:s64/64>>0");
  IioScanLayout back;
  ASSERT_TRUE(parse_iio_layout(wire, wire::kIioAccel3d, back, error)) << error;
  EXPECT_EQ(back.record_bytes, 24u);
  EXPECT_EQ(back.find("in_timestamp")->offset, 16u);
  EXPECT_FALSE(parse_iio_layout(wire, wire::kIioGyro3d, back, error));
  EXPECT_FALSE(
      parse_iio_layout("iio-hid-accel-3d;in_accel_x:le:s16/31>>0", wire::kIioAccel3d, back, error));
  EXPECT_NE(error.find("in_accel_x:le:s16/31>>0"), std::string::npos) << error;

  auto dup = d435i_accel_elements("le:s16/32>>0");
  dup[1].index = 0;
  EXPECT_FALSE(layout_iio_scan(dup, layout, error));
  EXPECT_NE(error.find("share index 0"), std::string::npos) << error;
  EXPECT_FALSE(layout_iio_scan({}, layout, error));
}

TEST(IioScanLayout, ElementValuesAreMaskedShiftedAndSignExtended) {
  IioScanElement e;
  ASSERT_TRUE(parse_iio_scan_type("le:s16/32>>0", e.type));
  // 0xFFFE in the low half (-2), the next HID field's bytes in the high half.
  const std::byte rec[4] = {std::byte{0xFE}, std::byte{0xFF}, std::byte{0x34}, std::byte{0x12}};
  EXPECT_EQ(iio_element_value(rec, e), -2);
  ASSERT_TRUE(parse_iio_scan_type("le:s32/32>>0", e.type));
  EXPECT_EQ(iio_element_value(rec, e), 0x1234FFFE);
  ASSERT_TRUE(parse_iio_scan_type("be:u12/16>>4", e.type));
  const std::byte be[2] = {std::byte{0xAB}, std::byte{0xC0}};
  EXPECT_EQ(iio_element_value(be, e), 0xABC);
}

/// One record in the D435i layout: x, y, z as 32-bit storage (low 16 significant, high 16
/// garbage), timestamp u64 at 16.
void put_record(std::vector<std::byte>& out, std::int16_t x, std::int16_t y, std::int16_t z,
                std::uint64_t stamp_ns) {
  auto put = [&](std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) out.push_back(static_cast<std::byte>((v >> (8 * i)) & 0xFF));
  };
  for (std::int16_t v : {x, y, z}) {
    put(static_cast<std::uint16_t>(v), 2);
    put(0xA5A5, 2);  // the kernel copies a u32 from the HID report: neighbouring bytes
  }
  put(0, 4);  // padding to the timestamp's alignment
  put(stamp_ns, 8);
}

const char* kAccelWire =
    "iio-hid-accel-3d;in_accel_x:le:s16/32>>0;in_accel_y:le:s16/32>>0;in_accel_z:le:s16/32>>0;"
    "in_timestamp:le:s64/64>>0";
const char* kGyroWire =
    "iio-hid-gyro-3d;in_anglvel_x:le:s16/32>>0;in_anglvel_y:le:s16/32>>0;"
    "in_anglvel_z:le:s16/32>>0;in_timestamp:le:s64/64>>0";

TEST(RealsenseImuDecoder, AccelInMetresPerSecondSquaredInTheDepthFrame) {
  RealsenseImuDecoder d(kAccelWire);
  ASSERT_TRUE(d.valid()) << d.error();
  EXPECT_EQ(d.kind(), MotionKind::kAccel);
  EXPECT_EQ(d.record_bytes(), 24u);
  std::vector<std::byte> bytes;
  // Camera upright at rest: the BMI055 reads +1 g on its y (1000 mg), a little x and z.
  put_record(bytes, 20, 1000, -50, 1'000'000'000);
  put_record(bytes, -1, -32768, 32767, 1'005'000'000);
  bytes.resize(bytes.size() + 10);  // a partial third record
  std::vector<D4xxMotionSample> out(4);
  ASSERT_EQ(d.decode(bytes, out), 2u);
  const double g = 9.80665;
  EXPECT_EQ(out[0].device_stamp.ns, 1'000'000'000);
  EXPECT_NEAR(out[0].xyz_depth.x(), -0.020 * g, 1e-12);  // x flipped into the depth frame
  EXPECT_NEAR(out[0].xyz_depth.y(), 1.000 * g, 1e-12);
  EXPECT_NEAR(out[0].xyz_depth.z(), 0.050 * g, 1e-12);  // z flipped
  EXPECT_NEAR(out[1].xyz_depth.y(), -32.768 * g, 1e-9);
  EXPECT_NEAR(out[1].xyz_depth.z(), -32.767 * g, 1e-9);
  EXPECT_EQ(out[1].device_stamp.ns, 1'005'000'000);
  EXPECT_EQ(d.counters().samples, 2u);
  EXPECT_EQ(d.counters().partial_bytes, 10u);
  // Fewer output slots than records: only what fits.
  EXPECT_EQ(d.decode(bytes, std::span(out).first(1)), 1u);
}

TEST(RealsenseImuDecoder, GyroInRadiansPerSecondWithEitherSensitivity) {
  std::vector<std::byte> bytes;
  put_record(bytes, 100, -200, 300, 42);
  std::vector<D4xxMotionSample> out(1);
  RealsenseImuDecoder d(kGyroWire);
  ASSERT_TRUE(d.valid()) << d.error();
  ASSERT_EQ(d.decode(bytes, out), 1u);
  const double lsb = 0.1 * std::numbers::pi / 180.0;
  EXPECT_EQ(out[0].kind, MotionKind::kGyro);
  EXPECT_NEAR(out[0].xyz_depth.x(), -100 * lsb, 1e-12);
  EXPECT_NEAR(out[0].xyz_depth.y(), -200 * lsb, 1e-12);
  EXPECT_NEAR(out[0].xyz_depth.z(), -300 * lsb, 1e-12);
  RealsenseImuConfig high;
  high.gyro_deg_per_lsb = 0.003814697265625;
  high.align_to_depth_frame = false;
  RealsenseImuDecoder raw(kGyroWire, high);
  ASSERT_EQ(raw.decode(bytes, out), 1u);
  EXPECT_NEAR(out[0].xyz_depth.x(), 100 * 0.003814697265625 * std::numbers::pi / 180.0, 1e-12);
}

TEST(RealsenseImuDecoder, UnusableWireFormatsAreRefusedAndCounted) {
  std::vector<D4xxMotionSample> out(1);
  const std::vector<std::byte> bytes(24);
  for (const char* bad : {"yuyv", "iio-hid-accel-3d;in_accel_x:le:s16/32>>0",
                          "iio-hid-gyro-3d;in_anglvel_x:le:s16/32>>0;in_anglvel_y:bogus"}) {
    RealsenseImuDecoder d(bad);
    EXPECT_FALSE(d.valid()) << bad;
    EXPECT_FALSE(d.error().empty());
    EXPECT_EQ(d.decode(bytes, out), 0u);
    EXPECT_EQ(d.counters().bad_chunks, 1u);
  }
}

// Found while fuzzing (realsense_fuzz): a shift of 2^32 - 1 wrapped realbits + shift past the
// storage check (then a 2^32-bit shift, UB), and repeats whose sizes wrapped the 32-bit record
// size to 0 (then decode() divided by zero). Both are refused with a reason.
TEST(RealsenseImuDecoder, WrappingShiftsAndRepeatsAreRefused) {
  IioScanType t;
  EXPECT_FALSE(parse_iio_scan_type("le:s1/8>>4294967295", t));
  EXPECT_FALSE(parse_iio_scan_type("le:s16/32X256>>0", t));
  EXPECT_TRUE(parse_iio_scan_type("le:s16/32X255>>16", t));
  std::vector<D4xxMotionSample> out(4);
  const std::vector<std::byte> bytes(64);
  for (const char* bad :
       {"iio-hid-accel-3d;in_accel_x:le:s1/8>>4294967295;in_accel_y:le:s16/32>>0;"
        "in_accel_z:le:s16/32>>0",
        "iio-hid-accel-3d;in_accel_x:le:s16/32X1073741824>>0;in_accel_y:le:s16/32X1073741824>>0;"
        "in_accel_z:le:s16/32X1073741824>>0;in_accel_w:le:s16/32X1073741824>>0"}) {
    RealsenseImuDecoder d(bad);
    EXPECT_FALSE(d.valid()) << bad;
    EXPECT_FALSE(d.error().empty());
    EXPECT_EQ(d.decode(bytes, out), 0u);
  }
  // Elements built in code are checked too: 64-bit sums, a cap on the record size.
  std::vector<IioScanElement> e(2);
  for (std::uint32_t i = 0; i < 2; ++i) {
    e[i].name = "in_big" + std::to_string(i);
    e[i].index = i;
    ASSERT_TRUE(parse_iio_scan_type("le:u64/64X255>>0", e[i].type));
  }
  IioScanLayout layout;
  std::string error;
  ASSERT_TRUE(layout_iio_scan(e, layout, error)) << error;
  EXPECT_EQ(layout.record_bytes, 2u * 8u * 255u);
  e[1].type.repeat = 0x20000000;  // 8 B x 2^29 = 2^32 B: wrapped to 0 before
  EXPECT_FALSE(layout_iio_scan(e, layout, error));
  EXPECT_NE(error.find("bytes per record"), std::string::npos) << error;
}

/// A fake /sys/bus/iio/devices tree and /dev with FIFOs, in a temp dir.
class FakeIio : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("posed-iio-" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_ / "sys");
    fs::create_directories(root_ / "dev");
    make_device("iio:device0", "als", "in_illuminance", false);  // another HID sensor
    make_device("iio:device1", "accel_3d", "in_accel", true);
    make_device("iio:device2", "gyro_3d", "in_anglvel", true);
  }
  void TearDown() override {
    for (int fd : writers_) ::close(fd);
    fs::remove_all(root_);
  }
  void write_file(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }
  std::string read_file(const fs::path& p) {
    std::ifstream in(p);
    std::string s;
    std::getline(in, s);
    return s;
  }
  void make_device(const std::string& dir, const std::string& name, const std::string& stem,
                   bool with_rate) {
    const fs::path d = root_ / "sys" / dir;
    fs::create_directories(d / "scan_elements");
    fs::create_directories(d / "buffer");
    write_file(d / "name", name + "\n");
    write_file(d / "buffer" / "enable", "0\n");
    write_file(d / "buffer" / "length", "2\n");
    if (with_rate) write_file(d / (stem + "_sampling_frequency"), "0\n");
    // Listed out of order on purpose: the layout follows _index, not the directory.
    const std::pair<std::string, std::string> els[] = {{"in_timestamp", "le:s64/64>>0"},
                                                       {stem + "_z", "le:s16/32>>0"},
                                                       {stem + "_x", "le:s16/32>>0"},
                                                       {stem + "_y", "le:s16/32>>0"}};
    const int index[] = {3, 2, 0, 1};
    for (int i = 0; i < 4; ++i) {
      write_file(d / "scan_elements" / (els[i].first + "_en"), "0\n");
      write_file(d / "scan_elements" / (els[i].first + "_type"), els[i].second + "\n");
      write_file(d / "scan_elements" / (els[i].first + "_index"), std::to_string(index[i]) + "\n");
    }
    ASSERT_EQ(::mkfifo((root_ / "dev" / dir).c_str(), 0600), 0);
  }
  /// Holds the FIFO open for writing (O_RDWR never blocks) and returns the descriptor.
  int writer(const std::string& dir) {
    const int fd = ::open((root_ / "dev" / dir).c_str(), O_RDWR | O_NONBLOCK);
    writers_.push_back(fd);
    return fd;
  }
  RealsenseImuSourceConfig config() {
    RealsenseImuSourceConfig c;
    for (auto* d : {&c.accel, &c.gyro}) {
      d->sysfs_root = (root_ / "sys").string();
      d->dev_dir = (root_ / "dev").string();
    }
    c.reopen_interval_ms = 1;
    return c;
  }
  fs::path root_;
  std::vector<int> writers_;
};

TEST_F(FakeIio, SourceConfiguresSysfsLikeLibrealsenseAndReadsWholeRecords) {
  RealsenseImuSource source("d435i_imu", config());
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  const fs::path accel = root_ / "sys" / "iio:device1";
  EXPECT_EQ(read_file(accel / "buffer" / "enable"), "1");
  EXPECT_EQ(read_file(accel / "buffer" / "length"), "128");
  EXPECT_EQ(read_file(accel / "in_accel_sampling_frequency"), "250");
  EXPECT_EQ(read_file(root_ / "sys" / "iio:device2" / "in_anglvel_sampling_frequency"), "200");
  EXPECT_EQ(read_file(accel / "scan_elements" / "in_accel_x_en"), "1");
  EXPECT_EQ(read_file(accel / "scan_elements" / "in_timestamp_en"), "1");
  EXPECT_EQ(read_file(root_ / "sys" / "iio:device0" / "buffer" / "enable"), "0");  // untouched
  EXPECT_EQ(source.device(0).dev_node, (root_ / "dev" / "iio:device1").string());
  EXPECT_EQ(source.wire_format(0), kAccelWire);
  EXPECT_EQ(source.wire_format(1), kGyroWire);

  const int accel_w = writer("iio:device1");
  const int gyro_w = writer("iio:device2");
  std::vector<std::byte> a, g;
  put_record(a, 0, 1000, 0, 5'000);
  put_record(a, 1, 1001, 2, 9'000);
  put_record(g, 10, 20, 30, 6'000);
  // The gyro record arrives in two pieces: no chunk may carry half a record.
  ASSERT_EQ(::write(accel_w, a.data(), a.size()), static_cast<ssize_t>(a.size()));
  ASSERT_EQ(::write(gyro_w, g.data(), 10), 10);

  RealsenseImuDecoder accel_dec(source.wire_format(0));
  RealsenseImuDecoder gyro_dec(source.wire_format(1));
  std::vector<D4xxMotionSample> samples(8);
  RawChunk chunk;
  ASSERT_EQ(source.read(chunk, Duration::from_ms(200)), ReadStatus::kData);
  EXPECT_EQ(chunk.channel, 0u);
  EXPECT_EQ(chunk.bytes.size(), 48u);
  ASSERT_EQ(accel_dec.decode(chunk.bytes, samples), 2u);
  EXPECT_EQ(samples[1].device_stamp.ns, 9'000);
  EXPECT_NEAR(samples[1].xyz_depth.y(), 1.001 * 9.80665, 1e-12);

  EXPECT_EQ(source.read(chunk, Duration::from_ms(20)), ReadStatus::kTimeout);  // 10 B only
  ASSERT_EQ(::write(gyro_w, g.data() + 10, g.size() - 10), static_cast<ssize_t>(g.size() - 10));
  ASSERT_EQ(source.read(chunk, Duration::from_ms(200)), ReadStatus::kData);
  EXPECT_EQ(chunk.channel, 1u);
  ASSERT_EQ(chunk.bytes.size(), 24u);
  ASSERT_EQ(gyro_dec.decode(chunk.bytes, samples), 1u);
  EXPECT_EQ(samples[0].device_stamp.ns, 6'000);
  EXPECT_EQ(source.imu_counters().accel_records, 2u);
  EXPECT_EQ(source.imu_counters().gyro_records, 1u);
  EXPECT_EQ(source.counters().bytes, 72u);

  source.request_stop();
  EXPECT_EQ(source.read(chunk, Duration::from_ms(1)), ReadStatus::kEndOfStream);
  EXPECT_EQ(read_file(accel / "buffer" / "enable"), "0");
}

TEST_F(FakeIio, MissingDeviceOrBadScanTypeFailsWithThePath) {
  auto cfg = config();
  cfg.gyro.name = "gyro_3d_missing";
  RealsenseImuSource none("imu", cfg);
  std::string error;
  EXPECT_FALSE(none.open(error));
  EXPECT_NE(error.find("no IIO device named 'gyro_3d_missing'"), std::string::npos) << error;
  EXPECT_EQ(read_file(root_ / "sys" / "iio:device1" / "buffer" / "enable"), "0");  // undone

  write_file(root_ / "sys" / "iio:device2" / "scan_elements" / "in_anglvel_y_type", "le:s16\n");
  RealsenseImuSource bad("imu", config());
  EXPECT_FALSE(bad.open(error));
  EXPECT_NE(error.find("in_anglvel_y_type: cannot parse scan type 'le:s16'"), std::string::npos)
      << error;

  auto pinned = config();
  pinned.accel.device_dir = "iio:device0";  // the ambient light sensor
  RealsenseImuSource wrong("imu", pinned);
  EXPECT_FALSE(wrong.open(error));
  EXPECT_NE(error.find("is 'als', not 'accel_3d'"), std::string::npos) << error;
}

TEST_F(FakeIio, DevicesThatAppearAfterStartAreOpenedByARead) {
  // The camera is plugged in after posed started (or a HIL replay makes its devices later):
  // the failed open at start is retried on every read.
  const fs::path name = root_ / "sys" / "iio:device2" / "name";
  write_file(name, "not_yet\n");
  RealsenseImuSource source("imu", config());
  std::string error;
  EXPECT_FALSE(source.open(error));
  RawChunk chunk;
  EXPECT_EQ(source.read(chunk, Duration::from_ms(5)), ReadStatus::kDeviceLost);
  write_file(name, "gyro_3d\n");
  const ReadStatus s = source.read(chunk, Duration::from_ms(50));
  EXPECT_TRUE(s == ReadStatus::kTimeout || s == ReadStatus::kData);
  EXPECT_EQ(source.counters().reopened, 1u);
  EXPECT_EQ(source.device(1).dev_node, (root_ / "dev" / "iio:device2").string());
}

TEST_F(FakeIio, HangUpIsDeviceLostAndTheDevicesAreReopened) {
  RealsenseImuSource source("imu", config());
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  // A writer that opened and closed: the FIFO reports POLLHUP, as a vanished device does.
  ::close(::open((root_ / "dev" / "iio:device1").c_str(), O_WRONLY | O_NONBLOCK));
  RawChunk chunk;
  EXPECT_EQ(source.read(chunk, Duration::from_ms(100)), ReadStatus::kDeviceLost);
  EXPECT_EQ(source.imu_counters().lost, 1u);
  // Reopened on the next read; data flows again.
  const int w = writer("iio:device1");
  std::vector<std::byte> a;
  put_record(a, 1, 2, 3, 77);
  ReadStatus s = source.read(chunk, Duration::from_ms(50));
  EXPECT_TRUE(s == ReadStatus::kTimeout || s == ReadStatus::kData);
  EXPECT_EQ(source.counters().reopened, 1u);
  ASSERT_EQ(::write(w, a.data(), a.size()), 24);
  ASSERT_EQ(source.read(chunk, Duration::from_ms(200)), ReadStatus::kData);
  EXPECT_EQ(chunk.bytes.size(), 24u);
}

}  // namespace
}  // namespace posed::drivers::camera
