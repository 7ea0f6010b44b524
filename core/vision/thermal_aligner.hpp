#pragma once
// Thermal preprocessing of seed 000 §2.1.1 and the pairing compensation of issue 9, as one
// cv::remap per frame from the raw thermal frame to the visible camera's pixel grid:
//   raw thermal (640x512, distorted; 8-bit AGC'd or 16-bit counts)
//     -> undistortion with the thermal intrinsics
//     -> FOV compensation (eq. 1-6: only what the visible camera sees)
//     -> resampling to the visible resolution
//     -> registration by T_cam_thermal
//     -> rotation of the camera between the thermal and the visible stamp
//   -> 8-bit thermal image registered to the (distorted) visible image, ready for DWT fusion.
//
// Every step is a change of coordinates, so they compose into one map: for each visible pixel,
// its undistorted bearing (precomputed once from the visible intrinsics), rotated by the
// extrinsic and the inter-stamp rotation, projected and distorted by the thermal intrinsics.
// Nothing is interpolated twice. Where depth is unknown the registration is the homography at
// infinity K_t R_thermal_cam K_v^-1 (exact for distant points; the 0.17 m baseline of the M2DGR
// rig misplaces a point at depth z by f b / z: 0.5 px at 150 m ... 10 px at 7.5 m); kPlane
// registers a fronto-parallel plane at `plane_depth_m` instead. kLidarDepth registers each
// visible pixel at the depth the lidar gives its direction: the points (visible camera frame)
// are binned into a coarse grid over the undistorted normalised image plane, each cell keeping
// its nearest point's inverse depth (a surface hides what is behind it); empty cells take the
// mean of their filled neighbours for `depth_fill_cells` rings, and what stays empty is at
// infinity (sky, or no points at all). The grid is interpolated bilinearly in inverse depth to
// every pixel (through a precomputed remap) and the map recomputed: a pixel of inverse depth w
// samples the thermal pixel of R (x, y, 1) + w t_thermal_cam. kFovCrop is the paper's own
// method: a centred crop of eq. (6) size, scaled to the visible size, ignoring the principal
// point offset, the extrinsic rotation and the inter-stamp rotation (kept for comparison).
//
// When the inter-stamp rotation is negligible (below `min_compensation_px` of image motion) a
// precomputed fixed-point map is used; otherwise the map is recomputed (a vectorisable loop over
// the precomputed bearings), which is cheaper than composing a cached map with a homography.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <opencv2/core/mat.hpp>
#include <span>
#include <vector>

#include "core/vision/fov_compensation.hpp"
#include "core/vision/pinhole_camera.hpp"
#include "core/vision/thermal_normalizer.hpp"

namespace posed::vision {

enum class AlignMode {
  kInfiniteHomography,  ///< K_t R K_v^-1 through both distortion models (default)
  kPlane,               ///< points on the plane z = plane_depth_m of the visible camera
  kFovCrop,             ///< seed 000 as published: centred eq. (6) crop, scaled; no rotation
  kLidarDepth,          ///< per-pixel depth from the lidar points (coarse grid), else infinity
};

struct ThermalAlignConfig {
  AlignMode mode = AlignMode::kInfiniteHomography;
  double plane_depth_m = 10.0;        ///< kPlane only [m]
  bool rotation_compensation = true;  ///< warp by the inter-stamp rotation
  double min_compensation_px = 0.1;   ///< smaller rotations are ignored [px of image motion]
  int depth_grid_cols = 40;           ///< kLidarDepth: grid cells across the image [1]
  int depth_grid_rows = 30;           ///< kLidarDepth: grid cells down the image [1]
  int depth_fill_cells = 2;           ///< kLidarDepth: empty cells filled this many rings out [1]
  double depth_min_m = 0.5;           ///< kLidarDepth: nearer points are ignored (the robot) [m]
  std::size_t depth_max_points = 60000;  ///< kLidarDepth: more are subsampled evenly [1]
  ThermalNormalizeConfig normalize;      ///< for 16-bit frames
};

/// What one alignment did.
struct AlignStats {
  bool rotation_compensated = false;  ///< the inter-stamp rotation was applied
  double rotation_rad = 0;            ///< angle of the inter-stamp rotation [rad]
  int invalid_pixels = 0;             ///< visible pixels whose source is outside the thermal frame
  bool normalized = false;            ///< the frame was 16-bit and was normalised
  int depth_cells = 0;                ///< kLidarDepth: grid cells with a lidar point [1]
  int depth_filled_cells = 0;         ///< kLidarDepth: of the others, filled from neighbours [1]
  ThermalNormalizeStats normalize;    ///< when normalised
};

class ThermalAligner {
 public:
  /// `T_cam_thermal`: the thermal camera's pose in the visible camera frame (p_cam =
  /// T_cam_thermal p_thermal), as `extrinsics.T_cam_thermal` in the config.
  ThermalAligner(const PinholeCamera& visible, const PinholeCamera& thermal,
                 const Eigen::Isometry3d& T_cam_thermal, const ThermalAlignConfig& config);

