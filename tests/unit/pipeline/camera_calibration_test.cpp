// The D435i's factory calibration applied to the configuration, against the fake HW-monitor
// endpoint that answers in the firmware's format (tests/unit/camera/fake_d4xx_usb.hpp).

#include "daemon/pipeline/camera_calibration.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "daemon/config/config_loader.hpp"
#include "drivers/camera/d4xx_calibration_reader.hpp"
#include "tests/unit/camera/fake_d4xx_usb.hpp"

namespace posed::pipeline {
namespace camera_calibration_test {

/// Where the forward model puts the undistorted point (x, y).
Eigen::Vector2d forward(const ForwardDistortion& d, double x, double y) {
  const double r2 = x * x + y * y, radial = 1 + d.k1 * r2 + d.k2 * r2 * r2;
  return {x * radial + 2 * d.p1 * x * y + d.p2 * (r2 + 2 * x * x),
          y * radial + d.p1 * (r2 + 2 * y * y) + 2 * d.p2 * x * y};
}

TEST(D435iCalibration, TheForwardFitReproducesTheInverseBrownConradyModel) {
  const std::array<double, 5> c = {0.12, -0.24, 0.001, -0.002, 0.06};
  const double fx = 615, fy = 614, cx = 322, cy = 241;
  const ForwardDistortion d = forward_from_inverse_brown_conrady(c, fx, fy, cx, cy, 640, 480);
  // Round trip through both models at pixels the fit never saw: distorted -> inverse model ->
  // undistorted -> fitted forward model -> distorted again.
  double worst_px = 0;
  for (const auto& [u, v] : {std::pair{3.7, 5.1},
                             {639.2, 2.9},
                             {17.5, 470.3},
                             {400.1, 300.6},
                             {320.3, 240.9},
                             {631.0, 477.7}}) {
    const double x = (u - cx) / fx, y = (v - cy) / fy, r2 = x * x + y * y;
    const double f = 1 + c[0] * r2 + c[1] * r2 * r2 + c[4] * r2 * r2 * r2;
    const double ux = x * f + 2 * c[2] * x * y + c[3] * (r2 + 2 * x * x);
    const double uy = y * f + 2 * c[3] * x * y + c[2] * (r2 + 2 * y * y);
    const Eigen::Vector2d back = forward(d, ux, uy);
    worst_px = std::max(worst_px, std::hypot(fx * (back.x() - x), fy * (back.y() - y)));
  }
  EXPECT_LT(worst_px, 0.5);
  EXPECT_LT(d.rms_px, 0.2);
  // The radial terms undo the inverse ones to first order.
  EXPECT_NEAR(d.k1, -c[0], 0.03);
}

TEST(D435iCalibration, AZeroInverseModelIsAZeroForwardModel) {
  const ForwardDistortion d =
      forward_from_inverse_brown_conrady({0, 0, 0, 0, 0}, 600, 600, 320, 240, 640, 480);
  EXPECT_EQ(d.k1, 0.0);
  EXPECT_EQ(d.p2, 0.0);
  EXPECT_LT(d.max_px, 1e-9);
}

TEST(D435iCalibration, FactoryIntrinsicsReplaceTheConfiguredOnesWhenTheCameraAnswers) {
  config::PosedConfig config = config::default_config();
  config.visible_camera.intrinsics_source = "factory";
  test::FakeD4xxUsb usb;
  const std::string line = apply_d435i_factory_calibration(config, usb);
  // The same tables read directly give the values now in the configuration.
  drivers::camera::D4xxCalibration direct;
  std::string error;
  ASSERT_TRUE(drivers::camera::read_d4xx_calibration(usb, {}, direct, error)) << error;
  EXPECT_DOUBLE_EQ(config.visible_camera.fx, direct.colour.colour.fx);
  EXPECT_DOUBLE_EQ(config.visible_camera.cy, direct.colour.colour.cy);
  EXPECT_NE(config.visible_camera.k1, config::default_config().visible_camera.k1);
  EXPECT_NE(line.find("factory calibration (fake usb 8086:0b3a)"), std::string::npos) << line;
}

TEST(D435iCalibration, WithoutTheCameraTheConfiguredIntrinsicsStay) {
  config::PosedConfig config = config::default_config();
  config.visible_camera.intrinsics_source = "factory";
  test::FakeD4xxUsb usb;
  usb.present = false;
  const std::string line = apply_d435i_factory_calibration(config, usb);
  EXPECT_EQ(config.visible_camera.fx, config::default_config().visible_camera.fx);
  EXPECT_EQ(config.visible_camera.k2, config::default_config().visible_camera.k2);
  EXPECT_TRUE(line.empty()) << "the reader's warning is the one line: " << line;
}

TEST(D435iCalibration, ConfiguredIntrinsicsNeverAskTheCamera) {
  config::PosedConfig config = config::default_config();
  config.visible_camera.intrinsics_source = "config";
  test::FakeD4xxUsb usb;
  apply_d435i_factory_calibration(config, usb);
  EXPECT_EQ(usb.transactions, 0);
  EXPECT_EQ(config.visible_camera.fx, config::default_config().visible_camera.fx);
}

}  // namespace camera_calibration_test
}  // namespace posed::pipeline
