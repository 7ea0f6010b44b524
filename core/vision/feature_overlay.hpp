#pragma once
// The tracked image with what the front end made of it, for a person to look at (rt/posed/
// image/compressed, `posectl inspect frontend --save-frames`): each feature coloured by its
// track length, a ring around those with lidar depth (some labelled in metres), and a caption
// with the frame's counts.

#include <opencv2/core.hpp>
#include <string>

#include "core/vision/frontend_frame.hpp"

namespace posed::vision {

/// White text outlined in black at the top left of `image` (BGR), readable on any image.
void draw_label(cv::Mat& image, const std::string& text);

/// Track length as a BGR colour: new features red, through yellow, to green at 20 frames.
cv::Scalar track_colour(std::uint32_t track_length);

/// `tracked_grey` (8-bit grey) in colour with `frame`'s features and counts drawn on it.
cv::Mat feature_overlay(const cv::Mat& tracked_grey, const FrontendFrame& frame);

}  // namespace posed::vision
