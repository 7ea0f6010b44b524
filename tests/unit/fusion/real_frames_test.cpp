// Real frames through the visual-thermal front end (issue 9): the colour frame of a real D435
// (librealsense's recording in ../shared/realdata/realsense_d435/, read with posed's own ROS 1
// bag reader and colour decoder) and a real 16-bit radiometric thermal frame
// (../shared/realdata/thermal_16bit/), each through the modes that use it. Skipped, saying why,
// without the shared data.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/vision/visual_frontend.hpp"
#include "drivers/camera/pixel_formats.hpp"
#include "drivers/recording/ros1_bag_reader.hpp"
#include "drivers/recording/ros1_messages.hpp"
#include "tests/common/realdata.hpp"
#include "tests/unit/vision/synthetic_scene.hpp"

namespace posed::testing {
namespace real_frames_test {

namespace ros1 = drivers::recording::ros1;
namespace camera = drivers::camera;
using test::read_bytes;
using test::realdata_path;

/// The bag's colour frame as BGR8, or empty (with `why`).
cv::Mat d435_colour_frame(std::string& why) {
  const std::string path = realdata_path("realsense_d435/single_depth_color_640x480.bag");
  if (path.empty()) {
    why = "../shared/realdata/realsense_d435 is not here";
    return {};
  }
  ros1::BagReader reader;
  if (!reader.open(path, why)) return {};
  ros1::BagMessage m;
  while (reader.next(m)) {
    if (m.connection->topic != "/device_0/sensor_1/Color_0/image/data") continue;
    ros1::Image image;
    if (ros1::decode_image(m.data, image) != ros1::Ros1Status::kOk) continue;
    const auto format = ros1::camera_wire_format(image);
    if (!format) continue;
    cv::Mat bgr(static_cast<int>(image.height), static_cast<int>(image.width), CV_8UC3);
    const camera::ImageSpan dst{
        {reinterpret_cast<std::byte*>(bgr.data), bgr.total() * bgr.elemSize()},
        static_cast<std::uint32_t>(bgr.step)};
    if (camera::convert_frame({image.data, image.width, image.height, image.step, *format}, dst) !=
        camera::ConvertStatus::kOk) {
      continue;
    }
    // convert_frame keeps RGB8 as RGB8; the front end reads B,G,R unless told.
    if (*format == camera::WireFormat::kRgb8) cv::cvtColor(bgr, bgr, cv::COLOR_RGB2BGR);
    return bgr;
  }
  why = "no decodable colour frame in " + path;
  return {};
}

cv::Mat thermal_16bit_frame(std::string& why) {
  const std::string path = realdata_path("thermal_16bit/frame_000000_640x512_u16le.raw");
  if (path.empty()) {
    why = "../shared/realdata/thermal_16bit is not here";
    return {};
  }
  const std::vector<std::uint8_t> bytes = read_bytes(path);
  if (bytes.size() != 640u * 512u * 2u) {
    why = path + ": not 640x512 16-bit";
    return {};
  }
  cv::Mat raw(512, 640, CV_16UC1);
  std::memcpy(raw.data, bytes.data(), bytes.size());
  return raw;
}

vision::FrontendConfig rig(vision::FrontendMode mode) {
  vision::FrontendConfig c;
  c.mode = mode;
  c.visible_camera = vision::scene::m2dgr_visible();
  c.thermal_camera = vision::scene::m2dgr_thermal();
  c.T_cam_thermal = vision::scene::m2dgr_T_cam_thermal();
  return c;
}

/// Two passes over the same frame: features are found, and all of them track onto themselves.
void expect_sane(vision::VisualFrontend& frontend, vision::FrontendInput input,
                 const vision::ImageQuality& (*quality)(const vision::FrontendFrame&)) {
  vision::FrontendFrame frame;
  input.visible_stamp = input.thermal_stamp = HostTime::from_ns(1'000'000'000);
  ASSERT_EQ(frontend.process(input, frame), vision::FrontendStatus::kOk);
  // At least a third of the 300 the tracker keeps: a real indoor scene has that many corners
  // 20 px apart (the D435 frame gives 135, the thermal pair more).
  EXPECT_GT(frame.counts.features, 100) << "a real scene has corners";
  const vision::ImageQuality& q = quality(frame);
  ASSERT_TRUE(q.valid);
  EXPECT_GT(q.gradient_metric, 0.01);
  EXPECT_LT(q.gradient_metric, 1.0);
  EXPECT_GT(q.noise_sigma, 0.0);
  EXPECT_LT(q.noise_sigma, 15.0) << "a daylight / radiometric frame is not that noisy";
  EXPECT_GT(q.confidence, 0.0);
  EXPECT_LE(q.confidence, 1.0);
  input.visible_stamp = input.thermal_stamp = HostTime::from_ns(1'066'000'000);
  ASSERT_EQ(frontend.process(input, frame), vision::FrontendStatus::kOk);
  EXPECT_GT(frame.counts.match_success_rate(), 0.95) << "the same frame tracks onto itself";
}

TEST(RealFrames, AD435ColourFrameThroughTheVisibleFrontEnd) {
  std::string why;
  const cv::Mat bgr = d435_colour_frame(why);
  if (bgr.empty()) GTEST_SKIP() << why;
  ASSERT_EQ(bgr.cols, 640);
  ASSERT_EQ(bgr.rows, 480);
  vision::VisualFrontend frontend(rig(vision::FrontendMode::kVisible));
  vision::FrontendInput input;
  input.visible = bgr;
  expect_sane(frontend, input, [](const vision::FrontendFrame& f) -> const vision::ImageQuality& {
    return f.quality.visible;
  });
}

TEST(RealFrames, ThePairOfRealFramesThroughTheFusedFrontEnd) {
  std::string why;
  const cv::Mat bgr = d435_colour_frame(why);
  if (bgr.empty()) GTEST_SKIP() << why;
  const cv::Mat raw = thermal_16bit_frame(why);
  if (raw.empty()) GTEST_SKIP() << why;
  // Two cameras that never saw the same scene: this checks the pipeline on real pixel
  // statistics (16-bit normalisation, registration, fusion, quality), not registration.
  vision::VisualFrontend frontend(rig(vision::FrontendMode::kFused));
  vision::FrontendInput input;
  input.visible = bgr;
  input.thermal = raw;
  expect_sane(frontend, input, [](const vision::FrontendFrame& f) -> const vision::ImageQuality& {
    return f.quality.fused;
  });
}

}  // namespace real_frames_test
}  // namespace posed::testing
