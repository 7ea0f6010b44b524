#pragma once
// Shi-Tomasi corner selection from a score image already computed: the second half of OpenCV's
// cv::goodFeaturesToTrack (featureselect.cpp, OpenCV 4.6), step for step, so the corners are the
// same. The feature tracker computes the minimum-eigenvalue image once to mask corners no
// stronger than the image's noise floor (FeatureTracker::mask_weak_corners); calling
// goodFeaturesToTrack afterwards computed it a second time on every frame.

#include <cstddef>
#include <opencv2/core.hpp>
#include <vector>

namespace posed::vision {

/// `score`: cv::cornerMinEigenVal of the image (CV_32FC1); it is overwritten (scores under
/// `quality` x the best score within `mask` become 0). `mask`: CV_8UC1 of the same size, or empty.
/// `corners` becomes the strongest local maxima (3x3) within the
/// mask, strongest first (ties: the later pixel in memory first, as OpenCV's sort), each at least
/// `min_distance_px` from every corner before it, at most `max_corners` (0: no limit) [px].
void select_corners(cv::Mat& score, const cv::Mat& mask, int max_corners, double quality,
                    double min_distance_px, std::vector<cv::Point2f>& corners);

/// The value std::nth_element would put at position `n` of `values`' elements (CV_32FC1, no
/// NaN; `n` < its size): the n-th smallest, found by three counting passes over the floats'
/// bits (11, 11 and 10 at a time) instead of a copy and a partial sort. -0 and +0 compare equal,
/// as for nth_element, and either may be returned.
float nth_smallest(const cv::Mat& values, std::size_t n);

}  // namespace posed::vision
