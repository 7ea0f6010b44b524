#include "tools/sim/realsense_imu_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

#include "drivers/camera/iio_scan.hpp"
#include "drivers/common/wire_format.hpp"

namespace posed::sim {

namespace {

namespace cam = drivers::camera;

constexpr double kGravity = 9.80665;            // librealsense's accel scale: 0.001 g per LSB
constexpr double kAccelLsb = 0.001 * kGravity;  // [m/s^2]
constexpr double kGyroLsb = 0.1 * std::numbers::pi / 180.0;  // [rad/s]
constexpr std::size_t kRecordBytes = 24;

// The hid-sensor records' layout: three le:s16/32 axes and the le:s64 timestamp.
std::string wire_format(std::string_view prefix, const char* stem) {
  std::vector<cam::IioScanElement> elements(4);
  for (int i = 0; i < 3; ++i) {
    elements[i].name = std::string(stem) + static_cast<char>('x' + i);
    elements[i].index = static_cast<std::uint32_t>(i);
    cam::parse_iio_scan_type("le:s16/32>>0", elements[i].type);
  }
  elements[3].name = "in_timestamp";
  elements[3].index = 3;
  cam::parse_iio_scan_type("le:s64/64>>0", elements[3].type);
  cam::IioScanLayout layout;
  std::string error;
  cam::layout_iio_scan(elements, layout, error);
  return cam::describe_iio_layout(prefix, layout);
}

}  // namespace

std::string realsense_accel_wire_format() {
  return wire_format(drivers::wire::kIioAccel3d, "in_accel_");
}
std::string realsense_gyro_wire_format() {
  return wire_format(drivers::wire::kIioGyro3d, "in_anglvel_");
}

RealsenseImuModel::RealsenseImuModel(const RealsenseImuModelConfig& config,
                                     const Trajectory& trajectory, const ClockModel& clock,
                                     std::uint64_t seed)
    : config_(config),
      trajectory_(trajectory),
      accel_schedule_(clock, config.accel_rate_hz),
      gyro_schedule_(clock, config.gyro_rate_hz),
      rng_(seed) {
  if (config_.noise) {
    std::normal_distribution<double> n(0.0, 1.0);
    for (int a = 0; a < 3; ++a) gyro_bias_[a] = config_.gyro_bias_sigma_radps * n(rng_);
    for (int a = 0; a < 3; ++a) accel_bias_[a] = config_.accel_bias_sigma_mps2 * n(rng_);
  }
}

void RealsenseImuModel::truth_at(Duration t, Eigen::Vector3d& w_rsimu_radps,
                                 Eigen::Vector3d& f_rsimu_mps2) const {
  const TrajectorySample s = trajectory_.at(t);
  // Angular acceleration by a central difference over 2 ms of the exact rates.
  const Duration h = Duration::from_ms(1);
  const Eigen::Vector3d alpha =
      (trajectory_.at(t + h).w_base_radps - trajectory_.at(t - h).w_base_radps) / (2 * h.seconds());
  const Eigen::Vector3d& w = s.w_base_radps;
  const Eigen::Vector3d r = config_.T_base_rsimu.translation();
  const Eigen::Vector3d f = s.f_base_mps2 + alpha.cross(r) + w.cross(w.cross(r));
  const Eigen::Matrix3d R_rsimu_base = config_.T_base_rsimu.linear().transpose();
  w_rsimu_radps = R_rsimu_base * w;
  f_rsimu_mps2 = R_rsimu_base * f;
}

std::vector<std::byte> RealsenseImuModel::record(const Eigen::Vector3d& value_depth, double lsb,
                                                 DeviceTime stamp) const {
  // The sensor's axes are diag(-1, 1, -1) of the depth frame's (the decoder flips them back).
  const double sensor[3] = {-value_depth.x(), value_depth.y(), -value_depth.z()};
  std::vector<std::byte> out(kRecordBytes, std::byte{0});
  for (int a = 0; a < 3; ++a) {
    const long raw = std::clamp(std::lround(sensor[a] / lsb), -32768L, 32767L);
    const auto v = static_cast<std::int32_t>(raw);
    std::memcpy(out.data() + 4 * a, &v, sizeof v);  // little-endian host (x86-64, arm64)
  }
  const std::int64_t ns = stamp.ns;
  std::memcpy(out.data() + 16, &ns, sizeof ns);
  return out;
}

void RealsenseImuModel::perturb(Eigen::Vector3d& v, Eigen::Vector3d& bias, double rate_hz,
                                double random_walk, double noise_density) {
  if (!config_.noise) return;
  // Discrete equivalents of the continuous densities at the sample period dt: bias step
  // sigma = walk * sqrt(dt), white sigma = density / sqrt(dt).
  const double dt = 1.0 / rate_hz;
  std::normal_distribution<double> n(0.0, 1.0);
  for (int a = 0; a < 3; ++a) bias[a] += random_walk * std::sqrt(dt) * n(rng_);
  for (int a = 0; a < 3; ++a) v[a] += bias[a] + noise_density / std::sqrt(dt) * n(rng_);
}

std::vector<std::byte> RealsenseImuModel::emit_accel() {
  const Duration t = accel_schedule_.true_time(accel_index_);
  const DeviceTime d = accel_schedule_.device(accel_index_);
  ++accel_index_;
  Eigen::Vector3d w, f;
  truth_at(t, w, f);
  perturb(f, accel_bias_, config_.accel_rate_hz, config_.accel_random_walk,
          config_.accel_noise_density);
  return record(f, kAccelLsb, d);
}

std::vector<std::byte> RealsenseImuModel::emit_gyro() {
  const Duration t = gyro_schedule_.true_time(gyro_index_);
  const DeviceTime d = gyro_schedule_.device(gyro_index_);
  ++gyro_index_;
  Eigen::Vector3d w, f;
  truth_at(t, w, f);
  perturb(w, gyro_bias_, config_.gyro_rate_hz, config_.gyro_random_walk,
          config_.gyro_noise_density);
  return record(w, kGyroLsb, d);
}

}  // namespace posed::sim