  /// `thermal` (CV_8UC1 or CV_16UC1, the thermal camera's size) -> `aligned` (CV_8UC1, the
  /// visible camera's size). `R_camtv_camtt` rotates directions from the camera frame at the
  /// thermal stamp into the camera frame at the visible stamp (identity: no motion); from the IMU,
  /// R_imu_cam^T R_world_imu(t_visible)^T R_world_imu(t_thermal) R_imu_cam. False (and `aligned`
  /// untouched) when the frame's size or type is wrong. `p_cam_m`: lidar points in the visible
  /// camera frame at the visible stamp [m], used by kLidarDepth (empty: infinity everywhere).
  bool align(const cv::Mat& thermal, const Eigen::Matrix3d& R_camtv_camtt, cv::Mat& aligned,
             AlignStats& stats, std::span<const Eigen::Vector3f> p_cam_m = {});

  /// Non-zero where the last aligned image has a thermal source pixel (CV_8UC1, visible size).
  const cv::Mat& valid_mask() const { return valid_; }

  /// The raw thermal pixel a visible pixel samples (the same arithmetic as the map, in double;
  /// kLidarDepth: at the last align()'s depth grid, interpolated as in the map). False when the
  /// ray misses the thermal image plane.
  bool thermal_pixel(const Eigen::Vector2d& visible_px, const Eigen::Matrix3d& R_camtv_camtt,
                     Eigen::Vector2d& thermal_px) const;

  /// The raw thermal pixels the visible image samples (bounding box of the static map), in the
  /// thermal frame.
  const cv::Rect& source_roi() const { return source_roi_; }

  /// That region of `thermal` at its native resolution as 8-bit grey, for measurements that
  /// resampling would bias (image noise, see image_quality.hpp): a view for 8-bit frames, or
  /// the 16-bit counts through the stretch `stats` reports for the last align().
  void native_grey(const cv::Mat& thermal, const AlignStats& stats, cv::Mat& grey) const;

  /// The eq. (6) crop (kFovCrop's region, reported for every mode).
  const FovCrop& fov_crop() const { return crop_; }
  /// kLidarDepth: the last align()'s inverse depth per visible pixel [1/m] (0: infinity);
  /// empty in the other modes.
  const cv::Mat& inverse_depth() const { return inverse_depth_; }
  const ThermalAlignConfig& config() const { return config_; }

 private:
  /// Fills map_x_/map_y_/valid_ for a rotation (thermal frame from visible camera frame) and
  /// translation (thermal frame, divided by the plane depth; zero at infinity), or with
  /// `inverse_depth` (CV_32FC1, visible size) the translation times each pixel's inverse depth.
  void compute_map(const Eigen::Matrix3f& R_thermal_ray, const Eigen::Vector3f& t_thermal_scaled,
                   const cv::Mat* inverse_depth = nullptr);
  /// kLidarDepth: bins the points into depth_grid_ and interpolates it into inverse_depth_.
  /// False when no point falls into the grid.
  bool build_depth(std::span<const Eigen::Vector3f> p_cam_m, AlignStats& stats);
  /// kLidarDepth with a depth grid (and not `for_static`): `t_over_depth` is the translation
  /// itself, to be scaled by each pixel's inverse depth.
  void total_transform(const Eigen::Matrix3d& R_camtv_camtt, Eigen::Matrix3d& R,
                       Eigen::Vector3d& t_over_depth, bool for_static = false) const;
  void init_depth_grid();

  PinholeCamera visible_, thermal_;
  Eigen::Isometry3d T_cam_thermal_;
  ThermalAlignConfig config_;
  FovCrop crop_;
  // Per visible pixel (row-major, visible size): the ray that pixel sees, as (x, y, 1): the
  // undistorted normalised visible coordinates, or for kFovCrop the undistorted normalised
  // thermal coordinates of the crop.
  cv::Mat ray_x_, ray_y_;  // CV_32FC1
  // The current map (float), its fixed-point form for the static case, and validity.
  cv::Mat map_x_, map_y_, map_xy_, map_frac_, valid_;
  cv::Mat static_map_xy_, static_map_frac_, static_valid_;
  int static_invalid_ = 0;
  cv::Rect source_roi_;
  int invalid_ = 0;
  cv::Mat remapped_counts_;
  // kLidarDepth: grid extent in normalised coordinates, the grid (inverse depth [1/m], CV_32FC1),
  // its fill buffers, the fixed-point map from visible pixels to grid coordinates, and the
  // interpolated inverse depth per visible pixel.
  float grid_x0_ = 0, grid_y0_ = 0, grid_cells_per_x_ = 1, grid_cells_per_y_ = 1;
  cv::Mat depth_grid_, depth_grid_next_, grid_map_xy_, grid_map_frac_, inverse_depth_;
  bool depth_valid_ = false;  // the last align() registered by depth
  std::vector<float> ones_;   // inverse depth 1 per pixel: the translation applies unscaled
  ThermalNormalizer normalizer_;
};

}  // namespace posed::vision
