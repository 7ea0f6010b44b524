// Golden tests of the packet decoder on real captures: the VLP-32C capture (model/mode, counts,
// geometry against the calibration, timing, a flat ground) and the HDL-32E capture against
// VeloView's expected per-frame point counts and point coordinates.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <sstream>

#include "drivers/velodyne/calibration_loader.hpp"
#include "drivers/velodyne/packet_decoder.hpp"
#include "tests/common/realdata.hpp"
#include "tests/unit/velodyne/capture_fixture.hpp"

namespace posed::drivers::velodyne {
namespace {

constexpr double kPi = std::numbers::pi;

std::uint16_t raw_distance(const std::vector<std::byte>& p, std::size_t block, std::size_t ch) {
  return read_u16_le(p.data() + block * 100 + 4 + ch * 3);
}

struct Vlp32cCapture : ::testing::Test {
  void SetUp() override {
    pcap = test::realdata_path("velodyne_vlp32c/vlp32c_nebula_5scans.pcap");
    calib = test::realdata_path("velodyne_vlp32c/calibration_VLP32.yaml");
    if (pcap.empty() || calib.empty()) GTEST_SKIP() << "velodyne_vlp32c real data not found";
    std::string error;
    ASSERT_TRUE(load_calibration(calib, calibration, error)) << error;
    for (auto& d : test::load_datagrams(pcap)) packets.push_back(std::move(d.payload));
    ASSERT_EQ(packets.size(), 379u);
  }
  std::string pcap, calib;
  Calibration calibration;
  std::vector<std::vector<std::byte>> packets;
};

TEST_F(Vlp32cCapture, ModelModeAndCounts) {
  PacketDecoder decoder(calibration);
  auto out = std::make_unique<DecodedPacket>();
  std::uint64_t points = 0, zeros = 0;
  for (const auto& p : packets) {
    ASSERT_EQ(decoder.decode(p, *out), DecodeStatus::kOk);
    EXPECT_EQ(out->product, ProductId::kVlp32c);
    EXPECT_EQ(out->return_mode, ReturnMode::kStrongest);
    EXPECT_EQ(out->firing_count, 12u);
    EXPECT_EQ(out->firing_period_ns, 55'296);
    EXPECT_EQ(out->point_count + out->no_return_count + out->out_of_range_count, 384u);
    points += out->point_count;
    zeros += out->no_return_count;
    // The sensor spins at ~600 rpm (10 Hz): 0.2° per 55.296 µs firing.
    EXPECT_NEAR(out->rpm, 600.0, 15.0);
  }
  EXPECT_EQ(decoder.product(), ProductId::kVlp32c);
  EXPECT_EQ(decoder.counters().packets_ok, 379u);
  EXPECT_EQ(decoder.counters().malformed(), 0u);
  // Every channel is either a point or a "no return" (raw 0); none is out of range by default.
  EXPECT_EQ(points + zeros, 379u * 384u);
  // Independently: count the non-zero raw distances in the bytes.
  std::uint64_t nonzero = 0;
  for (const auto& p : packets) {
    for (std::size_t b = 0; b < 12; ++b) {
      for (std::size_t c = 0; c < 32; ++c) nonzero += raw_distance(p, b, c) != 0;
    }
  }
  EXPECT_EQ(points, nonzero);
  EXPECT_EQ(points, 131305u);
}

TEST_F(Vlp32cCapture, EveryPointMatchesTheCalibration) {
  PacketDecoder decoder(calibration);
  auto out = std::make_unique<DecodedPacket>();
  double worst_range = 0, worst_elev = 0, worst_az = 0;
  for (const auto& p : packets) {
    ASSERT_EQ(decoder.decode(p, *out), DecodeStatus::kOk);
    for (std::uint32_t i = 0; i < out->point_count; ++i) {
      const DecodedPoint& pt = out->points[i];
      ASSERT_LT(pt.block, 12);
      ASSERT_LT(pt.channel, 32);
      EXPECT_EQ(pt.laser, pt.channel);
      const LaserCorrection& l = calibration.lasers[pt.laser];
      const double x = pt.x_m, y = pt.y_m, z = pt.z_m;
      const double r = std::sqrt(x * x + y * y + z * z);
      // range = raw × 4 mm (the VLP-32C's distance unit)
      const double want_r = raw_distance(p, pt.block, pt.channel) * 0.004;
      worst_range = std::max(worst_range, std::fabs(r - want_r));
      worst_range = std::max(worst_range, std::fabs(pt.range_m - want_r));
      // elevation = the laser's vert_correction
      worst_elev = std::max(worst_elev, std::fabs(std::asin(z / r) - l.vert_correction_rad));
      // azimuth (Velodyne: clockwise, so −atan2(y, x)) = block azimuth + rotation since the
      // block's first firing − rot_correction (manual 9.6). The rotation during a firing is the
      // azimuth change to the next block; the last block, and a block before a jump (this
      // capture splices turns inside a packet), take the previous block's.
      const auto gap_after = [&](std::size_t b) -> int {
        if (b + 1 >= 12) return -1;
        const int g = (out->block_azimuth_cdeg[b + 1] + 36000 - out->block_azimuth_cdeg[b]) % 36000;
        return g <= 100 ? g : -1;
      };
      int gap = gap_after(pt.block);
      for (std::size_t b = pt.block; gap < 0 && b > 0; --b) gap = gap_after(b - 1);
      ASSERT_GE(gap, 0);
      const double block_az = out->block_azimuth_cdeg[pt.block] / 100.0 * kPi / 180.0;
      const double az = -std::atan2(y, x);
      const double interp = (pt.channel / 2) * 2.304 / 55.296 * (gap / 100.0 * kPi / 180);
      double err = az - (block_az + interp - l.rot_correction_rad);
      err = std::remainder(err, 2 * kPi);
      worst_az = std::max(worst_az, std::fabs(err));
      // per-point time: firing (block) × 55.296 µs + pair index × 2.304 µs
      EXPECT_EQ(pt.t_ns, pt.block * 55'296 + (pt.channel / 2) * 2'304);
      // ring order follows elevation
      EXPECT_EQ(pt.ring, rings_by_elevation(calibration)[pt.laser]);
    }
  }
  EXPECT_LT(worst_range, 1e-4);  // float arithmetic on ranges up to ~130 m
  EXPECT_LT(worst_elev, 2e-5);
  EXPECT_LT(worst_az, 2e-5);  // float trigonometry
}

TEST_F(Vlp32cCapture, TimestampsAdvanceOneFiringCyclePerBlock) {
  PacketDecoder decoder(calibration);
  auto out = std::make_unique<DecodedPacket>();
  std::uint32_t prev = 0;
  int consecutive = 0;
  for (std::size_t i = 0; i < packets.size(); ++i) {
    ASSERT_EQ(decoder.decode(packets[i], *out), DecodeStatus::kOk);
    if (i > 0) {
      const std::uint32_t dt = out->device_time_us - prev;
      // 12 × 55.296 µs = 663.552 µs; the stamp is whole µs.
      if (dt < 1000) {
        EXPECT_TRUE(dt == 663 || dt == 664) << "packet " << i << " dt " << dt;
        ++consecutive;
      }
    }
    prev = out->device_time_us;
  }
  EXPECT_GT(consecutive, 360);  // all but the jumps over the dropped rear half of each turn
}

TEST_F(Vlp32cCapture, GroundIsFlat) {
  PacketDecoder decoder(calibration);
  auto out = std::make_unique<DecodedPacket>();
  // The lowest lasers (−25°…−7°) see the ground in front of the sensor.
  std::vector<Eigen::Vector3d> ground;
  for (const auto& p : packets) {
    ASSERT_EQ(decoder.decode(p, *out), DecodeStatus::kOk);
    for (std::uint32_t i = 0; i < out->point_count; ++i) {
      const DecodedPoint& pt = out->points[i];
      if (calibration.lasers[pt.laser].vert_correction_rad < -7.0 * kPi / 180 && pt.z_m < -0.2f &&
          pt.z_m > -0.45f) {
        ground.emplace_back(pt.x_m, pt.y_m, pt.z_m);
      }
    }
  }
  ASSERT_GT(ground.size(), 15000u);
  // Least-squares plane z = a x + b y + c.
  Eigen::MatrixXd A(static_cast<Eigen::Index>(ground.size()), 3);
  Eigen::VectorXd z(static_cast<Eigen::Index>(ground.size()));
  for (std::size_t i = 0; i < ground.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    A(k, 0) = ground[i].x();
    A(k, 1) = ground[i].y();
    A(k, 2) = 1.0;
    z(k) = ground[i].z();
  }
  const Eigen::Vector3d abc = A.colPivHouseholderQr().solve(z);
  const Eigen::VectorXd residual = A * abc - z;
  std::vector<double> abs_res(ground.size());
  for (std::size_t i = 0; i < ground.size(); ++i) {
    abs_res[i] = std::fabs(residual(static_cast<Eigen::Index>(i)));
  }
  std::sort(abs_res.begin(), abs_res.end());
  const double tilt_deg = std::atan(std::hypot(abc.x(), abc.y())) * 180 / kPi;
  EXPECT_LT(tilt_deg, 3.0);
  EXPECT_NEAR(abc.z(), -0.3, 0.05);  // sensor height above the ground [m]
  EXPECT_LT(abs_res[abs_res.size() * 8 / 10], 0.02) << "80% of ground points within 2 cm";
}

TEST_F(Vlp32cCapture, BuiltinTableGivesTheSamePoints) {
  PacketDecoder with_file(calibration);
  PacketDecoder builtin;  // empty calibration: the manual's table for the product seen
  auto a = std::make_unique<DecodedPacket>();
  auto b = std::make_unique<DecodedPacket>();
  for (const auto& p : packets) {
    ASSERT_EQ(with_file.decode(p, *a), DecodeStatus::kOk);
    ASSERT_EQ(builtin.decode(p, *b), DecodeStatus::kOk);
    ASSERT_EQ(a->point_count, b->point_count);
    for (std::uint32_t i = 0; i < a->point_count; ++i) {
      EXPECT_NEAR(a->points[i].x_m, b->points[i].x_m, 1e-4);
      EXPECT_NEAR(a->points[i].y_m, b->points[i].y_m, 1e-4);
      EXPECT_NEAR(a->points[i].z_m, b->points[i].z_m, 1e-4);
    }
  }
}

TEST_F(Vlp32cCapture, RangeLimitsDropPoints) {
  PacketDecoder decoder(calibration, {.min_range_m = 1.0, .max_range_m = 20.0});
  auto out = std::make_unique<DecodedPacket>();
  std::uint64_t kept = 0, dropped = 0;
  for (const auto& p : packets) {
    ASSERT_EQ(decoder.decode(p, *out), DecodeStatus::kOk);
    for (std::uint32_t i = 0; i < out->point_count; ++i) {
      EXPECT_GE(out->points[i].range_m, 1.0f);
      EXPECT_LE(out->points[i].range_m, 20.0f);
    }
    kept += out->point_count;
    dropped += out->out_of_range_count;
  }
  EXPECT_EQ(kept + dropped, 131305u);
  EXPECT_GT(dropped, 0u);
}

TEST_F(Vlp32cCapture, WrongModelIsRejected) {
  PacketDecoder decoder(calibration, {.expected_product = ProductId::kHdl32e});
  auto out = std::make_unique<DecodedPacket>();
  EXPECT_EQ(decoder.decode(packets[0], *out), DecodeStatus::kModelMismatch);
  PacketDecoder sixteen(builtin_calibration(ProductId::kVlp16));  // 16 lasers vs a 32-laser sensor
  EXPECT_EQ(sixteen.decode(packets[0], *out), DecodeStatus::kModelMismatch);
  EXPECT_EQ(sixteen.counters().model_mismatch, 1u);
}

// ---- HDL-32E: VeloView's expectations --------------------------------------------------------

struct VeloViewExpectation {
  std::size_t frame_count = 0;
  std::map<std::size_t, std::size_t> point_counts;
  std::size_t values_frame = 0;
  struct Value {
    std::size_t index;
    double x, y, z;
    int intensity;
  };
  std::vector<Value> values;
};

VeloViewExpectation read_test_file(const std::string& path) {
  VeloViewExpectation e;
  std::ifstream in(path);
  std::string line;
  std::size_t frame = 0;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string key;
    s >> key;
    if (key == "frame_count") s >> e.frame_count;
    if (key == "frame") s >> frame;
    if (key == "point_count") {
      std::size_t n = 0;
      s >> n;
      e.point_counts[frame] = n;
      e.values_frame = frame;
    }
    if (key == "point_values") {
      VeloViewExpectation::Value v{};
      s >> v.index >> v.x >> v.y >> v.z >> v.intensity;
      e.values.push_back(v);
    }
  }
  return e;
}

TEST(Hdl32eCapture, MatchesVeloViewFrameCountsAndPoints) {
  POSED_REQUIRE_REALDATA(pcap, "velodyne_hdl32e/monterey-first-100-packets.pcap");
  POSED_REQUIRE_REALDATA(xml, "velodyne_hdl32e/HDL-32.xml");
  POSED_REQUIRE_REALDATA(expect_path, "velodyne_hdl32e/monterey.test");
  const VeloViewExpectation expect = read_test_file(expect_path);
  ASSERT_EQ(expect.frame_count, 19u);
  ASSERT_EQ(expect.values.size(), 4u);
  Calibration cal;
  std::string error;
  ASSERT_TRUE(load_calibration(xml, cal, error)) << error;
  PacketDecoder decoder(cal);
  auto out = std::make_unique<DecodedPacket>();
  // VeloView starts a frame whenever the block azimuth decreases and keeps every non-zero return,
  // in packet, block, channel order.
  std::vector<std::vector<DecodedPoint>> frames(1);
  std::uint32_t last_az = 0;
  bool first = true;
  for (const auto& d : test::load_datagrams(pcap)) {
    if (d.dst_port != 2368) continue;
    ASSERT_EQ(decoder.decode(d.payload, *out), DecodeStatus::kOk);
    ASSERT_EQ(out->product, ProductId::kHdl32e);
    std::uint32_t next = 0;
    for (std::uint32_t b = 0; b < 12; ++b) {
      if (!first && out->block_azimuth_cdeg[b] < last_az) frames.emplace_back();
      first = false;
      last_az = out->block_azimuth_cdeg[b];
      while (next < out->point_count && out->points[next].block == b) {
        frames.back().push_back(out->points[next++]);
      }
    }
  }
  EXPECT_EQ(decoder.counters().packets_ok, 2702u);
  ASSERT_EQ(frames.size(), expect.frame_count);
  for (const auto& [frame, count] : expect.point_counts) {
    EXPECT_EQ(frames[frame].size(), count) << "frame " << frame;
  }
  // VeloView's frame is x right, y forward; ours is x forward, y left: (x, y) = (y_vv, −x_vv).
  // VeloView does not interpolate HDL-32E azimuths within a block; allow the rotation during
  // one firing cycle (0.2° at 10 Hz ⇒ 3.5 mm/m) plus 1 cm.
  for (const auto& v : expect.values) {
    const DecodedPoint& p = frames[expect.values_frame].at(v.index);
    const double range = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    const double tol = 0.01 + range * 0.0035;
    EXPECT_NEAR(p.x_m, v.y, tol) << "point " << v.index;
    EXPECT_NEAR(p.y_m, -v.x, tol) << "point " << v.index;
    EXPECT_NEAR(p.z_m, v.z, 0.01) << "point " << v.index;
    EXPECT_EQ(p.intensity, v.intensity) << "point " << v.index;
    EXPECT_EQ(p.t_ns, p.block * 46'080 + p.channel * 1'152);
  }
}

}  // namespace
}  // namespace posed::drivers::velodyne
