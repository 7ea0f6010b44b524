#pragma once
// Files a run's map is exported to (posed --save-map, posectl export --pcd):
//  - the point cloud as PCD v0.7 (pointclouds.org "The PCD file format"), binary, fields x y z
//    float32 in the map frame [m]: PCL, CloudCompare, Open3D and RViz tools read it;
//  - the keyframe poses as a TUM trajectory (`stamp tx ty tz qx qy qz qw`, stamp [s] on the wall
//    clock exactly as posed stamps its DDS poses, position [m]), the format `posectl eval` and evo
//    read, so keyframes line up with poses captured over DDS and with a simulator's ground truth.
// Both are written to a temporary name and renamed into place, so a crash never leaves a
// half-written file under the final name.

#include <Eigen/Geometry>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "core/time.hpp"

namespace posed::drivers::recording {

struct StampedTransform {
  WallTime stamp;
  Eigen::Isometry3d T;
};

/// Writes `path` through `path.tmp` and a rename: `body` writes the content and says whether it
/// succeeded. False with `error` naming the file and the failing step.
bool write_atomically(const std::string& path, std::string& error,
                      const std::function<bool(std::FILE*)>& body);

/// One TUM line (with '\n') for a pose at `stamp_ns`.
std::string tum_line(std::int64_t stamp_ns, const Eigen::Vector3d& p_m,
                     const Eigen::Quaterniond& q);

/// False with `error` naming the file and the failing step.
bool write_pcd(const std::string& path, const std::vector<Eigen::Vector3f>& points_m,
               std::string& error);
bool write_tum(const std::string& path, const std::vector<StampedTransform>& poses,
               std::string& error);

}  // namespace posed::drivers::recording
