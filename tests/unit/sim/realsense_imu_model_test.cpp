// The simulated D435i IMU through the real IIO decoder and the combiner: with noise off, the
// combined samples are the trajectory's rate and specific force at the IMU frame's origin, up to
// the LSBs (0.1 deg/s, 1 mg) and the lever arm's angular acceleration (the D435i sits a metre
// from the IMU frame's origin on the rig).

#include "tools/sim/realsense_imu_model.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "drivers/camera/realsense_imu_combiner.hpp"
#include "drivers/camera/realsense_imu_decoder.hpp"
#include "tools/sim/scenarios.hpp"

namespace posed::sim {
namespace {

namespace cam = drivers::camera;

TEST(RealsenseImuModel, DecodedAndCombinedItReadsWhatTheImuFramesOriginFeels) {
  std::string error;
  auto s = make_scenario("street_night", 3, 30.0, 9.805, error);
  ASSERT_TRUE(s) << error;
  RealsenseImuModelConfig cfg;
  cfg.noise = false;
  // Where config/posed.yaml puts it: the colour camera's axes, 0.58 m ahead and 0.83 m up.
  cfg.T_base_rsimu.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  cfg.T_base_rsimu.translation() = Eigen::Vector3d(0.58, 0.01, 0.84);
  const ClockModel clock({5'000'000'000, -20.0, 0, 0}, 0, 1);
  RealsenseImuModel model(cfg, s->trajectory, clock, 7);

  cam::RealsenseImuDecoder accel(realsense_accel_wire_format());
  cam::RealsenseImuDecoder gyro(realsense_gyro_wire_format());
  ASSERT_TRUE(accel.valid()) << accel.error();
  ASSERT_TRUE(gyro.valid()) << gyro.error();
  cam::RealsenseImuMounting m;
  m.R_imu_depth = cfg.T_base_rsimu.linear();
  m.p_imu_rsimu_m = cfg.T_base_rsimu.translation();
  cam::RealsenseImuCombiner combiner(m);

  std::vector<cam::RealsenseImuSample> out;
  std::vector<cam::D4xxMotionSample> decoded(1);
  std::uint64_t accel_records = 0, gyro_records = 0;
  const Duration end = Duration::from_seconds(20.0);
  while (model.next_accel() < end || model.next_gyro() < end) {
    const bool accel_next = model.next_accel() <= model.next_gyro();
    const std::vector<std::byte> record = accel_next ? model.emit_accel() : model.emit_gyro();
    ASSERT_EQ(record.size(), 24u);
    ASSERT_EQ((accel_next ? accel : gyro).decode(record, decoded), 1u);
    (accel_next ? accel_records : gyro_records)++;
    combiner.add(decoded[0], {}, out);
  }
  EXPECT_NEAR(static_cast<double>(accel_records), 20 * 250.0, 2.0);
  EXPECT_NEAR(static_cast<double>(gyro_records), 20 * 200.0, 2.0);
  ASSERT_GT(out.size(), 3900u);

  double sum_f2 = 0, max_f = 0, max_w = 0;
  std::size_t n = 0;
  for (std::size_t k = 10; k < out.size(); ++k) {  // after the angular acceleration settled
    const Duration t = clock.true_at(out[k].device_stamp);
    const TrajectorySample truth = s->trajectory.at(t);
    const double ew = (out[k].angular_velocity_radps - truth.w_base_radps).norm();
    const double ef = (out[k].specific_force_mps2 - truth.f_base_mps2).norm();
    max_w = std::max(max_w, ew);
    max_f = std::max(max_f, ef);
    sum_f2 += ef * ef;
    ++n;
  }
  const double rms_f = std::sqrt(sum_f2 / static_cast<double>(n));
  // Gyro: half an LSB per axis. Accel: the LSB and the 4 ms interpolation (< 0.01 m/s^2 with the
  // D435i at the origin), and mostly the lever arm's angular acceleration taken from a quantised
  // gyro a metre away: 0.11 m/s^2 RMS here, about twice a calibrated BMI055's bias residual.
  EXPECT_LT(max_w, 1.6e-3);
  EXPECT_LT(rms_f, 0.15) << "max " << max_f;
  EXPECT_LT(max_f, 0.4) << "at the turns' onsets, where the angular acceleration jumps";
  RecordProperty("rms_specific_force_error_mps2", std::to_string(rms_f));
}

}  // namespace
}  // namespace posed::sim
