#pragma once
// How well an image patch fixes a tracked point in each direction: its structure tensor (the sum
// of the gradients' outer products over the KLT window), the matrix whose inverse bounds KLT's
// error (Lucas-Kanade's normal equations), scaled to 1 along its best direction. A corner's is
// near the identity; a straight edge's is near 0 along the edge, where KLT cannot see motion
// (the aperture problem). The back end weighs a feature's flow by it
// (fusion::FrameMotionConfig::aperture_max_ratio).

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

namespace posed::vision {

/// The structure tensor of `grey` (CV_8UC1) over the (2 half_px + 1)² window at `at` (clipped to
/// the image), in pixel axes, over its largest eigenvalue; the identity on a flat patch.
Eigen::Matrix2d patch_shape(const cv::Mat& grey, cv::Point2f at, int half_px);

}  // namespace posed::vision
