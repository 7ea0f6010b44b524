// Simulated A9 frames through the real decoder: with noise off they integrate back onto the
// trajectory; with noise on, the white noise and bias walk have the configured densities.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "drivers/imu/a9_protocol.hpp"
#include "tools/sim/imu_model.hpp"
#include "tools/sim/scenarios.hpp"

namespace posed::sim {
namespace {

namespace a9 = drivers::a9;

struct Decoded {
  std::int64_t t_ns;
  Eigen::Vector3d w, f;
  std::uint32_t counter;
  ImuSampleTruth truth;
};

std::vector<Decoded> run(ImuModel& imu, double seconds) {
  a9::A9Decoder decoder;
  std::vector<Decoded> out;
  std::vector<std::uint8_t> buf(a9::kMaxFrameSize);
  while (imu.next_send() < Duration::from_seconds(seconds)) {
    const std::size_t n = imu.emit(buf);
    decoder.feed(std::span<const std::uint8_t>(buf.data(), n), [&](const a9::A9Frame& fr) {
      const ImuSample s = a9::to_imu_sample(fr.sensor, {}, HostTime{}, DeviceTime{});
      out.push_back({imu.last().t_true_ns, s.angular_velocity_radps, s.specific_force_mps2,
                     fr.sensor.counter_us, imu.last()});
    });
  }
  return out;
}

TEST(ImuModel, NoiseFreeSamplesIntegrateBackToTheTrajectory) {
  std::string error;
  auto s = make_scenario("room", 5, 30.0, 9.805, error);
  ASSERT_TRUE(s) << error;
  ImuModelConfig cfg;
  cfg.noise = false;
  ClockModel clock({1'000'000'000, 35.0, 0, 0}, 0, 1);
  ImuModel imu(cfg, s->trajectory, clock, 1);
  const auto samples = run(imu, 20.0);
  ASSERT_NEAR(static_cast<double>(samples.size()), 20 * 150.0, 2.0);
  // Start from the true state at the first sample; trapezoidal integration on SO(3) × R³.
  const TrajectorySample s0 = s->trajectory.at(Duration::from_ns(samples[0].t_ns));
  Eigen::Quaterniond q = s0.q_map_base;
  Eigen::Vector3d v = s0.v_map_mps, p = s0.p_map_base_m;
  const Eigen::Vector3d g(0, 0, -9.805);
  double max_att = 0, max_pos = 0;
  for (std::size_t k = 1; k < samples.size(); ++k) {
    const auto& a = samples[k - 1];
    const auto& b = samples[k];
    // The decoded value equals the exact one up to float32 (and the 9.80665 [g] round trip).
    ASSERT_LT((b.w - b.truth.w_true_radps).norm(), 1e-6);
    ASSERT_LT((b.f - b.truth.f_true_mps2).norm(), 1e-5);
    const double dt = static_cast<double>(b.t_ns - a.t_ns) * 1e-9;
    const Eigen::Vector3d a_map0 = q * a.f + g;
    const Eigen::Vector3d w_mid = 0.5 * (a.w + b.w);
    const Eigen::Vector3d dth = w_mid * dt;
    // Second-order correction for the rotation axis turning during the step.
    const Eigen::Vector3d corr = a.w.cross(b.w) * dt * dt / 12.0;
    const Eigen::Vector3d rot = dth + corr;
    q = (q * Eigen::Quaterniond(Eigen::AngleAxisd(
                 rot.norm(), rot.norm() > 0 ? rot.normalized() : Eigen::Vector3d::UnitX())))
            .normalized();
    const Eigen::Vector3d a_map1 = q * b.f + g;
    p += v * dt + (2 * a_map0 + a_map1) * dt * dt / 6.0;
    v += 0.5 * (a_map0 + a_map1) * dt;
    const TrajectorySample truth = s->trajectory.at(Duration::from_ns(b.t_ns));
    max_att = std::max(max_att, Eigen::AngleAxisd(truth.q_map_base.conjugate() * q).angle());
    max_pos = std::max(max_pos, (truth.p_map_base_m - p).norm());
  }
  EXPECT_LT(max_att, 1e-4);  // [rad] over 20 s
  EXPECT_LT(max_pos, 0.02);  // [m] over 20 s of dead reckoning
  // Samples are regular on the A9's counter (6666/6667 µs) and the counter is the device clock.
  for (std::size_t k = 1; k < samples.size(); ++k) {
    const std::uint32_t d = samples[k].counter - samples[k - 1].counter;
    ASSERT_TRUE(d == 6666 || d == 6667) << d;
  }
}

TEST(ImuModel, NoiseHasTheConfiguredDensities) {
  std::string error;
  auto s = make_scenario("corridor", 6, 60.0, 9.805, error);
  ASSERT_TRUE(s) << error;
  ImuModelConfig cfg;  // M2DGR's A9 figures
  ClockModel clock({0, 0, 0, 0}, 0, 1);
  ImuModel imu(cfg, s->trajectory, clock, 77);
  const auto samples = run(imu, 60.0);
  double gw = 0, ga = 0;
  for (const auto& x : samples) {
    gw += (x.w - x.truth.w_true_radps - x.truth.gyro_bias_radps).squaredNorm();
    ga += (x.f - x.truth.f_true_mps2 - x.truth.accel_bias_mps2).squaredNorm();
  }
  const auto n = static_cast<double>(3 * samples.size());
  EXPECT_NEAR(std::sqrt(gw / n), cfg.gyro_noise_density * std::sqrt(150.0),
              0.03 * cfg.gyro_noise_density * std::sqrt(150.0));
  EXPECT_NEAR(std::sqrt(ga / n), cfg.accel_noise_density * std::sqrt(150.0),
              0.03 * cfg.accel_noise_density * std::sqrt(150.0));
  // Bias walk: increments of the bias over 1 s have σ = walk · √1 s.
  double sw = 0, sa = 0;
  int m = 0;
  for (std::size_t k = 150; k < samples.size(); k += 150) {
    sw += (samples[k].truth.gyro_bias_radps - samples[k - 150].truth.gyro_bias_radps).squaredNorm();
    sa += (samples[k].truth.accel_bias_mps2 - samples[k - 150].truth.accel_bias_mps2).squaredNorm();
    m += 3;
  }
  EXPECT_NEAR(std::sqrt(sw / m), cfg.gyro_random_walk, 0.25 * cfg.gyro_random_walk);
  EXPECT_NEAR(std::sqrt(sa / m), cfg.accel_random_walk, 0.25 * cfg.accel_random_walk);
}

}  // namespace
}  // namespace posed::sim
