#include "core/vision/thermal_aligner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace posed::vision {
namespace {

// Map value for a visible pixel with no thermal source: far enough outside the frame that
// bilinear interpolation reads only the constant border.
constexpr float kOutside = -16.f;
// A ray with less depth than this (in units of the plane depth, or at infinity in units of the
// normalised ray) misses the thermal image plane.
constexpr float kMinDepth = 1e-3f;

}  // namespace

ThermalAligner::ThermalAligner(const PinholeCamera& visible, const PinholeCamera& thermal,
                               const Eigen::Isometry3d& T_cam_thermal,
                               const ThermalAlignConfig& config)
    : visible_(visible),
      thermal_(thermal),
      T_cam_thermal_(T_cam_thermal),
      config_(config),
      crop_(vision::fov_crop(thermal, visible)),
      normalizer_(config.normalize) {
  CV_Assert(visible.valid() && thermal.valid());
  ray_x_.create(visible.height, visible.width, CV_32FC1);
  ray_y_.create(visible.height, visible.width, CV_32FC1);
  for (int r = 0; r < visible.height; ++r) {
    float* rx = ray_x_.ptr<float>(r);
    float* ry = ray_y_.ptr<float>(r);
    for (int c = 0; c < visible.width; ++c) {
      Eigen::Vector2d xy;
      if (config_.mode == AlignMode::kFovCrop) {
        // Eq. (6) crop resampled to the visible size: the visible image's extent [-0.5, W - 0.5]
        // onto the crop's [left, left + X'] in undistorted thermal pixels, then normalised.
        const double u = crop_.left_px + (c + 0.5) * crop_.width_px / visible.width;
        const double v = crop_.top_px + (r + 0.5) * crop_.height_px / visible.height;
        xy = {(u - thermal.cx) / thermal.fx, (v - thermal.cy) / thermal.fy};
      } else if (!visible.normalised_from_pixel(Eigen::Vector2d(c, r), xy)) {
        xy = {1e6, 1e6};  // beyond any lens's model: the map marks it invalid
      }
      rx[c] = static_cast<float>(xy.x());
      ry[c] = static_cast<float>(xy.y());
    }
  }
  map_x_.create(visible.height, visible.width, CV_32FC1);
  map_y_.create(visible.height, visible.width, CV_32FC1);
  valid_.create(visible.height, visible.width, CV_8UC1);
  ones_.assign(static_cast<std::size_t>(visible.width), 1.f);
  if (config_.mode == AlignMode::kLidarDepth) init_depth_grid();

  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  total_transform(Eigen::Matrix3d::Identity(), R, t, true);
  compute_map(R.cast<float>(), t.cast<float>());
  cv::convertMaps(map_x_, map_y_, static_map_xy_, static_map_frac_, CV_16SC2);
  static_valid_ = valid_.clone();
  static_invalid_ = invalid_;
  double x_lo = thermal.width, x_hi = -1, y_lo = thermal.height, y_hi = -1;
  for (int r = 0; r < map_x_.rows; ++r) {
    for (int c = 0; c < map_x_.cols; ++c) {
      if (valid_.at<std::uint8_t>(r, c) == 0) continue;
      x_lo = std::min(x_lo, static_cast<double>(map_x_.at<float>(r, c)));
      x_hi = std::max(x_hi, static_cast<double>(map_x_.at<float>(r, c)));
      y_lo = std::min(y_lo, static_cast<double>(map_y_.at<float>(r, c)));
      y_hi = std::max(y_hi, static_cast<double>(map_y_.at<float>(r, c)));
    }
  }
  if (x_hi >= x_lo && y_hi >= y_lo) {
    const int x0 = static_cast<int>(std::floor(x_lo)), y0 = static_cast<int>(std::floor(y_lo));
    const int x1 = std::min(thermal.width, static_cast<int>(std::ceil(x_hi)) + 1);
    const int y1 = std::min(thermal.height, static_cast<int>(std::ceil(y_hi)) + 1);
    source_roi_ = cv::Rect(x0, y0, x1 - x0, y1 - y0);
  }
}

