#pragma once
// Scan-to-map registration (LOAM's mapping step, seed 000 §2.3, seed 001's point-to-line and
// point-to-plane with an IMU prior): the pose T_map_lidar that puts the scan's edge points on the
// map's lines and its planar points on the map's planes, by Gauss-Newton on SE(3) from the IMU
// prediction, correspondences refound each iteration, a Cauchy kernel against outliers.
//
// Degeneracy (Zhang, Kaess & Singh 2016, "On degeneracy of optimization-based state estimation";
// seed 000 eq. 13): the eigenvalues of the normal matrix JᵀJ at the prediction say how well each
// direction of the pose is constrained. Directions below a threshold are degenerate (a
// corridor's axis, an open field's height): every update is projected onto the well-constrained
// subspace ("solution remapping"), so along degenerate directions the pose stays the
// prediction, and the returned information is zero there, so the back end trusts the IMU.
//
// The test is applied to the rotation and translation blocks separately, each after the other is
// left free (their Schur complements), so each eigenvalue has one unit: for translation, the
// number of (Cauchy-weighted) point constraints along that direction; for rotation, the sum of
// those constraints' squared lever arms [m²]. A full 6x6 eigen-analysis mixes the two units and
// its threshold would depend on the scene's size.

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <vector>

#include "core/lidar/voxel_map.hpp"
#include "core/work_splitter.hpp"

namespace posed::lidar {

struct ScanMatcherConfig {
  int max_iterations = 12;                  ///< [1]
  double convergence_rotation_rad = 1e-4;   ///< update below this ends the iterations [rad]
  double convergence_translation_m = 1e-3;  ///< [m]
  int neighbours = 5;                       ///< map points per correspondence [1]
  double max_correspondence_m = 1.5;        ///< nearest map points must be this close [m]
  double plane_max_error_m = 0.05;          ///< every neighbour within this of the fitted plane [m]
  /// the neighbours of a plane must spread in two directions: middle / largest eigenvalue
  double plane_min_spread_ratio = 0.05;
  double edge_min_linearity = 3.0;  ///< largest / second eigenvalue of an edge's neighbours
  double cauchy_scale_m = 0.2;      ///< robust kernel scale [m]
  /// point constraints below which a translation direction is degenerate [1]
  double degeneracy_translation_threshold = 10.0;
  /// squared lever arms below which a rotation direction is degenerate [m²]
  double degeneracy_rotation_threshold_m2 = 20.0;
  bool handle_degeneracy = true;  ///< false: ablation, no remapping, no widening
  /// along degenerate directions the measurement's information is scaled by this (widened) [1]
  double degenerate_information_scale = 0.01;
  double residual_sigma_m = 0.05;  ///< 1-sigma of one point residual, for the information
  /// The residuals of one scan are not independent (the same map errors, deskew and calibration
  /// errors under all of them), so JᵀJ/sigma² overstates how well a scan fixes the pose: these
  /// floors are added to the match's covariance in the constrained directions. Measured on the
  /// simulator (tools/eval-sim, street_night seeds 11-13, 120 s): 1 mrad for rotation, 1 cm for
  /// translation gave the smallest trajectory error; much looser tilt lets the map's slow tilt
  /// leak into the accelerometer bias, much tighter makes the window trust single scans.
  /// about the lidar's x and y axes [rad]
  double tilt_sigma_floor_rad = 0.001;
  /// about the lidar's z axis [rad]
  double yaw_sigma_floor_rad = 0.001;
  double translation_sigma_floor_m = 0.01;
  int min_correspondences = 30;  ///< fewer: the match failed [1]
};

struct ScanMatchResult {
  bool ok = false;  ///< converged with enough correspondences
  /// estimate after degeneracy remapping: the prediction along degenerate directions
  Eigen::Isometry3d T_map_lidar = Eigen::Isometry3d::Identity();
  /// what the scan itself says, degenerate directions included (= T_map_lidar when none): the
  /// measurement for the back end, with `information`
  Eigen::Isometry3d T_map_lidar_measured = Eigen::Isometry3d::Identity();
  /// information of T_map_lidar_measured, order (rotation x,y,z [rad], translation x,y,z [m]) as a
  /// right perturbation T * Exp(delta); widened along degenerate directions
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  /// at the prediction: the rotation block's 3 (ascending) [m²], then the translation block's 3
  /// (ascending) [1] (see above)
  Eigen::Matrix<double, 6, 1> eigenvalues = Eigen::Matrix<double, 6, 1>::Zero();
  /// columns matching `eigenvalues`: block-diagonal (rotation axes, translation directions)
  Eigen::Matrix<double, 6, 6> eigenvectors = Eigen::Matrix<double, 6, 6>::Identity();
  int degenerate_directions = 0;
  int iterations = 0;
  std::size_t edge_correspondences = 0, plane_correspondences = 0;
  double residual_rms_m = 0;  ///< of the inlier residuals at the solution [m]
};

/// One linearised correspondence: residual r (1 row for planes, 3 for edges, in metres) of the
/// map-frame point R p + t, with the unit normal / line projector that defines it. Exposed so the
/// Ceres cross-check in the tests solves the same problem.
struct Correspondence {
  Eigen::Vector3d p_lidar;    ///< scan point [m]
  Eigen::Vector3d anchor;     ///< a point on the plane or line (map) [m]
  Eigen::Vector3d direction;  ///< plane normal or line direction (unit)
  bool is_plane = true;
};

class ScanMatcher {
 public:
  explicit ScanMatcher(const ScanMatcherConfig& config) : config_(config) {}

