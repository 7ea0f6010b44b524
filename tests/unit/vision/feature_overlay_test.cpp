// The front end's annotated image (core/vision/feature_overlay): each feature drawn where it is,
// coloured by its track length, a ring where lidar gives depth, the counts in a caption.

#include "core/vision/feature_overlay.hpp"

#include <gtest/gtest.h>

namespace posed::vision {
namespace {

cv::Vec3b at(const cv::Mat& bgr, int x, int y) { return bgr.at<cv::Vec3b>(y, x); }

TEST(FeatureOverlay, DrawsEachFeatureInItsTrackColourAndRingsTheOnesWithDepth) {
  const cv::Mat grey(120, 160, CV_8UC1, cv::Scalar(128));
  FrontendFrame frame;
  FrontendFeature fresh;
  fresh.pixel_px = {40, 80};
  fresh.track_length = 1;
  FrontendFeature old;
  old.pixel_px = {120, 80};
  old.track_length = 30;
  old.depth_m = 12.5;
  frame.features = {fresh, old};
  frame.counts.features = 2;

  const cv::Mat out = feature_overlay(grey, frame);
  ASSERT_EQ(out.type(), CV_8UC3);
  ASSERT_EQ(out.size(), grey.size());
  EXPECT_EQ(at(out, 40, 80), cv::Vec3b(0, 0, 255));   // new: red (BGR)
  EXPECT_EQ(at(out, 120, 80), cv::Vec3b(0, 255, 0));  // 20 frames and more: green
  const cv::Vec3b ring = at(out, 126, 80);            // the depth ring, 6 px out (anti-aliased)
  EXPECT_GT(ring[0], 200);
  EXPECT_LT(ring[2], 60);
  EXPECT_EQ(at(out, 46, 80), cv::Vec3b(128, 128, 128));   // no ring without depth
  EXPECT_EQ(at(out, 10, 110), cv::Vec3b(128, 128, 128));  // the image elsewhere untouched
  // The caption is drawn at the top left, light on a dark outline.
  int light = 0, dark = 0;
  for (int y = 6; y < 26; ++y) {
    for (int x = 6; x < 160; ++x) {
      const cv::Vec3b p = at(out, x, y);
      light += p[0] > 200 && p[1] > 200 && p[2] > 200;
      dark += p[0] < 50 && p[1] < 50 && p[2] < 50;
    }
  }
  EXPECT_GT(light, 20);
  EXPECT_GT(dark, 20);
}

TEST(FeatureOverlay, TrackColourGoesFromRedThroughYellowToGreen) {
  EXPECT_EQ(track_colour(1), cv::Scalar(0, 0, 255));
  EXPECT_EQ(track_colour(0), cv::Scalar(0, 0, 255));  // never seen: as new, no wrap-around
  EXPECT_NEAR(track_colour(10)[1], 255, 30);
  EXPECT_NEAR(track_colour(10)[2], 255, 30);
  EXPECT_EQ(track_colour(20), cv::Scalar(0, 255, 0));
  EXPECT_EQ(track_colour(500), cv::Scalar(0, 255, 0));
}

}  // namespace
}  // namespace posed::vision
