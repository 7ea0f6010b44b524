// Simulated VLP-32C packets through the real decoder: the decoded points are the cast points
// (noise off: within the 4 mm distance LSB), the timing is the sensor's, the noise is as set,
// and position packets parse with a GPRMC that matches the packets' clock.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "drivers/velodyne/packet_decoder.hpp"
#include "drivers/velodyne/position_packet.hpp"
#include "tools/sim/bvh.hpp"
#include "tools/sim/lidar_model.hpp"
#include "tools/sim/scenarios.hpp"
#include "tools/sim/vlp32c_encoder.hpp"

namespace posed::sim {
namespace {

namespace vel = drivers::velodyne;

struct LidarFixture : ::testing::Test {
  void SetUp() override {
    std::string error;
    auto s = make_scenario("street_night", 4, 30.0, 9.805, error);
    ASSERT_TRUE(s) << error;
    scenario = std::move(*s);
    bvh = Bvh(scenario.world);
    config.T_base_lidar.translation() = Eigen::Vector3d(0.27255, -0.00053, 0.17954);
  }
  SensorScene scene() const { return {scenario.world, bvh, scenario.trajectory}; }
  Scenario scenario;
  Bvh bvh;
  LidarModelConfig config;
  ClockModel clock{{30'000'000'000'000, 20.0, 0, 0}, 0, 1};
};

TEST_F(LidarFixture, DecodesBackToTheCastPointsWithinTheDistanceLsb) {
  config.noise = false;
  config.azimuth0_deg = 123.4;
  LidarModel lidar(config, vel::builtin_calibration(vel::ProductId::kVlp32c), scene(), clock, 1);
  vel::PacketDecoder decoder;
  vel::DecodedPacket decoded;
  std::vector<std::byte> bytes(vel::kDataPacketBytes);
  LidarPacketTruth truth;
  double max_err = 0;
  std::uint64_t points = 0, expected = 0;
  // 8 s of driving: ~12000 packets, the vehicle moving and turning.
  while (lidar.next_data_send() < Duration::from_s(8)) {
    lidar.emit_data(bytes, &truth);
    ASSERT_EQ(decoder.decode(bytes, decoded), vel::DecodeStatus::kOk);
    ASSERT_EQ(decoded.product, vel::ProductId::kVlp32c);
    for (std::size_t b = 0; b < 12; ++b)
      for (std::size_t c = 0; c < 32; ++c) expected += truth.returned[b][c] ? 1 : 0;
    for (std::uint32_t i = 0; i < decoded.point_count; ++i) {
      const vel::DecodedPoint& p = decoded.points[i];
      ASSERT_TRUE(truth.returned[p.block][p.channel]);
      const Eigen::Vector3f got(p.x_m, p.y_m, p.z_m);
      max_err = std::max(max_err,
                         static_cast<double>((got - truth.p_lidar_m[p.block][p.channel]).norm()));
      ++points;
    }
  }
  EXPECT_EQ(points, expected);
  EXPECT_GT(points, 3'000'000u);  // most of the 4.6 M rays hit something in a street
  EXPECT_LT(max_err, 0.0025);     // half the 4 mm LSB plus float rounding
}

TEST_F(LidarFixture, TimingIsTheSensors) {
  LidarModel lidar(config, vel::builtin_calibration(vel::ProductId::kVlp32c), scene(), clock, 2);
  vel::PacketDecoder decoder;
  vel::DecodedPacket decoded;
  std::vector<std::byte> bytes(vel::kDataPacketBytes);
  LidarPacketTruth truth;
  int packets = 0;
  std::uint32_t first_us = 0, last_us = 0;
  float rpm_sum = 0;
  while (lidar.next_data_send() < Duration::from_s(3)) {
    lidar.emit_data(bytes, &truth);
    ASSERT_EQ(decoder.decode(bytes, decoded), vel::DecodeStatus::kOk);
    if (packets == 0) first_us = decoded.device_time_us;
    last_us = decoded.device_time_us;
    rpm_sum += decoded.rpm;
    // firings 55.296 µs apart on the device clock (true time runs 20 ppm slower)
    EXPECT_NEAR(static_cast<double>(truth.firing_true_ns[11] - truth.firing_true_ns[0]),
                11 * 55'296.0 / (1 + 20e-6), 2.0);
    ++packets;
  }
  // 1507.05 packets/s on the device clock, minus the first partial packet
  EXPECT_NEAR(packets, 3 * 1e9 / (12 * 55'296.0) * (1 + 20e-6), 2.0);
  EXPECT_NEAR(static_cast<double>(last_us - first_us), (packets - 1) * 663.552, 1.0);
  // The device clock starts at 30000 s = 8 h 20 min: 20 min past the hour.
  EXPECT_NEAR(first_us, 1'200'000'000.0, 1.0);
  EXPECT_NEAR(rpm_sum / static_cast<float>(packets), 600.0, 6.0);
}

TEST_F(LidarFixture, NoiseAndDropouts) {
  LidarModelConfig clean = config, noisy = config;
  clean.noise = false;
  noisy.noise = true;
  const auto cal = vel::builtin_calibration(vel::ProductId::kVlp32c);
  LidarModel a(clean, cal, scene(), clock, 3);
  LidarModel b(noisy, cal, scene(), clock, 3);
  std::vector<std::byte> pa(vel::kDataPacketBytes), pb(vel::kDataPacketBytes);
  double sum2 = 0;
  std::uint64_t n = 0, clean_returns = 0, noisy_returns = 0;
  for (int k = 0; k < 3000; ++k) {
    a.emit_data(pa);
    b.emit_data(pb);
    for (std::size_t blk = 0; blk < 12; ++blk)
      for (std::size_t c = 0; c < 32; ++c) {
        const std::size_t off = blk * 100 + 4 + c * 3;
        const auto ra = vel::read_u16_le(pa.data() + off), rb = vel::read_u16_le(pb.data() + off);
        clean_returns += ra != 0;
        noisy_returns += rb != 0;
        if (ra != 0 && rb != 0) {
          const double d = (rb - ra) * 0.004;
          sum2 += d * d;
          ++n;
        }
      }
  }
  EXPECT_NEAR(std::sqrt(sum2 / static_cast<double>(n)), 0.02, 0.002);
  EXPECT_LT(noisy_returns, clean_returns);           // dark asphalt far away drops out
  EXPECT_GT(noisy_returns, clean_returns * 6 / 10);  // but most returns survive
}

TEST_F(LidarFixture, PositionPacketsCarryTheSensorsTime) {
  LidarModel lidar(config, vel::builtin_calibration(vel::ProductId::kVlp32c), scene(), clock, 4);
  std::vector<std::byte> bytes(vel::kPositionPacketBytes);
  for (int k = 0; k < 3; ++k) {
    const Duration sent = lidar.next_position_send();
    lidar.emit_position(bytes);
    vel::PositionPacket p;
    ASSERT_EQ(vel::parse_position_packet(bytes, p), vel::PositionStatus::kOk);
    ASSERT_TRUE(p.gprmc && p.gprmc->valid);
    EXPECT_EQ(p.pps, vel::PpsStatus::kLocked);
    // The device clock at the send time, in µs past the hour, is the packet's stamp.
    const std::int64_t dev_us = clock.device_at(sent).ns / 1000;
    EXPECT_NEAR(static_cast<double>(p.device_time_us), static_cast<double>(dev_us % 3'600'000'000),
                1.0);
    EXPECT_EQ(p.gprmc->hour, 8u);
    EXPECT_EQ(p.gprmc->minute, 20u);
    EXPECT_EQ(p.gprmc->second, static_cast<std::uint32_t>(k + 1));
    EXPECT_EQ(p.gprmc->year, 2024u);
    auto top = vel::top_of_hour(*p.gprmc, p.device_time_us);
    ASSERT_TRUE(top);
  }
}

}  // namespace
}  // namespace posed::sim
