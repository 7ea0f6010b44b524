#include "core/mapping/registration.hpp"

#include <pcl/filters/voxel_grid.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

namespace posed::mapping {

std::string_view verdict_name(RegistrationVerdict verdict) {
  switch (verdict) {
    case RegistrationVerdict::kAccepted:
      return "accepted";
    case RegistrationVerdict::kTooFewPoints:
      return "too_few_points";
    case RegistrationVerdict::kDiverged:
      return "diverged";
    case RegistrationVerdict::kNotClose:
      return "not_close";
    case RegistrationVerdict::kLowOverlap:
      return "low_overlap";
    case RegistrationVerdict::kDegenerate:
      return "degenerate";
  }
  return "unknown";
}

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

Cloud::Ptr thinned(std::span<const Eigen::Vector3f> points, double voxel_m) {
  Cloud::Ptr raw(new Cloud);
  raw->reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (p.allFinite()) {
      raw->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    }
  }
  Cloud::Ptr out(new Cloud);
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  const auto leaf = static_cast<float>(voxel_m);
  grid.setLeafSize(leaf, leaf, leaf);
  grid.setInputCloud(raw);
  grid.filter(*out);
  return out;
}

struct LocalPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double planarity = 0.0;  ///< 1 - smallest / middle eigenvalue of the scatter [0..1]
};

/// The plane through `target`'s points nearest `p` (normal: smallest eigenvector of their
/// scatter).
LocalPlane local_plane(const pcl::KdTreeFLANN<pcl::PointXYZ>& tree, const Cloud& target,
                       const pcl::PointXYZ& p, int neighbours, std::vector<int>& index,
                       std::vector<float>& distance2) {
  if (tree.nearestKSearch(p, neighbours, index, distance2) < 3) {
    return {};
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const int i : index) {
    mean += target[static_cast<std::size_t>(i)].getVector3fMap().cast<double>();
  }
  mean /= static_cast<double>(index.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const int i : index) {
    const Eigen::Vector3d d =
        target[static_cast<std::size_t>(i)].getVector3fMap().cast<double>() - mean;
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  const double middle = eig.eigenvalues()(1);
  return {eig.eigenvectors().col(0), mean,
          middle > 0.0 ? 1.0 - eig.eigenvalues()(0) / middle : 0.0};
}

}  // namespace

std::vector<Eigen::Vector3f> thin_cloud(std::span<const Eigen::Vector3f> points, double voxel_m) {
  const Cloud::Ptr cloud = thinned(points, voxel_m);
  std::vector<Eigen::Vector3f> out;
  out.reserve(cloud->size());
  for (const pcl::PointXYZ& p : *cloud) {
    out.emplace_back(p.x, p.y, p.z);
  }
  return out;
}

RegistrationResult register_clouds(std::span<const Eigen::Vector3f> source,
                                   std::span<const Eigen::Vector3f> target,
                                   const Eigen::Isometry3d& T_target_source_guess,
                                   const RegistrationConfig& config) {
  RegistrationResult result;
  result.T_target_source = T_target_source_guess;
  const Cloud::Ptr source_cloud = thinned(source, config.voxel_m);
  const Cloud::Ptr target_cloud = thinned(target, config.voxel_m);
  result.source_points = static_cast<int>(source_cloud->size());
  result.target_points = static_cast<int>(target_cloud->size());
  const int min_points = 2 * config.normal_neighbours + 20;
  if (result.source_points < min_points || result.target_points < min_points) {
    return result;
  }

  pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
  gicp.setInputSource(source_cloud);
  gicp.setInputTarget(target_cloud);
  gicp.setMaxCorrespondenceDistance(config.max_correspondence_m);
  gicp.setMaximumIterations(config.max_iterations);
  gicp.setTransformationEpsilon(1e-6);
  gicp.setEuclideanFitnessEpsilon(1e-6);
  Cloud aligned;
  gicp.align(aligned, T_target_source_guess.matrix().cast<float>());
  if (!gicp.hasConverged()) {
    result.verdict = RegistrationVerdict::kDiverged;
    return result;
  }
  result.T_target_source.matrix() = gicp.getFinalTransformation().cast<double>();
  // Re-orthonormalise: the float product drifts from a rotation by ~1e-7.
  result.T_target_source.linear() =
      Eigen::Quaterniond(result.T_target_source.rotation()).normalized().toRotationMatrix();

  // Inliers, their distances and the point-to-plane information of the aligned query.
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(target_cloud);
  std::vector<int> index(1), neighbours;
  std::vector<float> distance2(1), neighbour_distance2;
  const double inlier2 = config.inlier_distance_m * config.inlier_distance_m;
  double sum2 = 0.0;
  int inliers = 0;
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  for (const pcl::PointXYZ& p : aligned) {
    if (tree.nearestKSearch(p, 1, index, distance2) < 1 || distance2[0] > inlier2) {
      continue;
    }
    ++inliers;
    const LocalPlane plane = local_plane(tree, *target_cloud, p, config.normal_neighbours,
                                         neighbours, neighbour_distance2);
    // Thinned clouds sample a surface at different places: the distance to the surface, not to
    // the nearest sample, says how well they agree. Off planes (edges, clutter) the nearest
    // sample is all there is.
    const double to_plane = plane.normal.dot(p.getVector3fMap().cast<double>() - plane.centroid);
    sum2 += plane.planarity > 0.5 ? to_plane * to_plane : distance2[0];
    information += plane.planarity * plane.normal * plane.normal.transpose();
  }
  result.overlap = static_cast<double>(inliers) / static_cast<double>(result.source_points);
  result.rms_m = inliers > 0 ? std::sqrt(sum2 / inliers) : 0.0;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(information / result.source_points);
  result.constraint = eig.eigenvalues()(0);
  result.weakest_direction = eig.eigenvectors().col(0);

  if (result.overlap < config.min_overlap) {
    result.verdict = RegistrationVerdict::kLowOverlap;
  } else if (result.rms_m > config.max_rms_m) {
    result.verdict = RegistrationVerdict::kNotClose;
  } else if (result.constraint < config.min_constraint) {
    result.verdict = RegistrationVerdict::kDegenerate;
  } else {
    result.verdict = RegistrationVerdict::kAccepted;
  }
  return result;
}

}  // namespace posed::mapping
