#pragma once
// The motion of a camera between two frames from features tracked across them, with metric
// scale from the lidar depth the front end gave them (seed 000 §2.2.1; LVI-SAM's VIS): a
// perspective-n-point problem in both directions at once. A feature with depth in frame a is a
// 3-D point X_a that must project onto its observation in b; one with depth in b must project
// onto its observation in a. Gauss-Newton on T_a_b (rotation and translation, right
// perturbation: T_a_b Exp(φ), p + R ρ) from a guess (the IMU's prediction, which over a tenth of a
// second is good to millimetres), a Huber kernel, then the observations beyond
// `outlier_sigma` are dropped and the solve repeated: tracks the front end's fundamental-matrix
// RANSAC let through with a wrong depth (a point of the wall behind an edge) are what it removes.
//
// The covariance is the inverse of the Gauss-Newton Hessian at `pixel_sigma`: it says which
// directions the features pin (a camera looking down a corridor pins the motion along it through
// the features' expansion, metre for metre scaled by their lidar depths). Pure, deterministic,
// no OpenCV.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <span>

namespace posed::fusion {

/// One feature of a frame as the back end keeps it.
struct FrameFeature {
  std::uint64_t id = 0;
  Eigen::Vector2d normalised = Eigen::Vector2d::Zero();  ///< (x/z, y/z) in the camera frame [-]
  double depth_m = std::numeric_limits<double>::quiet_NaN();  ///< z; NaN: no lidar depth [m]
  /// how well its image patch fixes it per direction, 1 along the best (vision::FrontendFeature::
  /// patch_shape) [-]
  Eigen::Matrix2d patch_shape = Eigen::Matrix2d::Identity();
};

struct FrameMotionConfig {
  /// observation noise in normalised coordinates (pixel noise / focal length) [-]
  double pixel_sigma = 1.0 / 600.0;
  double huber_sigma = 1.5;    ///< Huber threshold [sigma]
  double outlier_sigma = 3.0;  ///< observations beyond are dropped after the first solve [sigma]
  int min_inliers = 12;        ///< fewer usable observations: no estimate [1]
  int iterations = 8;          ///< Gauss-Newton iterations per round [1]
  double min_depth_m = 0.3;    ///< points nearer (or behind) either camera are skipped [m]
  /// keep the guess's rotation and solve for the translation only: over a tenth of a second the
  /// gyro knows the rotation far better than the features (0.04 deg against ~0.2 deg on the
  /// simulated rigs, where yaw and sideways motion trade off through depth errors)
  bool fix_rotation = false;
  /// observations further than this from where the guess puts them are left out (0: none); if
  /// fewer than half of them and min_inliers remain, none are. A guess from the IMU and the
  /// window's velocity is good to a fraction of a pixel over a tenth of a second, while a
  /// feature that does not move with the world misses it by its whole flow [normalised]
  double guess_gate = 0;
  /// with fewer than half of the observations inside guess_gate, trust the majority and use them
  /// all (a guess gone stale after a jolt); false: fewer than min_inliers inside is no estimate.
  /// A thermal image's fixed pattern on uniform walls can be most of its features, all holding
  /// still while the robot moves: there the majority must not decide
  bool gate_falls_back = true;
  /// An observation nearer to where its feature was in the other frame than to where the guess
  /// moves it is left out, when the guess moves it by more than this [sigma] (0: no test). A
  /// corner of the shading a robot's own lamp casts on a plain wall, or of dirt on the lens, does
  /// not move with the world: it says the camera stood still. Where such corners are a large
  /// share (the simulated corridor: a quarter of the features with depth), the Huber kernel and
  /// the outlier round cannot outvote them, and the motion came out 13-17 % short on average.
  /// A guess from the IMU and the window is far better than the half of the flow this test
  /// needs, so a feature of the world passes it; if most observations fail it, the guess is what
  /// is wrong (a speed estimate twice the truth) and none is left out.
  double still_flow_sigma = 2.0;
  /// Weigh each observation by its features' patch shapes, its sigma along a direction the
  /// patches fix poorly up to this many times pixel_sigma (0 or 1: every observation isotropic).
  /// Along a straight edge KLT cannot see motion (the aperture problem); in a corridor the
  /// walls' and floor's edges run towards the focus of expansion, along the flow, so their tracks
  /// slide or stick along them and, weighed as corners, pull the motion short.
  double aperture_max_ratio = 0;
};

enum class FrameMotionStatus : std::uint8_t {
  kOk,
  kTooFewPoints,    ///< fewer than min_inliers features with depth tracked across the frames
  kTooFewInliers,   ///< enough before, not after the outliers were dropped
  kIllConditioned,  ///< the features do not pin every direction (Hessian not positive definite)
};

struct FrameMotion {
  FrameMotionStatus status = FrameMotionStatus::kTooFewPoints;
  /// camera b in camera a
  Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity();
  /// (rotation, translation) right perturbation of T_a_b [rad², m²]; with fix_rotation, the
  /// rotation rows and columns are zero (the features did not measure it)
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Identity();
  int observations = 0;  ///< residual pairs set up (both directions) [1]
  int inliers = 0;       ///< kept after outlier removal [1]
  int still = 0;         ///< observations left out as not moving with the world [1]
  double rms_sigma = 0;  ///< RMS of the inliers' residuals [sigma]
  bool ok() const { return status == FrameMotionStatus::kOk; }
};

/// Features of both frames sorted by id (the front end's order).
FrameMotion estimate_frame_motion(std::span<const FrameFeature> a, std::span<const FrameFeature> b,
                                  const Eigen::Isometry3d& T_a_b_guess,
                                  const FrameMotionConfig& config);

}  // namespace posed::fusion
