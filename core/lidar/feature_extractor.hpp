#pragma once
// Edge and planar features of one deskewed scan (LOAM, Zhang & Singh 2014; LeGO-LOAM, Shan &
// Englot 2018; seed 001's LiDAR preprocessing):
//  1. a range image, rings x azimuth bins (32 x ~1809 for a VLP-32C at 600 rpm);
//  2. ground: vertically adjacent pixels of the lower rings whose connecting vector is within
//     `ground_max_slope_deg` of horizontal;
//  3. along each ring, the smoothness of every pixel from its 5 neighbours either side: how far it
//     lies from their mean range, less 3 sigma of the range noise, over its range,
//     c = max(|sum(r_j - r_i)| / 10 - 3 sigma_r, 0) / r_i (scale-free, so near and far surfaces
//     are judged alike, and noise alone never makes an edge nor spoils a plane);
//  4. rejection of unreliable pixels: the far side of an occlusion (a range jump between
//     neighbours), beams nearly parallel to the surface (both neighbours far off in range), and
//     pixels next to gaps;
//  5. per ring, 6 sectors; in each, the sharpest non-ground pixels above `edge_threshold` become
//     edges (at most `edges_per_sector`, never two within 5 pixels), and every pixel below
//     `plane_threshold` (ground included) is a plane candidate, voxel-downsampled.

#include <array>
#include <cstdint>
#include <vector>

#include "core/lidar/scan_motion.hpp"
#include "core/work_splitter.hpp"

namespace posed::lidar {

struct FeatureConfig {
  int rows = 32;       ///< rings
  int columns = 1809;  ///< azimuth bins per turn
  /// rings below this index may be ground (the VLP-32C's horizon is near ring 20 of 32)
  int ground_rows = 20;
  double ground_max_slope_deg = 10.0;  ///< [deg]
  double edge_threshold = 0.005;       ///< smoothness above which a pixel may be an edge [-]
  double plane_threshold = 0.002;      ///< smoothness below which a pixel may be a plane [-]
  int edges_per_sector = 4;            ///< [1]
  int sectors = 6;                     ///< per ring [1]
  double occlusion_jump_m = 0.3;       ///< range jump that marks an occlusion [m]
  double parallel_beam_ratio = 0.02;   ///< both neighbours off by this fraction: grazing [-]
  double range_noise_m = 0.02;         ///< 1-sigma range noise of the sensor [m]
  double plane_voxel_m = 0.4;          ///< downsampling of planar features [m]
  double edge_voxel_m = 0.2;           ///< downsampling of edge features [m]
};

struct ScanFeatures {
  std::vector<Eigen::Vector3f> edges;   ///< lidar frame at the scan end [m]
  std::vector<Eigen::Vector3f> planes;  ///< lidar frame at the scan end [m]
  std::size_t ground_pixels = 0;        ///< pixels classified as ground [1]
  std::size_t valid_pixels = 0;         ///< pixels with a return [1]
  void clear() {
    edges.clear();
    planes.clear();
    ground_pixels = valid_pixels = 0;
  }
};

class FeatureExtractor {
 public:
  explicit FeatureExtractor(const FeatureConfig& config);
  /// Extracts the features of `points` into `out` (cleared first). Buffers are reused.
  void extract(const std::vector<ScanPoint>& points, ScanFeatures& out);
  const FeatureConfig& config() const { return config_; }
  /// Where the rings' steps 3-5 run in parts (null: here). The features are the same either way.
  void set_splitter(WorkSplitter* splitter) { splitter_ = splitter; }

 private:
  /// The rings are cut into this many parts, each with its own scratch and outputs, joined in
  /// ring order.
  static constexpr std::size_t kParts = 4;
  struct RingPart {
    // per ring: the valid pixels in column order
    std::vector<std::int32_t> ring_points;
    std::vector<float> smoothness;
    std::vector<std::uint8_t> excluded;
    std::vector<std::int32_t> order;
    std::vector<Eigen::Vector3f> edges, planes;  // of this part's rings, in ring order
  };
  /// Steps 3-5 for ring `r`, appending to `part`'s edges and planes.
  void ring_features(const std::vector<ScanPoint>& points, int r, RingPart& part) const;

  FeatureConfig config_;
  WorkSplitter* splitter_ = nullptr;
  // range image: point index per pixel, -1 = empty
  std::vector<std::int32_t> pixel_;
  std::vector<std::uint8_t> ground_;
  std::array<RingPart, kParts> parts_;
  std::array<std::vector<std::uint64_t>, 2> voxel_keys_;  // the planes', the edges'
};

/// Keeps one point per voxel of `voxel_m` (the one closest to the voxel's centre), in place.
/// `keys` is scratch (reused).
void voxel_downsample(std::vector<Eigen::Vector3f>& points, double voxel_m,
                      std::vector<std::uint64_t>& keys);

}  // namespace posed::lidar