void ThermalAligner::init_depth_grid() {
  // The grid spans the rays the visible pixels see, in undistorted normalised coordinates, so
  // that a point is binned by two divisions (no distortion model per point).
  float x_lo = 1e9f, x_hi = -1e9f, y_lo = 1e9f, y_hi = -1e9f;
  for (int r = 0; r < ray_x_.rows; ++r) {
    const float* rx = ray_x_.ptr<float>(r);
    const float* ry = ray_y_.ptr<float>(r);
    for (int c = 0; c < ray_x_.cols; ++c) {
      if (rx[c] > 1e5f) continue;  // beyond the lens model
      x_lo = std::min(x_lo, rx[c]);
      x_hi = std::max(x_hi, rx[c]);
      y_lo = std::min(y_lo, ry[c]);
      y_hi = std::max(y_hi, ry[c]);
    }
  }
  const int cols = std::max(1, config_.depth_grid_cols);
  const int rows = std::max(1, config_.depth_grid_rows);
  grid_x0_ = x_lo;
  grid_y0_ = y_lo;
  grid_cells_per_x_ = static_cast<float>(cols) / std::max(x_hi - x_lo, 1e-6f);
  grid_cells_per_y_ = static_cast<float>(rows) / std::max(y_hi - y_lo, 1e-6f);
  depth_grid_.create(rows, cols, CV_32FC1);
  depth_grid_next_.create(rows, cols, CV_32FC1);
  // Each pixel's position in the grid, cell centres at integers, for one remap per frame.
  cv::Mat gx(ray_x_.size(), CV_32FC1), gy(ray_x_.size(), CV_32FC1);
  for (int r = 0; r < ray_x_.rows; ++r) {
    for (int c = 0; c < ray_x_.cols; ++c) {
      const float x = ray_x_.at<float>(r, c), y = ray_y_.at<float>(r, c);
      gx.at<float>(r, c) = x > 1e5f ? 0.f : (x - grid_x0_) * grid_cells_per_x_ - 0.5f;
      gy.at<float>(r, c) = x > 1e5f ? 0.f : (y - grid_y0_) * grid_cells_per_y_ - 0.5f;
    }
  }
  cv::convertMaps(gx, gy, grid_map_xy_, grid_map_frac_, CV_16SC2);
}

