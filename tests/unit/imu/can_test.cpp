#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

#include "drivers/imu/can_frame.hpp"
#include "drivers/imu/can_imu_mapping.hpp"
#include "drivers/imu/candump_log.hpp"

namespace posed::drivers::can {
namespace {

CandumpRecord parse_ok(std::string_view line) {
  CandumpRecord r;
  std::string error;
  EXPECT_TRUE(parse_candump_line(line, r, error)) << line << ": " << error;
  return r;
}

TEST(Candump, StandardFrame) {
  const auto r = parse_ok("(1600000000.123456) can0 123#DEADBEEF");
  EXPECT_EQ(r.stamp_ns, 1'600'000'000'123'456'000LL);
  EXPECT_STREQ(r.interface.data(), "can0");
  EXPECT_EQ(r.frame.id, 0x123u);
  EXPECT_FALSE(r.frame.extended);
  EXPECT_FALSE(r.frame.fd);
  ASSERT_EQ(r.frame.len, 4);
  EXPECT_EQ(r.frame.data[0], 0xDE);
  EXPECT_EQ(r.frame.data[3], 0xEF);
}

TEST(Candump, ExtendedIdDotsEmptyAndDlcHint) {
  auto r = parse_ok("(1436509052.249713) vcan0 12345678#11.22.33.44");
  EXPECT_TRUE(r.frame.extended);
  EXPECT_EQ(r.frame.id, 0x12345678u);
  EXPECT_EQ(r.frame.len, 4);
  EXPECT_EQ(r.frame.data[1], 0x22);
  r = parse_ok("(1436509052.249713) can1 7FF#");
  EXPECT_EQ(r.frame.len, 0);
  r = parse_ok("(0.000001) can0 123#1122334455667788_E");
  EXPECT_EQ(r.frame.len, 8);
  EXPECT_EQ(r.frame.data[7], 0x88);
}

TEST(Candump, FdFrameWithFlags) {
  const auto r = parse_ok(
      "(1600000000.000100) can0 0CF00400##3000102030405060708090A0B0C0D0E0F101112131415161718191A"
      "1B1C1D1E1F");
  EXPECT_TRUE(r.frame.fd);
  EXPECT_TRUE(r.frame.extended);
  EXPECT_EQ(r.frame.fd_flags, 0x3);  // BRS | ESI
  EXPECT_EQ(r.frame.len, 32);
  EXPECT_EQ(r.frame.data[31], 0x1F);
}

TEST(Candump, RemoteAndErrorFrames) {
  auto r = parse_ok("(1600000000.000000) can0 123#R");
  EXPECT_TRUE(r.frame.remote);
  EXPECT_EQ(r.frame.len, 0);
  r = parse_ok("(1600000000.000000) can0 123#R4");
  EXPECT_TRUE(r.frame.remote);
  EXPECT_EQ(r.frame.len, 4);
  r = parse_ok("(1600000000.000000) can0 20000040#0000000000000000");
  EXPECT_TRUE(r.frame.error);
  EXPECT_FALSE(r.frame.extended);
  EXPECT_EQ(r.frame.id, 0x40u);  // CAN_ERR_BUSOFF
}

TEST(Candump, RejectsMalformedLinesWithColumn) {
  for (const char* bad : {
           "1600000000.1 can0 123#00",                      // no '('
           "(1600000000.1) can0 1234#00",                   // 4-digit ID
           "(1600000000.1) can0 800#00",                    // standard ID > 0x7FF
           "(1600000000.1) can0 123#0",                     // odd nibble
           "(1600000000.1) can0 123#001122334455667788",    // 9 bytes classic
           "(1600000000.1) can0 123##1001122334455667788",  // FD length 9
           "(1600000000.1) can0 123#R9",
           "(1600000000.1) can0 123",
           "(1600000000.1) can0 123##",
           "(abc) can0 123#00",
       }) {
    CandumpRecord r;
    std::string error;
    EXPECT_FALSE(parse_candump_line(bad, r, error)) << bad;
    EXPECT_NE(error.find("column"), std::string::npos) << bad << " -> " << error;
  }
}

// Fuzzing (can_fuzz) found seconds that overflow the int64 nanosecond stamp (UB): refused.
TEST(Candump, TimestampBeyondInt64NanosecondsIsRefused) {
  EXPECT_EQ(parse_ok("(9223372035.999999) can0 123#00").stamp_ns, 9'223'372'035'999'999'000LL);
  for (const char* bad : {"(9223372036.0) can0 123#00", "(170000010060.0) can0 123#00",
                          "(999999999999.999999) can0 123#00"}) {
    CandumpRecord r;
    std::string error;
    EXPECT_FALSE(parse_candump_line(bad, r, error)) << bad;
    EXPECT_NE(error.find("2^63"), std::string::npos) << bad << " -> " << error;
  }
}

// can_fuzz: an interface name with a NUL or control byte was accepted, and read back empty.
TEST(Candump, InterfaceNameMustBePrintable) {
  using namespace std::string_literals;
  for (const std::string& bad :
       {"(1.0) \0can0 123#R"s, "(1.0) ca\tn0 123#00"s, "(1.0) can\x7f 123#00"s}) {
    CandumpRecord r;
    std::string error;
    EXPECT_FALSE(parse_candump_line(bad, r, error)) << bad;
    EXPECT_NE(error.find("bad interface name"), std::string::npos) << error;
  }
}

TEST(CanFrame, KernelBytesRoundTrip) {
  for (const char* line : {"(1.0) can0 123#DEADBEEF", "(1.0) can0 12345678#01",
                           "(1.0) can0 123##1AABBCCDDEEFF0011223344.55", "(1.0) can0 123#R3",
                           "(1.0) can0 20000004#0004000000000000"}) {
    const CanFrame f = parse_ok(line).frame;
    std::array<std::uint8_t, kCanFdMtu> buf{};
    const std::size_t n = to_kernel_bytes(f, buf);
    ASSERT_EQ(n, f.fd ? kCanFdMtu : kCanMtu) << line;
    CanFrame back;
    ASSERT_TRUE(from_kernel_bytes(std::span(buf).first(n), back)) << line;
    EXPECT_EQ(back.id, f.id);
    EXPECT_EQ(back.extended, f.extended);
    EXPECT_EQ(back.remote, f.remote);
    EXPECT_EQ(back.error, f.error);
    EXPECT_EQ(back.fd, f.fd);
    EXPECT_EQ(back.fd_flags, f.fd_flags);
    EXPECT_EQ(back.len, f.len);
    EXPECT_EQ(back.data, f.data) << line;
  }
  std::array<std::uint8_t, 20> odd{};
  CanFrame f;
  EXPECT_FALSE(from_kernel_bytes(odd, f));
}

/// A hypothetical CAN IMU: 0x180 gyro xyz int16 LE [1e-3 rad/s] + counter u16 LE [100 µs];
/// 0x181 accel xyz int16 big-endian [1e-3 g], reporting minus specific force like the A9.
CanImuMapping example_mapping() {
  constexpr double g = 9.80665;
  CanImuMapping m;
  m.fields = {
      {0x180, false, ImuField::kGyroX, 0, FieldType::kI16, false, 1e-3, 0},
      {0x180, false, ImuField::kGyroY, 2, FieldType::kI16, false, 1e-3, 0},
      {0x180, false, ImuField::kGyroZ, 4, FieldType::kI16, false, 1e-3, 0},
      {0x180, false, ImuField::kCounter, 6, FieldType::kU16, false, 100, 0},
      {0x181, false, ImuField::kAccelX, 0, FieldType::kI16, true, -1e-3 * g, 0},
      {0x181, false, ImuField::kAccelY, 2, FieldType::kI16, true, -1e-3 * g, 0},
      {0x181, false, ImuField::kAccelZ, 4, FieldType::kI16, true, -1e-3 * g, 0},
  };
  m.complete_on_id = 0x181;
  return m;
}

TEST(CanImuMapping, DecodesACandumpLogThroughTheReplaySource) {
  const auto path = std::filesystem::temp_directory_path() / "posed_can_imu_test.log";
  {
    std::ofstream out(path);
    // gyro (0.1, -0.2, 0.003) rad/s, counter 7 → 700 µs; accel (0, 0, -1000 mg) big-endian.
    out << "(1600000000.000000) can0 180#E80330FF03000700\n"
        << "(1600000000.000100) can0 181#00000000FC18\n"
        << "(1600000000.000200) can0 7DF#0201050000000000\n"  // unrelated ID
        << "this is not a candump line\n"
        << "(1600000000.000300) can0 181#000000000000\n"  // completes without gyro
        << "(1600000000.000400) can0 180#E803\n";         // too short for gyro y/z
  }
  CandumpReplaySource source(path.string());
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  CanImuDecoder decoder(example_mapping());
  std::vector<CanImuStatus> statuses;
  CanImuReading reading, first;
  RawChunk chunk;
  while (source.read(chunk, Duration::from_ms(1)) == ReadStatus::kData) {
    CanFrame frame;
    ASSERT_TRUE(from_kernel_bytes(
        {reinterpret_cast<const std::uint8_t*>(chunk.bytes.data()), chunk.bytes.size()}, frame));
    const CanImuStatus s = decoder.decode(frame, reading);
    if (s == CanImuStatus::kSample) {
      first = reading;
      EXPECT_EQ(chunk.host_receive.ns, 1'600'000'000'000'100'000LL);
    }
    statuses.push_back(s);
  }
  std::filesystem::remove(path);
  EXPECT_EQ(statuses, (std::vector<CanImuStatus>{CanImuStatus::kPartial, CanImuStatus::kSample,
                                                 CanImuStatus::kIgnored, CanImuStatus::kIncomplete,
                                                 CanImuStatus::kTooShort}));
  EXPECT_EQ(source.counters().rejected, 1u);
  EXPECT_NEAR(first.gyro_radps.x(), 1.0, 1e-12);     // 0x03E8 = 1000
  EXPECT_NEAR(first.gyro_radps.y(), -0.208, 1e-12);  // 0xFF30 = -208
  EXPECT_NEAR(first.gyro_radps.z(), 0.003, 1e-12);
  EXPECT_TRUE(first.has_counter);
  EXPECT_EQ(first.counter_us, 700u);
  EXPECT_NEAR(first.specific_force_mps2.z(), 9.80665, 1e-9);  // 0xFC18 = -1000 mg → +1 g
  const ImuSample s = to_imu_sample(first, a9::A9Mounting{}, HostTime{}, DeviceTime{});
  EXPECT_NEAR(s.specific_force_mps2.z(), 9.80665, 1e-9);
  EXPECT_EQ(decoder.counters().samples, 1u);
  EXPECT_EQ(decoder.counters().incomplete, 1u);
  EXPECT_EQ(decoder.counters().too_short, 1u);
}

TEST(CanImuMapping, FloatFieldsInAnFdFrame) {
  CanImuMapping m;
  const ImuField axes[6] = {ImuField::kGyroX,  ImuField::kGyroY,  ImuField::kGyroZ,
                            ImuField::kAccelX, ImuField::kAccelY, ImuField::kAccelZ};
  for (int i = 0; i < 6; ++i) {
    m.fields.push_back({0x1ABCDE00, true, axes[i], static_cast<std::uint8_t>(4 * i),
                        FieldType::kF32, false, 1.0, 0.0});
  }
  m.complete_on_id = 0x1ABCDE00;
  m.complete_on_extended = true;
  std::string error;
  ASSERT_TRUE(validate(m, error)) << error;
  CanFrame f;
  f.id = 0x1ABCDE00;
  f.extended = true;
  f.fd = true;
  f.len = 24;
  const float values[6] = {0.5f, -0.25f, 2.0f, 0.1f, 0.2f, 9.81f};
  std::memcpy(f.data.data(), values, sizeof values);  // little-endian host
  CanImuDecoder d(m);
  CanImuReading r;
  ASSERT_EQ(d.decode(f, r), CanImuStatus::kSample);
  EXPECT_EQ(r.gyro_radps.y(), -0.25);
  EXPECT_NEAR(r.specific_force_mps2.z(), 9.81, 1e-6);
  f.extended = false;  // same number, other ID space
  EXPECT_EQ(d.decode(f, r), CanImuStatus::kIgnored);
}

// can_fuzz: an f32 counter holding NaN or inf, or a counter scaled past 2^64 us, was cast to
// u64 (UB). The counter is clamped to [0, 2^64 - 1]; NaN reads 0.
TEST(CanImuMapping, CounterOutOfRangeIsClampedNotCast) {
  CanImuMapping m;
  const ImuField axes[6] = {ImuField::kGyroX,  ImuField::kGyroY,  ImuField::kGyroZ,
                            ImuField::kAccelX, ImuField::kAccelY, ImuField::kAccelZ};
  for (int i = 0; i < 6; ++i) {
    m.fields.push_back({0x100, false, axes[i], 0, FieldType::kU8, false, 1.0, 0.0});
  }
  m.fields.push_back({0x100, false, ImuField::kCounter, 4, FieldType::kF32, false, 1e30, 0.0});
  m.complete_on_id = 0x100;
  CanImuDecoder d(m);
  CanFrame f;
  f.id = 0x100;
  f.len = 8;
  const float counters[] = {std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::infinity(), 1e30f, -5.0f, 2.0f};
  const std::uint64_t expected[] = {0, std::numeric_limits<std::uint64_t>::max(),
                                    std::numeric_limits<std::uint64_t>::max(), 0,
                                    std::numeric_limits<std::uint64_t>::max()};
  for (std::size_t i = 0; i < std::size(counters); ++i) {
    std::memcpy(f.data.data() + 4, &counters[i], 4);  // little-endian host
    CanImuReading r;
    ASSERT_EQ(d.decode(f, r), CanImuStatus::kSample);
    EXPECT_EQ(r.counter_us, expected[i]) << counters[i];
  }
}

TEST(CanImuMapping, ValidateSaysWhatIsWrong) {
  std::string error;
  CanImuMapping m = example_mapping();
  m.fields.pop_back();
  EXPECT_FALSE(validate(m, error));
  EXPECT_NE(error.find("accel"), std::string::npos) << error;
  m = example_mapping();
  m.fields[1].field = ImuField::kGyroX;
  EXPECT_FALSE(validate(m, error));
  EXPECT_NE(error.find("twice"), std::string::npos) << error;
  m = example_mapping();
  m.fields[0].byte_offset = 63;  // an int16 at 63..64
  EXPECT_FALSE(validate(m, error));
  EXPECT_NE(error.find("exceed 64"), std::string::npos) << error;
  m = example_mapping();
  m.complete_on_id = 0x999;
  EXPECT_FALSE(validate(m, error));
  // An invalid mapping decodes nothing rather than garbage.
  CanImuDecoder d(m);
  CanImuReading r;
  CanFrame f;
  f.id = 0x180;
  f.len = 8;
  EXPECT_EQ(d.decode(f, r), CanImuStatus::kIgnored);
}

TEST(CanImuMapping, NamesRoundTripAndValidateSaysWhichEntry) {
  for (int i = 0; i <= static_cast<int>(ImuField::kCounter); ++i) {
    const auto f = static_cast<ImuField>(i);
    EXPECT_EQ(imu_field_from_string(to_string(f)), f);
  }
  for (int i = 0; i <= static_cast<int>(FieldType::kF32); ++i) {
    const auto t = static_cast<FieldType>(i);
    EXPECT_EQ(field_type_from_string(to_string(t)), t);
  }
  EXPECT_EQ(imu_field_from_string("gyro_w"), std::nullopt);
  EXPECT_EQ(field_type_from_string("i64"), std::nullopt);
  EXPECT_EQ(field_size(FieldType::kF32), 4u);

  std::string error;
  std::size_t bad = 0;
  CanImuMapping m = example_mapping();
  EXPECT_TRUE(validate(m, error, bad)) << error;
  m.fields[2].field = ImuField::kGyroX;
  EXPECT_FALSE(validate(m, error, bad));
  EXPECT_EQ(bad, 2u);
  EXPECT_NE(error.find("gyro_x mapped twice"), std::string::npos) << error;
  m = example_mapping();
  m.complete_on_id = 0x999;
  EXPECT_FALSE(validate(m, error, bad));
  EXPECT_EQ(bad, std::string::npos) << "a problem of the mapping as a whole";
}

}  // namespace
}  // namespace posed::drivers::can
