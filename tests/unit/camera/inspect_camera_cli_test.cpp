// posectl inspect camera as a user runs it, against Aravis's GigE Vision fake camera served
// from this process on loopback (as aravis_fake_camera_test does): --list finds it with its
// pixel formats; a capture from Aravis's Fake interface writes PNGs (16-bit kept 16-bit); bad
// usage fails with a message.
// Needs the posectl executable of this build; skipped, saying so, when it has not been built.

#include <arv.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

namespace posed::drivers::camera {
namespace {

namespace fs = std::filesystem;

fs::path posectl_path() {
  const char* env = std::getenv("POSED_BUILD_DIR");
  const fs::path build = env != nullptr ? fs::path(env) : fs::path(POSED_BUILD_DIR_DEFAULT);
  return build / "tools" / "posectl" / "posectl";
}

struct CliRun {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

CliRun run(const std::string& args) {
  CliRun r;
  const std::string cmd = posectl_path().string() + " inspect camera " + args + " 2>&1";
  std::FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) r.output.append(buf.data(), n);
  const int status = ::pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

class InspectCameraCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(posectl_path())) GTEST_SKIP() << posectl_path() << " not built (ninja posectl)";
    dir_ = fs::temp_directory_path() / ("posed_inspect_camera_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(InspectCameraCli, HelpAndBadUsage) {
  const CliRun help = run("--help");
  EXPECT_EQ(help.exit_code, 0) << help.output;
  EXPECT_NE(help.output.find("--frames"), std::string::npos) << help.output;
  EXPECT_NE(help.output.find("aravis:ID"), std::string::npos) << help.output;
  const CliRun none = run("");
  EXPECT_EQ(none.exit_code, 2) << none.output;
  EXPECT_NE(none.output.find("give --list, or DEVICE and --out DIR"), std::string::npos);
  const CliRun missing = run("/dev/video97 --frames 1 --out " + dir_.string());
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_NE(missing.output.find("/dev/video97: open failed"), std::string::npos) << missing.output;
  const CliRun bad_format = run("/dev/video0 --format nv12 --out " + dir_.string());
  EXPECT_EQ(bad_format.exit_code, 2) << bad_format.output;
}

TEST_F(InspectCameraCli, ListsTheFakeGigECameraWithItsPixelFormats) {
  ArvGvFakeCamera* fake =
      ARV_GV_FAKE_CAMERA(g_object_new(ARV_TYPE_GV_FAKE_CAMERA, "interface-name", "127.0.0.1",
                                      "serial-number", "POSEDCLI", nullptr));
  if (fake == nullptr || !arv_gv_fake_camera_is_running(fake)) {
    if (fake != nullptr) g_object_unref(fake);
    GTEST_SKIP() << "Aravis GigE fake camera could not bind 127.0.0.1 (no loopback?)";
  }
  const CliRun list = run("--list");
  EXPECT_EQ(list.exit_code, 0) << list.output;
  EXPECT_NE(list.output.find("V4L2 devices"), std::string::npos) << list.output;
  const auto at = list.output.find("POSEDCLI");
  ASSERT_NE(at, std::string::npos) << list.output;
  // "  aravis:<id>  <vendor> <model> serial POSEDCLI ..."; the id is the first word of the line.
  const auto line_start = list.output.rfind("aravis:", at);
  ASSERT_NE(line_start, std::string::npos);
  const std::string id =
      list.output.substr(line_start, list.output.find(' ', line_start) - line_start);
  EXPECT_NE(list.output.find("Mono16", at), std::string::npos) << list.output;

  EXPECT_EQ(id.rfind("aravis:", 0), 0u) << id;
  g_object_unref(fake);
}

// Capture through Aravis's in-process Fake interface (arv_enable_interface("Fake"), the
// --aravis-fake switch): posectl owns the simulated camera, so frames flow without a network.
TEST_F(InspectCameraCli, CapturesTheAravisFakeInterfaceCameraToPng) {
  const std::string id = "aravis:Fake_1";
  const CliRun list = run("--list --aravis-fake");
  EXPECT_NE(list.output.find(id), std::string::npos) << list.output;
  const CliRun y16 =
      run(id + " --aravis-fake --format y16 --width 640 --height 512 --fps 50 --frames 3 --out " +
          (dir_ / "y16").string());
  EXPECT_EQ(y16.exit_code, 0) << y16.output;
  EXPECT_NE(y16.output.find("[3/3]"), std::string::npos) << y16.output;
  EXPECT_NE(y16.output.find("written=3/3"), std::string::npos) << y16.output;
  const cv::Mat img =
      cv::imread((dir_ / "y16" / "frame_000002.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.depth(), CV_16U);  // 16-bit kept as 16-bit
  EXPECT_EQ(img.cols, 640);
  EXPECT_EQ(img.rows, 512);
  double lo = 0, hi = 0;
  cv::minMaxLoc(img, &lo, &hi);
  EXPECT_GT(hi, lo);  // the fake's test pattern, not a blank image

  const CliRun y8 =
      run(id + " --aravis-fake --format y8 --width 320 --height 256 --frames 2 --out " +
          (dir_ / "y8").string());
  EXPECT_EQ(y8.exit_code, 0) << y8.output;
  const cv::Mat grey =
      cv::imread((dir_ / "y8" / "frame_000001.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(grey.empty());
  EXPECT_EQ(grey.depth(), CV_8U);
  EXPECT_EQ(grey.cols, 320);
}

}  // namespace
}  // namespace posed::drivers::camera