bool ThermalAligner::build_depth(std::span<const Eigen::Vector3f> p_cam_m, AlignStats& stats) {
  const int cols = depth_grid_.cols, rows = depth_grid_.rows;
  constexpr float kEmpty = -1.f;
  depth_grid_.setTo(kEmpty);
  const std::size_t stride =
      std::max<std::size_t>(1, (p_cam_m.size() + config_.depth_max_points - 1) /
                                   std::max<std::size_t>(1, config_.depth_max_points));
  const float min_z = static_cast<float>(config_.depth_min_m);
  for (std::size_t i = 0; i < p_cam_m.size(); i += stride) {
    const Eigen::Vector3f& p = p_cam_m[i];
    if (!(p.z() >= min_z)) continue;
    const float w = 1.f / p.z();
    const float gx = (p.x() * w - grid_x0_) * grid_cells_per_x_;
    const float gy = (p.y() * w - grid_y0_) * grid_cells_per_y_;
    if (!(gx >= 0.f && gx < static_cast<float>(cols) && gy >= 0.f &&
          gy < static_cast<float>(rows))) {
      continue;
    }
    // The nearest point per cell (largest inverse depth): a surface hides what is behind it.
    float& cell = depth_grid_.at<float>(static_cast<int>(gy), static_cast<int>(gx));
    cell = std::max(cell, w);
  }
  int filled = 0;
  for (int r = 0; r < rows; ++r) {
    const float* g = depth_grid_.ptr<float>(r);
    for (int c = 0; c < cols; ++c) filled += g[c] >= 0.f ? 1 : 0;
  }
  stats.depth_cells = filled;
  if (filled == 0) return false;
  // Rings of empty cells take the mean of their filled 8-neighbours (the rings between a
  // spinning lidar's scan lines, the shadows behind near objects); the rest is at infinity.
  for (int ring = 0; ring < config_.depth_fill_cells; ++ring) {
    depth_grid_.copyTo(depth_grid_next_);
    int added = 0;
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        if (depth_grid_.at<float>(r, c) >= 0.f) continue;
        float sum = 0.f;
        int n = 0;
        for (int dr = -1; dr <= 1; ++dr) {
          for (int dc = -1; dc <= 1; ++dc) {
            const int rr = r + dr, cc = c + dc;
            if (rr < 0 || rr >= rows || cc < 0 || cc >= cols) continue;
            const float v = depth_grid_.at<float>(rr, cc);
            if (v >= 0.f) {
              sum += v;
              ++n;
            }
          }
        }
        if (n > 0) {
          depth_grid_next_.at<float>(r, c) = sum / static_cast<float>(n);
          ++added;
        }
      }
    }
    cv::swap(depth_grid_, depth_grid_next_);
    stats.depth_filled_cells += added;
    if (added == 0) break;
  }
  cv::max(depth_grid_, 0.f, depth_grid_);  // still empty: infinity
  cv::remap(depth_grid_, inverse_depth_, grid_map_xy_, grid_map_frac_, cv::INTER_LINEAR,
            cv::BORDER_REPLICATE);
  return true;
}

void ThermalAligner::native_grey(const cv::Mat& thermal, const AlignStats& stats,
                                 cv::Mat& grey) const {
  const cv::Mat roi = thermal(source_roi_);
  if (thermal.type() == CV_8UC1) {
    grey = roi;
    return;
  }
  const double span = std::max(1, stats.normalize.high_counts - stats.normalize.low_counts);
  roi.convertTo(grey, CV_8U, 255.0 / span, -255.0 * stats.normalize.low_counts / span);
}

void ThermalAligner::total_transform(const Eigen::Matrix3d& R_camtv_camtt, Eigen::Matrix3d& R,
                                     Eigen::Vector3d& t_over_depth, bool for_static) const {
  if (config_.mode == AlignMode::kFovCrop) {  // rays are already in the thermal frame
    R.setIdentity();
    t_over_depth.setZero();
    return;
  }
  // Direction b in the camera at the visible stamp -> camera at the thermal stamp (R^T b) ->
  // thermal frame (R_thermal_cam). A point on the plane is d (x, y, 1): in the thermal frame
  // d R (x, y, 1) + t_thermal_cam, which projects like R (x, y, 1) + t_thermal_cam / d. The
  // camera's translation between the stamps is neglected (millimetres against metres).
  const Eigen::Matrix3d R_thermal_cam = T_cam_thermal_.linear().transpose();
  R = R_thermal_cam * R_camtv_camtt.transpose();
  if (config_.mode == AlignMode::kPlane && config_.plane_depth_m > 0) {
    t_over_depth = -(R_thermal_cam * T_cam_thermal_.translation()) / config_.plane_depth_m;
  } else if (config_.mode == AlignMode::kLidarDepth && depth_valid_ && !for_static) {
    // Unscaled: compute_map multiplies it by each pixel's inverse depth.
    t_over_depth = -(R_thermal_cam * T_cam_thermal_.translation());
  } else {
    t_over_depth.setZero();
  }
}

