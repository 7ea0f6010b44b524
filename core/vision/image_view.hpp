#pragma once
// cv::Mat headers over the pixels of a core Image (no copy): the front end reads the driver's
// pool buffer in place. The Image must outlive the view.

#include <opencv2/core/mat.hpp>

#include "core/measurements.hpp"

namespace posed::vision {

/// OpenCV type of a pixel format (CV_8UC1, CV_16UC1, CV_8UC3); -1 for formats the front end does
/// not read (depth).
int cv_type(PixelFormat format);

/// A header over `image`'s pixels, or an empty Mat when the image is unusable: no pixels, an
/// unsupported format, a stride shorter than a row, or a buffer shorter than stride x height.
cv::Mat view(const Image& image);

}  // namespace posed::vision