  ScanMatchResult match(const std::vector<Eigen::Vector3f>& edges_lidar,
                        const std::vector<Eigen::Vector3f>& planes_lidar, const VoxelMap& edge_map,
                        const VoxelMap& plane_map, const Eigen::Isometry3d& T_map_lidar_predicted);

  /// The correspondences of the last iteration (for tests and diagnostics).
  const std::vector<Correspondence>& correspondences() const { return correspondences_; }
  const ScanMatcherConfig& config() const { return config_; }
  /// Changes what counts as degenerate along translations and what a degenerate scan still says
  /// there, from the next match on (LioEstimator: another sensor pins what the lidar barely does).
  void set_translation_degeneracy(double threshold, double information_scale) {
    config_.degeneracy_translation_threshold = threshold;
    config_.degenerate_information_scale = information_scale;
  }
  /// Where the correspondence search's parts run (null: here). The correspondences, and so the
  /// match, are the same either way.
  void set_splitter(WorkSplitter* splitter) { splitter_ = splitter; }

 private:
  /// Parts of the correspondence search: more than helper threads, so a part a busy helper has
  /// not taken yet is taken by the caller.
  static constexpr std::size_t kParts = 4;
  void associate(const std::vector<Eigen::Vector3f>& edges_lidar,
                 const std::vector<Eigen::Vector3f>& planes_lidar, const VoxelMap& edge_map,
                 const VoxelMap& plane_map, const Eigen::Isometry3d& T);

  ScanMatcherConfig config_;
  WorkSplitter* splitter_ = nullptr;
  std::vector<Correspondence> correspondences_;
  /// per part: its edges' and its planes' correspondences, joined in part order
  std::array<std::vector<Correspondence>, kParts> part_edges_, part_planes_;
};

/// Gauss-Newton normal equations of `correspondences` at T (right perturbation, rotation first):
/// H = sum w JᵀJ, g = sum w Jᵀr, with the Cauchy weight of each residual. Returns the weighted
/// squared residual sum; `inliers` counts residuals within 3 kernel scales.
double normal_equations(const std::vector<Correspondence>& correspondences,
                        const Eigen::Isometry3d& T, double cauchy_scale_m,
                        Eigen::Matrix<double, 6, 6>& H, Eigen::Matrix<double, 6, 1>& g,
                        std::size_t* inliers = nullptr, double* inlier_sq_sum = nullptr);

struct Degeneracy {
  Eigen::Matrix<double, 6, 1> eigenvalues = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 6> eigenvectors = Eigen::Matrix<double, 6, 6>::Identity();
  Eigen::Matrix<double, 6, 1> keep = Eigen::Matrix<double, 6, 1>::Ones();  ///< 1 = constrained
  int degenerate_directions = 0;
};
/// The degeneracy test on a normal matrix H (rotation first), as match() applies it.
Degeneracy analyse_degeneracy(const Eigen::Matrix<double, 6, 6>& H,
                              const ScanMatcherConfig& config);

/// `information` (zero outside the projector P's subspace) with the floors (1-sigma: rotation
/// about x, y, z [rad], translation [m]) added to its covariance inside that subspace.
Eigen::Matrix<double, 6, 6> information_with_floor(const Eigen::Matrix<double, 6, 6>& information,
                                                   const Eigen::Matrix<double, 6, 6>& P,
                                                   const Eigen::Vector3d& rotation_floor_rad,
                                                   double translation_floor_m);

/// T * Exp(delta) on SE(3) with delta = (rotation, translation), translation in the body frame.
Eigen::Isometry3d retract(const Eigen::Isometry3d& T, const Eigen::Matrix<double, 6, 1>& delta);

}  // namespace posed::lidar