void ThermalAligner::compute_map(const Eigen::Matrix3f& R, const Eigen::Vector3f& t,
                                 const cv::Mat* inverse_depth) {
  const float r00 = R(0, 0), r01 = R(0, 1), r02 = R(0, 2);
  const float r10 = R(1, 0), r11 = R(1, 1), r12 = R(1, 2);
  const float r20 = R(2, 0), r21 = R(2, 1), r22 = R(2, 2);
  const float tx = t.x(), ty = t.y(), tz = t.z();
  const float fx = static_cast<float>(thermal_.fx), fy = static_cast<float>(thermal_.fy);
  const float cx = static_cast<float>(thermal_.cx), cy = static_cast<float>(thermal_.cy);
  const float k1 = static_cast<float>(thermal_.k1), k2 = static_cast<float>(thermal_.k2);
  const float p1 = static_cast<float>(thermal_.p1), p2 = static_cast<float>(thermal_.p2);
  const float max_u = static_cast<float>(thermal_.width - 1);
  const float max_v = static_cast<float>(thermal_.height - 1);
  // Without a per-pixel depth, the translation (already divided by the plane depth, or zero)
  // applies with weight 1 everywhere.
  int invalid = 0;
  const int cols = ray_x_.cols;  // a local: the loops' trip count must not depend on stores
  for (int r = 0; r < ray_x_.rows; ++r) {
    const float* rx = ray_x_.ptr<float>(r);
    const float* ry = ray_y_.ptr<float>(r);
    const float* w = inverse_depth == nullptr ? ones_.data() : inverse_depth->ptr<float>(r);
    float* mx = map_x_.ptr<float>(r);
    float* my = map_y_.ptr<float>(r);
    std::uint8_t* ok = valid_.ptr<std::uint8_t>(r);
    // Branch-free so that the compiler vectorises it: (x, y, 1) rotated + t w, projected,
    // distorted (radial-tangential), scaled; misses are selected out at the end.
    for (int c = 0; c < cols; ++c) {
      const float X = r00 * rx[c] + r01 * ry[c] + r02 + tx * w[c];
      const float Y = r10 * rx[c] + r11 * ry[c] + r12 + ty * w[c];
      const float Z = r20 * rx[c] + r21 * ry[c] + r22 + tz * w[c];
      const bool in_front = Z > kMinDepth;
      const float inv_z = 1.f / (in_front ? Z : 1.f);
      const float x = X * inv_z, y = Y * inv_z;
      const float r2 = x * x + y * y;
      const float radial = 1.f + r2 * (k1 + k2 * r2);
      const float xd = x * radial + 2.f * p1 * x * y + p2 * (r2 + 2.f * x * x);
      const float yd = y * radial + p1 * (r2 + 2.f * y * y) + 2.f * p2 * x * y;
      const float u = fx * xd + cx, v = fy * yd + cy;
      // & rather than &&: no short-circuit branches in the loop body.
      const bool inside = in_front & (u >= 0.f) & (u <= max_u) & (v >= 0.f) & (v <= max_v);
      mx[c] = inside ? u : kOutside;
      my[c] = inside ? v : kOutside;
    }
    for (int c = 0; c < cols; ++c) {
      ok[c] = mx[c] >= 0.f ? 255 : 0;
      invalid += mx[c] >= 0.f ? 0 : 1;
    }
  }
  invalid_ = invalid;
}

