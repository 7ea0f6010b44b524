#pragma once
// The D435i's accelerometer (250 Hz) and gyro (200 Hz) are two streams on one device clock;
// posed's IMU samples carry both. This turns them into one sample per gyro reading, as
// librealsense's "linear interpolation" unite_imu_method does: the specific force is
// interpolated between the two accel readings around the gyro's stamp (a gyro reading waits at
// most one accel period for the next accel). Then both go into the IMU (base_link) frame, and
// the specific force is moved from where the D435i's IMU sits to the IMU frame's origin
// (f_o = f_r - alpha x r - w x (w x r), alpha from the gyro), so a backup IMU 10-20 cm from the
// A9 reads what the A9 would. Pure: no I/O, no allocation after construction.

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <vector>

#include "core/time.hpp"
#include "drivers/camera/realsense_imu_decoder.hpp"

namespace posed::drivers::camera {

/// Where the D435i's IMU is and what its calibration says.
struct RealsenseImuMounting {
  /// depth-frame axes (the decoder's output) into the IMU frame
  Eigen::Matrix3d R_imu_depth = Eigen::Matrix3d::Identity();
  /// position of the D435i's IMU in the IMU frame [m]
  Eigen::Vector3d p_imu_rsimu_m = Eigen::Vector3d::Zero();
  /// biases from rs-imu-calibration, in depth-frame axes, subtracted [rad/s], [m/s^2]
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias_mps2 = Eigen::Vector3d::Zero();
};

/// One combined sample in the IMU frame, on the device clock.
struct RealsenseImuSample {
  /// the gyro reading's device stamp [ns]
  DeviceTime device_stamp;
  /// host receive time of the gyro reading
  HostTime arrival;
  Eigen::Vector3d angular_velocity_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d specific_force_mps2 = Eigen::Vector3d::Zero();
};

struct RealsenseImuCombinerCounters {
  std::uint64_t combined = 0;      ///< samples made
  std::uint64_t held = 0;          ///< of those, with the last accel held (accel stream late)
  std::uint64_t no_accel = 0;      ///< gyro readings dropped: no accel reading yet
  std::uint64_t out_of_order = 0;  ///< readings not newer than their stream's last (dropped)
};

class RealsenseImuCombiner {
 public:
  explicit RealsenseImuCombiner(const RealsenseImuMounting& mounting);

  /// One decoded reading received at `arrival`; appends the samples it completes to `out`.
  void add(const D4xxMotionSample& reading, HostTime arrival, std::vector<RealsenseImuSample>& out);
  /// Gyro readings still waiting for a later accel reading.
  std::size_t pending() const { return gyro_.size(); }
  const RealsenseImuCombinerCounters& counters() const { return counters_; }

  /// A gyro reading waits for at most this many others before it takes the last accel as it is
  /// (an accel stream that stalled): 40 ms at 200 Hz.
  static constexpr std::size_t kMaxPending = 8;

 private:
  struct Reading {
    DeviceTime stamp;
    HostTime arrival;
    Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  };
  void release(const Reading& gyro, const Eigen::Vector3d& f_depth, bool held,
               std::vector<RealsenseImuSample>& out);
  Eigen::Vector3d accel_at(DeviceTime t) const;

  RealsenseImuMounting mounting_;
  std::deque<Reading> gyro_;
  /// the two newest accel readings (older first); valid per count
  Reading accel_[2];
  int accel_count_ = 0;
  bool have_gyro_stamp_ = false;
  DeviceTime last_gyro_stamp_;
  /// the last released rates in the IMU frame, for the angular acceleration
  bool have_w_ = false;
  Eigen::Vector3d last_w_ = Eigen::Vector3d::Zero();
  DeviceTime last_w_stamp_;
  Eigen::Vector3d alpha_ = Eigen::Vector3d::Zero();
  RealsenseImuCombinerCounters counters_;
};

}  // namespace posed::drivers::camera
