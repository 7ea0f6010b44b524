#pragma once
// The lidar points the camera front end associates depth with (seed 000 §2.2.1: "to get denser
// depth, several lidar frames are stacked"): the deskewed points of the scans matched in the
// last `window`, kept in the map frame at their matched poses, and handed out in a camera's
// frame at a frame's stamp. Only points in front of the camera are kept (the rest can never
// project into the image), thinned evenly to a bound per scan so the cost per frame is fixed.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <deque>
#include <span>
#include <vector>

#include "core/lidar/scan_motion.hpp"
#include "core/time.hpp"

namespace posed::fusion {

struct DepthCloudConfig {
  /// scans older than this before the frame are dropped [ns]
  Duration window = Duration::from_ms(1000);
  /// points kept per scan after the half-space cut, evenly strided [1]
  std::size_t max_points_per_scan = 20'000;
  /// the camera's optical axis in the lidar frame: points behind the lidar's plane across it
  /// are dropped (the visible camera looks forward) [unit vector]
  Eigen::Vector3d view_axis_lidar = Eigen::Vector3d::UnitX();
};

class DepthCloud {
 public:
  explicit DepthCloud(const DepthCloudConfig& config);

  /// A matched scan: points in the lidar frame at `stamp`, the lidar's pose then.
  void add_scan(HostTime stamp, const Eigen::Isometry3d& T_map_lidar,
                std::span<const lidar::ScanPoint> points_lidar);
  /// The points of the scans within the window before `t`, in the frame `T_map_cam` (the
  /// camera's pose at `t`), into `out` (cleared first) [m]. Scans older than the window go.
  void points_in_camera(HostTime t, const Eigen::Isometry3d& T_map_cam,
                        std::vector<Eigen::Vector3f>& out);
  /// scans held [1]
  std::size_t scans() const { return scans_.size(); }

 private:
  struct Scan {
    HostTime stamp;
    std::vector<Eigen::Vector3f> p_map_m;
  };
  DepthCloudConfig config_;
  std::deque<Scan> scans_;
  std::vector<std::vector<Eigen::Vector3f>> spare_;  // buffers of dropped scans, reused
};

}  // namespace posed::fusion