bool ThermalAligner::thermal_pixel(const Eigen::Vector2d& visible_px,
                                   const Eigen::Matrix3d& R_camtv_camtt,
                                   Eigen::Vector2d& thermal_px) const {
  Eigen::Vector2d xy;
  if (config_.mode == AlignMode::kFovCrop) {
    const double u = crop_.left_px + (visible_px.x() + 0.5) * crop_.width_px / visible_.width;
    const double v = crop_.top_px + (visible_px.y() + 0.5) * crop_.height_px / visible_.height;
    xy = {(u - thermal_.cx) / thermal_.fx, (v - thermal_.cy) / thermal_.fy};
  } else if (!visible_.normalised_from_pixel(visible_px, xy)) {
    return false;
  }
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  total_transform(R_camtv_camtt, R, t);
  double w = 1.0;
  if (config_.mode == AlignMode::kLidarDepth && depth_valid_) {
    // The grid interpolated as the map's remap does (bilinear, edges replicated).
    const double gx = std::clamp((xy.x() - grid_x0_) * grid_cells_per_x_ - 0.5, 0.0,
                                 static_cast<double>(depth_grid_.cols - 1));
    const double gy = std::clamp((xy.y() - grid_y0_) * grid_cells_per_y_ - 0.5, 0.0,
                                 static_cast<double>(depth_grid_.rows - 1));
    const int c0 = std::min(static_cast<int>(gx), depth_grid_.cols - 1);
    const int r0 = std::min(static_cast<int>(gy), depth_grid_.rows - 1);
    const int c1 = std::min(c0 + 1, depth_grid_.cols - 1);
    const int r1 = std::min(r0 + 1, depth_grid_.rows - 1);
    const double a = gx - c0, b = gy - r0;
    const auto g = [&](int r, int c) { return static_cast<double>(depth_grid_.at<float>(r, c)); };
    w = (1 - b) * ((1 - a) * g(r0, c0) + a * g(r0, c1)) + b * ((1 - a) * g(r1, c0) + a * g(r1, c1));
  }
  const Eigen::Vector3d p = R * Eigen::Vector3d(xy.x(), xy.y(), 1.0) + w * t;
  return thermal_.project(p, thermal_px);
}

bool ThermalAligner::align(const cv::Mat& thermal, const Eigen::Matrix3d& R_camtv_camtt,
                           cv::Mat& aligned, AlignStats& stats,
                           std::span<const Eigen::Vector3f> p_cam_m) {
  stats = {};
  if (thermal.cols != thermal_.width || thermal.rows != thermal_.height ||
      (thermal.type() != CV_8UC1 && thermal.type() != CV_16UC1)) {
    return false;
  }
  stats.rotation_rad = Eigen::AngleAxisd(R_camtv_camtt).angle();
  const double motion_px = stats.rotation_rad * std::max(visible_.fx, visible_.fy);
  const bool compensate = config_.mode != AlignMode::kFovCrop && config_.rotation_compensation &&
                          motion_px >= config_.min_compensation_px;
  depth_valid_ = config_.mode == AlignMode::kLidarDepth && build_depth(p_cam_m, stats);
  if (!depth_valid_) inverse_depth_.release();
  const cv::Mat* valid = &static_valid_;
  if (compensate || depth_valid_) {
    Eigen::Matrix3d R;
    Eigen::Vector3d t;
    total_transform(compensate ? R_camtv_camtt : Eigen::Matrix3d::Identity(), R, t);
    compute_map(R.cast<float>(), t.cast<float>(), depth_valid_ ? &inverse_depth_ : nullptr);
    // Fixed point for cv::remap: it would convert float maps block by block anyway, slower.
    cv::convertMaps(map_x_, map_y_, map_xy_, map_frac_, CV_16SC2);
    valid = &valid_;
    stats.invalid_pixels = invalid_;
  } else {
    static_valid_.copyTo(valid_);
    stats.invalid_pixels = static_invalid_;
  }
  stats.rotation_compensated = compensate;
  const bool dynamic = compensate || depth_valid_;

  const auto remap = [&](const cv::Mat& src, cv::Mat& dst) {
    if (dynamic) {
      cv::remap(src, dst, map_xy_, map_frac_, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
    } else {
      cv::remap(src, dst, static_map_xy_, static_map_frac_, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                cv::Scalar(0));
    }
  };
  if (thermal.type() == CV_8UC1) {
    remap(thermal, aligned);
  } else {
    remap(thermal, remapped_counts_);
    stats.normalize = normalizer_.normalize(remapped_counts_, *valid, aligned);
    stats.normalized = true;
  }
  return true;
}

}  // namespace posed::vision
