// posectl sim --miscalibrate: the rig the sensors really have differs from the configured one by
// the stated amounts, the same for a seed every time, and the IMU measures through its scale and
// misalignment.

#include "tools/sim/miscalibration.hpp"

#include <gtest/gtest.h>

#include "tools/sim/imu_model.hpp"
#include "tools/sim/scenarios.hpp"

namespace posed::sim {
namespace {

double angle_deg(const Eigen::Isometry3d& e) {
  return Eigen::AngleAxisd(e.linear()).angle() * 180.0 / M_PI;
}

TEST(Miscalibration, ErrorsHaveTheStatedSizesAndFollowTheSeed) {
  for (const std::uint64_t seed : {1u, 2u, 17u}) {
    const Miscalibration m = draw_miscalibration(seed);
    for (const Eigen::Isometry3d* e : {&m.lidar_error, &m.camera_error, &m.thermal_error}) {
      EXPECT_NEAR(angle_deg(*e), 1.0, 1e-9);
      EXPECT_NEAR(e->translation().norm(), 0.02, 1e-12);
    }
    for (const double latency_s : {m.visible_latency_error_s, m.thermal_latency_error_s}) {
      EXPECT_GE(std::abs(latency_s), 0.002);
      EXPECT_LE(std::abs(latency_s), 0.005);
    }
    for (const Eigen::Matrix3d* imu : {&m.gyro_scale_misalignment, &m.accel_scale_misalignment}) {
      EXPECT_LE((*imu - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 0.005);
      EXPECT_GT((*imu - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 0.0);
    }
    EXPECT_EQ(m.describe(), draw_miscalibration(seed).describe());
  }
  EXPECT_NE(draw_miscalibration(1).describe(), draw_miscalibration(2).describe());
  EXPECT_NE(draw_miscalibration(1).describe().find("T_imu_lidar 1.00 deg 2.0 cm"),
            std::string::npos)
      << draw_miscalibration(1).describe();
}

TEST(Miscalibration, TheSimulatedRigIsTheConfiguredOneTimesTheError) {
  SimRig rig;
  rig.T_imu_lidar.translation() = Eigen::Vector3d(0.1, 0.0, 0.3);
  const SimRig configured = rig;
  const Miscalibration m = draw_miscalibration(5);
  apply_miscalibration(m, rig);
  EXPECT_TRUE(rig.T_imu_lidar.isApprox(configured.T_imu_lidar * m.lidar_error));
  EXPECT_TRUE(rig.T_imu_cam.isApprox(configured.T_imu_cam * m.camera_error));
  EXPECT_DOUBLE_EQ(rig.visible_latency_s, configured.visible_latency_s + m.visible_latency_error_s);
  EXPECT_TRUE(rig.imu.gyro_scale_misalignment.isApprox(m.gyro_scale_misalignment));
}

TEST(Miscalibration, TheImuMeasuresThroughItsScaleAndMisalignment) {
  std::string error;
  auto s = make_scenario("room", 5, 10.0, 9.805, error);
  ASSERT_TRUE(s) << error;
  ImuModelConfig cfg;
  cfg.noise = false;
  cfg.gyro_scale_misalignment = draw_miscalibration(3).gyro_scale_misalignment;
  cfg.accel_scale_misalignment = draw_miscalibration(3).accel_scale_misalignment;
  ClockModel clock({0, 0.0, 0, 0}, 0, 1);
  ImuModel imu(cfg, s->trajectory, clock, 1);
  std::vector<std::uint8_t> buf(drivers::a9::kMaxFrameSize);
  for (int k = 0; k < 600; ++k) imu.emit(buf);
  const ImuSampleTruth& t = imu.last();
  EXPECT_TRUE(t.f_meas_mps2.isApprox(cfg.accel_scale_misalignment * t.f_true_mps2, 1e-12));
  EXPECT_TRUE(t.w_meas_radps.isApprox(cfg.gyro_scale_misalignment * t.w_true_radps, 1e-12));
  EXPECT_GT((t.f_meas_mps2 - t.f_true_mps2).norm(), 1e-3) << "the error shows in the samples";
}

}  // namespace
}  // namespace posed::sim
