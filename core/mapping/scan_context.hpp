#pragma once
// Scan Context (Kim & Kim, IROS 2018): a place descriptor of one lidar scan for loop candidates
// when drift is too large to find them by distance. The scan, levelled (z up, centred on the
// sensor), is cut into rings (range) x sectors (azimuth); each bin keeps the height of its
// highest point. Two places compare by the cosine distance of their sector columns, minimised
// over column shifts, so a revisit from another heading still matches and the best shift gives
// the yaw between them. The ring key (each ring's mean) does not depend on heading: it is what a
// nearest-neighbour search over all keyframes runs on.

#include <Eigen/Core>
#include <span>

namespace posed::mapping {

struct ScanContextConfig {
  int rings = 20;             ///< radial bins [1]
  int sectors = 60;           ///< azimuth bins [1] (6 degrees each at 60)
  double max_range_m = 80.0;  ///< points beyond are left out [m]
  /// added to every point's height so bins over the ground are positive; 0 marks an empty bin
  /// [m] (the sensor's height above the floor, roughly)
  double height_offset_m = 2.0;
  /// shifts searched around the one the sector keys suggest, each way [1]
  int shift_search = 3;
};

struct ScanContext {
  Eigen::MatrixXf bins;      ///< rings x sectors: highest point + offset [m], 0 = empty
  Eigen::VectorXf ring_key;  ///< rings: mean of each ring [m] (heading-invariant)
  /// sectors: mean of each column [m] (for a cheap first guess of the shift)
  Eigen::VectorXf sector_key;
};

/// `points_level` in a levelled sensor frame: origin at the sensor, z up (gravity), x any heading.
ScanContext make_scan_context(std::span<const Eigen::Vector3f> points_level,
                              const ScanContextConfig& config);

struct ScanContextMatch {
  /// mean cosine distance of the overlapping non-empty columns at the best shift [0..1]; 1 when
  /// no column overlaps
  double distance = 1.0;
  int shift = 0;  ///< `query` column j matches `candidate` column j + shift [sectors]
  /// the yaw of the query's frame in the candidate's frame implied by the shift [rad]
  double yaw_rad = 0.0;
};

ScanContextMatch match_scan_contexts(const ScanContext& query, const ScanContext& candidate,
                                     const ScanContextConfig& config);

}  // namespace posed::mapping
