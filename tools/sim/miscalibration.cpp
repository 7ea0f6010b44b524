#include "tools/sim/miscalibration.hpp"

#include <cmath>
#include <cstdio>
#include <random>

namespace posed::sim {
namespace {

constexpr double kRotationDeg = 1.0;
constexpr double kTranslationM = 0.02;
constexpr double kLatencyMinS = 0.002, kLatencyMaxS = 0.005;
constexpr double kImuMatrixError = 0.005;

Eigen::Vector3d random_direction(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Vector3d v;
  do {
    v = {n(rng), n(rng), n(rng)};
  } while (v.norm() < 1e-6);
  return v.normalized();
}

Eigen::Isometry3d extrinsic_error(std::mt19937_64& rng) {
  Eigen::Isometry3d e = Eigen::Isometry3d::Identity();
  e.linear() = Eigen::AngleAxisd(kRotationDeg * M_PI / 180.0, random_direction(rng)).matrix();
  e.translation() = kTranslationM * random_direction(rng);
  return e;
}

double latency_error(std::mt19937_64& rng) {
  const double size = std::uniform_real_distribution<double>(kLatencyMinS, kLatencyMaxS)(rng);
  return std::bernoulli_distribution(0.5)(rng) ? size : -size;
}

Eigen::Matrix3d imu_matrix(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-kImuMatrixError, kImuMatrixError);
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) += u(rng);
  return m;
}

std::string extrinsic_text(const char* name, const Eigen::Isometry3d& e) {
  char text[160];
  std::snprintf(text, sizeof text, "%s %.2f deg %.1f cm", name,
                Eigen::AngleAxisd(e.linear()).angle() * 180.0 / M_PI,
                e.translation().norm() * 100.0);
  return text;
}

/// Largest scale error (diagonal) and misalignment (off-diagonal) of M [%].
std::string imu_text(const char* name, const Eigen::Matrix3d& m) {
  double scale = 0, misalignment = 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      const double e = std::abs(m(r, c) - (r == c ? 1.0 : 0.0));
      (r == c ? scale : misalignment) = std::max(r == c ? scale : misalignment, e);
    }
  char text[160];
  std::snprintf(text, sizeof text, "%s scale up to %.2f %%, misalignment up to %.2f %%", name,
                scale * 100.0, misalignment * 100.0);
  return text;
}

}  // namespace

std::string Miscalibration::describe() const {
  char latencies[160];
  std::snprintf(latencies, sizeof latencies, "visible latency %+.1f ms, thermal latency %+.1f ms",
                visible_latency_error_s * 1e3, thermal_latency_error_s * 1e3);
  return extrinsic_text("T_imu_lidar", lidar_error) + ", " +
         extrinsic_text("T_imu_cam", camera_error) + ", " +
         extrinsic_text("T_cam_thermal", thermal_error) + ", " + latencies + ", " +
         imu_text("gyro", gyro_scale_misalignment) + ", " +
         imu_text("accel", accel_scale_misalignment);
}

Miscalibration draw_miscalibration(std::uint64_t seed) {
  // Its own stream: the world and the drive of the seed stay those of a calibrated run.
  std::mt19937_64 rng(seed ^ 0x6d69736361ull);
  Miscalibration m;
  m.lidar_error = extrinsic_error(rng);
  m.camera_error = extrinsic_error(rng);
  m.thermal_error = extrinsic_error(rng);
  m.visible_latency_error_s = latency_error(rng);
  m.thermal_latency_error_s = latency_error(rng);
  m.gyro_scale_misalignment = imu_matrix(rng);
  m.accel_scale_misalignment = imu_matrix(rng);
  return m;
}

void apply_miscalibration(const Miscalibration& error, SimRig& rig) {
  rig.T_imu_lidar = rig.T_imu_lidar * error.lidar_error;
  rig.T_imu_cam = rig.T_imu_cam * error.camera_error;
  rig.T_cam_thermal = rig.T_cam_thermal * error.thermal_error;
  rig.visible_latency_s += error.visible_latency_error_s;
  rig.thermal_latency_s += error.thermal_latency_error_s;
  rig.imu.gyro_scale_misalignment = error.gyro_scale_misalignment;
  rig.imu.accel_scale_misalignment = error.accel_scale_misalignment;
}

}  // namespace posed::sim
