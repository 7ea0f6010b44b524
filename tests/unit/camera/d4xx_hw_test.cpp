// Live D435i: reads the factory calibration over libusb from a connected camera. Labelled hw;
// skips, saying why, when no D435i is attached or it cannot be opened.
#include <gtest/gtest.h>

#include <Eigen/LU>

#include "drivers/camera/d4xx_calibration_reader.hpp"
#include "drivers/camera/libusb_transport.hpp"

namespace posed::drivers::camera {
namespace {

TEST(D435iHardware, FactoryCalibrationOverLibusb) {
  LibusbTransport usb;
  std::string error;
  if (!usb.open(error)) GTEST_SKIP() << "no D435i to talk to: " << error;
  D4xxCalibration c;
  ASSERT_TRUE(read_d4xx_calibration(usb, {848, 480, 640, 480}, c, error)) << error;
  EXPECT_TRUE(c.from_device);
  // A D435i's stereo baseline is 50 mm; its 640x480 colour focal length about 600-620 px.
  EXPECT_NEAR(c.depth.baseline_m, 0.050, 0.002);
  EXPECT_GT(c.colour.colour.fx, 550);
  EXPECT_LT(c.colour.colour.fx, 680);
  EXPECT_NEAR((c.colour.T_depth_colour.topLeftCorner<3, 3>().determinant()), 1.0, 1e-4);
}

}  // namespace
}  // namespace posed::drivers::camera
