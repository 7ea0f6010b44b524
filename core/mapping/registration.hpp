#pragma once
// Verifies a loop candidate: registers the query keyframe's cloud to the candidate's submap (PCL's
// Generalized-ICP from a first guess) and says whether the result is trustworthy. Three tests,
// because GICP "converges" on almost anything: the aligned clouds must be close (RMS of the
// inlier distances), overlap (share of query points with a target point near them), and pin
// every direction of translation. The last is what rejects a repetitive corridor: its walls and
// floor constrain everything but the corridor's axis, and along it the registration slides to
// wherever the first guess put it.
//
// The only translation unit of core/mapping that includes PCL's registration templates (a PCL
// unit costs ~12 s and ~1 GB to compile): its interface speaks Eigen.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <span>
#include <string_view>
#include <vector>

namespace posed::mapping {

struct RegistrationConfig {
  double voxel_m = 0.5;               ///< both clouds are thinned to one point per voxel [m]
  double max_correspondence_m = 2.0;  ///< GICP pairs no points farther apart [m]
  int max_iterations = 40;            ///< GICP iterations [1]
  /// after alignment: a query point with a target point this near is an inlier [m]; thinned
  /// clouds sample surfaces at different places, so this must exceed voxel_m
  double inlier_distance_m = 0.6;
  /// RMS point-to-plane distance of the inliers (each to the plane of its target neighbours) [m]
  double max_rms_m = 0.1;
  double min_overlap = 0.5;  ///< inliers over query points [0..1]
  /// the weakest translation direction's share of the point-to-plane information, per query
  /// point: lambda_min(sum n n^T) / N [0..1]; an open room gives ~0.2, a plain corridor ~0
  double min_constraint = 0.02;
  int normal_neighbours = 8;  ///< target points a normal is fitted to [1]
};

enum class RegistrationVerdict {
  kAccepted,
  kTooFewPoints,  ///< either cloud nearly empty after thinning
  kDiverged,      ///< GICP did not converge
  kNotClose,      ///< inlier RMS above max_rms_m
  kLowOverlap,    ///< inlier share below min_overlap
  kDegenerate,    ///< a translation direction below min_constraint
};
std::string_view verdict_name(RegistrationVerdict verdict);

struct RegistrationResult {
  RegistrationVerdict verdict = RegistrationVerdict::kTooFewPoints;
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  double rms_m = 0.0;     ///< RMS point-to-plane distance of the inliers after alignment [m]
  double overlap = 0.0;   ///< inliers over query points [0..1]
  double constraint = 0;  ///< lambda_min of the translation information per query point [0..1]
  Eigen::Vector3d weakest_direction = Eigen::Vector3d::Zero();  ///< in the target frame
  int source_points = 0;                                        ///< after thinning [1]
  int target_points = 0;                                        ///< after thinning [1]
  bool accepted() const { return verdict == RegistrationVerdict::kAccepted; }
};

/// One point per occupied voxel (their centroid), non-finite points dropped: how keyframe clouds
/// are kept.
std::vector<Eigen::Vector3f> thin_cloud(std::span<const Eigen::Vector3f> points, double voxel_m);

/// Registers `source` (query frame) onto `target` (candidate frame), starting from
/// `T_target_source_guess`.
RegistrationResult register_clouds(std::span<const Eigen::Vector3f> source,
                                   std::span<const Eigen::Vector3f> target,
                                   const Eigen::Isometry3d& T_target_source_guess,
                                   const RegistrationConfig& config);

}  // namespace posed::mapping
