// Position packets: the real HDL-32E capture's GPRMC sentences, and the hour arithmetic.

#include "drivers/velodyne/position_packet.hpp"

#include <gtest/gtest.h>

#include <cstring>

#include "tests/common/realdata.hpp"
#include "tests/unit/velodyne/capture_fixture.hpp"

namespace posed::drivers::velodyne {
namespace {

std::vector<std::byte> make_position(std::uint32_t us, std::uint8_t pps, const char* nmea) {
  std::vector<std::byte> p(512, std::byte{0});
  for (std::size_t i = 0; i < 4; ++i) p[198 + i] = static_cast<std::byte>((us >> (8 * i)) & 0xFF);
  p[202] = static_cast<std::byte>(pps);
  std::memcpy(p.data() + 206, nmea, std::strlen(nmea));
  return p;
}

TEST(PositionPacket, RealHdl32ePackets) {
  POSED_REQUIRE_REALDATA(pcap, "velodyne_hdl32e/monterey-first-100-packets.pcap");
  std::size_t parsed = 0;
  for (const auto& d : test::load_datagrams(pcap)) {
    if (d.dst_port != 8308) continue;
    PositionPacket pos;
    ASSERT_EQ(parse_position_packet(d.payload, pos), PositionStatus::kOk);
    ASSERT_TRUE(pos.gprmc.has_value());
    EXPECT_TRUE(pos.gprmc->valid);
    EXPECT_EQ(pos.gprmc->year, 2012u);
    EXPECT_EQ(pos.gprmc->month, 12u);
    EXPECT_EQ(pos.gprmc->day, 11u);
    EXPECT_NEAR(pos.gprmc->latitude_deg, 37.0 + 7.8324 / 60.0, 1e-3);
    EXPECT_NEAR(pos.gprmc->longitude_deg, -(121.0 + 39.2864 / 60.0), 1e-3);
    EXPECT_EQ(pos.pps, PpsStatus::kAbsent);  // the HDL-32E leaves byte 202 at zero
    // The device stamp, placed in UTC by the fix, agrees with the recorder's clock to ~2 s.
    const auto hour = top_of_hour(*pos.gprmc, pos.device_time_us);
    ASSERT_TRUE(hour.has_value());
    const WallTime t = absolute_time(*hour, pos.device_time_us);
    EXPECT_NEAR(static_cast<double>(t.ns - d.timestamp_ns) * 1e-9, 0.0, 2.0);
    ++parsed;
  }
  EXPECT_EQ(parsed, 299u);
}

TEST(PositionPacket, FirstRealSentenceExactly) {
  // From the capture: stamp 0x176FEA0D = 393210381 µs past 22:00 on 2012-12-11.
  const auto p = make_position(393'210'381, 2,
                               "$GPRMC,220632,A,3707.8324,N,12139.2864,W,000.0,144.7,111212,013.8,"
                               "E,D*09\r\n");
  PositionPacket pos;
  ASSERT_EQ(parse_position_packet(p, pos), PositionStatus::kOk);
  EXPECT_EQ(pos.pps, PpsStatus::kLocked);
  EXPECT_EQ(pos.gprmc->hour, 22u);
  EXPECT_EQ(pos.gprmc->minute, 6u);
  EXPECT_EQ(pos.gprmc->second, 32u);
  const auto hour = top_of_hour(*pos.gprmc, pos.device_time_us);
  ASSERT_TRUE(hour);
  EXPECT_EQ(hour->ns, 1355263200LL * 1'000'000'000);  // 2012-12-11T22:00:00Z
  EXPECT_EQ(absolute_time(*hour, 393'210'381).ns, 1355263593'210'381'000LL);
}

TEST(PositionPacket, HourBoundaryAndBadInput) {
  GprmcFix fix;
  ASSERT_TRUE(parse_gprmc("$GPRMC,225959.50,A,,,,,,,311299,,*", fix) == false);  // bad checksum
  ASSERT_TRUE(parse_gprmc("$GPRMC,235959.50,A,,,,,,,311299,,", fix));
  EXPECT_EQ(fix.microsecond, 500'000u);
  EXPECT_EQ(fix.year, 1999u);
  // Fix at 23:59:59 but the counter has wrapped: the stamp belongs to the next hour (next day).
  const auto next = top_of_hour(fix, 200'000);
  ASSERT_TRUE(next);
  EXPECT_EQ(next->ns, 946684800LL * 1'000'000'000);  // 2000-01-01T00:00:00Z
  const auto same = top_of_hour(fix, 3'599'000'000);
  ASSERT_TRUE(same);
  EXPECT_EQ(same->ns, (946684800LL - 3600) * 1'000'000'000);
  fix.valid = false;
  EXPECT_FALSE(top_of_hour(fix, 0));

  PositionPacket pos;
  EXPECT_EQ(parse_position_packet(std::vector<std::byte>(511), pos), PositionStatus::kWrongSize);
  EXPECT_EQ(parse_position_packet(make_position(3'600'000'000u, 0, ""), pos),
            PositionStatus::kBadTimestamp);
  EXPECT_EQ(parse_position_packet(make_position(5, 1, ""), pos), PositionStatus::kNoNmea);
  EXPECT_EQ(pos.pps, PpsStatus::kSynchronizing);
  EXPECT_EQ(parse_position_packet(make_position(5, 0, "$GPGGA,1,2,3"), pos),
            PositionStatus::kNoNmea);
  EXPECT_EQ(parse_position_packet(make_position(5, 0, "$GPRMC,99,A,*00"), pos),
            PositionStatus::kBadNmea);
  // 128 bytes of NMEA with no terminator must not read past the field.
  std::string long_nmea = "$GPRMC," + std::string(200, '9');
  auto p = make_position(5, 0, "");
  std::memcpy(p.data() + 206, long_nmea.data(), 512 - 206);
  EXPECT_EQ(parse_position_packet(p, pos), PositionStatus::kBadNmea);
}

}  // namespace
}  // namespace posed::drivers::velodyne
