#pragma once
// Lidar depth for visual features, seed 000 §2.2.1 (Fig. 4, 5), after LVI-SAM (Shan et al. 2021):
// recent deskewed lidar points, stacked over several scans by the caller and given in the camera
// frame, go onto the unit sphere around the camera; a nearest-neighbour search over their polar
// coordinates finds the 3 nearest to each feature's bearing; the feature's depth is where its ray
// meets the plane of those 3 points. Stacking scans mixes points of different surfaces, so a
// feature is given no depth when its 3 points span more than `max_span_m` (2 m, seed 000).
//
// Definitions (seed 000 says "the largest distance between the 3 points"):
//  - polar coordinates of a point p = (x, y, z) in the camera frame (x right, y down, z forward):
//    azimuth atan2(x, z), elevation atan2(y, hypot(x, z)) [rad]; the search's 2-D keys.
//  - span (SpanMeasure::kMaxPairwiseDistance, default): max |P_i - P_j| over the 3 pairs [m], the
//    paper's definition. kRangeSpread, max |P_i| - min |P_i| [m], is LVI-SAM's code; it accepts
//    any triangle on a surface facing the camera however wide, so it is weaker at depth edges.
//  - depth: z of the intersection s b of the unit ray b with the plane, s = (n . P_1) / (n . b),
//    n = (P_2 - P_1) x (P_3 - P_1) [m]: the same depth the normalised coordinates (x/z, y/z) use.
// A spinning lidar samples 0.2 deg along a ring but 0.33-1.3 deg between rings, so the 3 nearest
// points often lie on one ring: collinear, no plane. Then the third point is the nearest of the
// next `candidates` that makes a proper triangle with the first two (LVI-SAM keeps the degenerate
// plane and clamps the intersection into the points' range interval, which invents a depth).
// Beyond seed 000 a feature also gets no depth when its points are further than
// `max_neighbour_angle_rad` from its bearing, collinear after all, seen edge-on, or when the
// intersection lies outside their range interval by more than `max_extrapolation_m`. The points
// are culled to the camera's field of view and thinned to the nearest point per `cell_rad` cell
// of a polar grid (LVI-SAM does the same), so nearer surfaces hide the ones behind them.
//
// The search walks that grid's cells in square rings around the bearing's cell (LVI-SAM and an
// earlier posed built a kd-tree over the points for each frame; for the few hundred features of
// a frame the tree's build cost more than all the searches) and gives exactly the tree's answer:
// the nearest keys by the same float distance, up to the radius beyond which no point can lie
// within `max_neighbour_angle_rad` of the bearing.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "core/vision/pinhole_camera.hpp"

namespace posed::vision {

enum class SpanMeasure { kMaxPairwiseDistance, kRangeSpread };

struct DepthConfig {
  double max_span_m = 2.0;  ///< seed 000's rejection [m]
  SpanMeasure span = SpanMeasure::kMaxPairwiseDistance;
  double max_neighbour_angle_rad = 0.0436;  ///< 2.5 deg, LVI-SAM's search radius [rad]
  double cell_rad = 0.0044;                 ///< polar grid thinning, 0.25 deg [rad]
  double fov_margin_rad = 0.05;             ///< kept around the image's field of view [rad]
  double min_range_m = 0.5;                 ///< nearer points are ignored (the robot) [m]
  double max_range_m = 120.0;               ///< further points are ignored [m]
  double max_extrapolation_m = 0.5;         ///< intersection beyond the 3 ranges [m]
  double min_triangle_shape = 0.05;         ///< 2 area / longest side^2; below: collinear [-]
  int candidates = 16;                ///< neighbours searched for a non-collinear third point [1]
  double min_incidence_rad = 0.0873;  ///< 5 deg; ray closer to the plane: edge-on [rad]
};

enum class DepthStatus : std::uint8_t {
  kOk,
  kNoPoints,      ///< fewer than 3 points in the tree
  kTooFar,        ///< a neighbour beyond max_neighbour_angle_rad
  kSpan,          ///< the 3 points span more than max_span_m
  kDegenerate,    ///< collinear points, or the ray nearly in their plane
  kOutsideRange,  ///< the intersection is off the 3 points' range interval
};

struct DepthResult {
  double depth_m = std::numeric_limits<double>::quiet_NaN();  ///< z in the camera frame [m]
  DepthStatus status = DepthStatus::kNoPoints;
  double span_m = std::numeric_limits<double>::quiet_NaN();  ///< the measure used [m]
};

class DepthAssociator {
 public:
  /// `camera`: the image whose features will be asked for (its field of view bounds the cloud).
  DepthAssociator(const DepthConfig& config, const PinholeCamera& camera);
  ~DepthAssociator();
  DepthAssociator(const DepthAssociator&) = delete;
  DepthAssociator& operator=(const DepthAssociator&) = delete;

  /// Replaces the cloud: `p_cam_m` in the camera frame at the image's stamp [m]. Builds the tree.
  void set_points(std::span<const Eigen::Vector3f> p_cam_m);

  /// Depth of the feature at normalised undistorted coordinates (x/z, y/z).
  DepthResult depth(const Eigen::Vector2d& normalised) const;

  /// Points kept after culling and thinning [1].
  std::size_t tree_points() const { return points_.size(); }

  /// The kept points' polar keys (azimuth, elevation) [rad], in the order nearest() indexes.
  const std::vector<Eigen::Vector2f>& keys() const { return polar_; }

  /// The `wanted` points whose polar keys (azimuth, elevation) lie nearest `key` and within
  /// `max_key_distance_rad` of it, nearest first (ties: the earlier point), as indices into the
  /// kept points with their squared key distances [rad^2]; returns how many were found.
  std::size_t nearest(const Eigen::Vector2f& key, double max_key_distance_rad, std::size_t wanted,
                      std::uint32_t* index, float* distance_sq) const;

 private:
  DepthConfig config_;
  double azimuth_min_ = 0, azimuth_max_ = 0, elevation_min_ = 0, elevation_max_ = 0;
  // Normalised-plane bounds for the cheap first cull (before any trigonometry).
  double x_min_ = 0, x_max_ = 0, y_min_ = 0, y_max_ = 0;
  // depth()'s search radius: cos of the grid's largest |elevation|, sin(max_neighbour_angle / 2)
  double cos_elevation_bound_ = 1, sin_half_neighbour_angle_ = 0;
  int cells_x_ = 0, cells_y_ = 0;
  // per polar cell: index into candidates_ while thinning, then into points_; -1 = empty
  std::vector<std::int32_t> cell_best_;
  std::vector<float> cell_range_;
  std::vector<Eigen::Vector3f> candidates_;
  std::vector<Eigen::Vector2f> candidate_polar_;
  std::vector<Eigen::Vector3f> points_;  // kept, in cell order
  std::vector<Eigen::Vector2f> polar_;   // their keys (azimuth, elevation) [rad]
};

}  // namespace posed::vision
