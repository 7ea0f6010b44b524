#include "drivers/camera/v4l2_capture.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "drivers/camera/v4l2_enumerate.hpp"
#include "tests/unit/camera/fake_v4l2_device.hpp"

namespace posed::drivers::camera {
namespace {

using test::FakeEvent;
using test::FakeV4l2Device;

constexpr std::size_t kYuyvBytes = 640 * 480 * 2;

V4l2CaptureConfig yuyv_config(std::uint32_t fps = 15, std::uint32_t buffers = 4) {
  V4l2CaptureConfig c;
  c.device = "/dev/video0";
  c.format = WireFormat::kYuyv;
  c.width = 640;
  c.height = 480;
  c.fps = fps;
  c.buffer_count = buffers;
  return c;
}

const Duration kTimeout = Duration::from_ms(100);

TEST(V4l2Capture, NegotiatesFormatSizeRateAndStartsStreaming) {
  FakeV4l2Device dev;
  V4l2Capture cap(dev, yuyv_config());
  std::string error;
  ASSERT_TRUE(cap.open(error)) << error;
  const auto& n = cap.negotiated();
  EXPECT_EQ(n.fourcc, to_fourcc(WireFormat::kYuyv));
  EXPECT_EQ(n.width, 640u);
  EXPECT_EQ(n.height, 480u);
  EXPECT_EQ(n.stride_bytes, 1280u);
  EXPECT_EQ(n.frame_bytes, kYuyvBytes);
  EXPECT_EQ(n.interval_num, 1u);
  EXPECT_EQ(n.interval_den, 15u);
  EXPECT_EQ(n.buffer_count, 4u);
  EXPECT_EQ(n.card, "Fake Camera");
  const std::vector<std::string> expected{"QUERYCAP", "S_FMT",    "S_PARM",   "REQBUFS", "QUERYBUF",
                                          "QUERYBUF", "QUERYBUF", "QUERYBUF", "QBUF",    "QBUF",
                                          "QBUF",     "QBUF",     "STREAMON"};
  EXPECT_EQ(dev.calls, expected);
  EXPECT_EQ(dev.mapped, 4);
  EXPECT_EQ(dev.queued.size(), 4u);
  cap.close();
  EXPECT_EQ(dev.mapped, 0);
  EXPECT_EQ(dev.open_fds, 0);
  EXPECT_EQ(dev.count("STREAMOFF"), 1);
}

TEST(V4l2Capture, FormatTheDriverDoesNotOfferFailsWithContextAndCleansUp) {
  FakeV4l2Device dev;
  auto cfg = yuyv_config();
  cfg.format = WireFormat::kZ16;
  V4l2Capture cap(dev, cfg);
  std::string error;
  EXPECT_FALSE(cap.open(error));
  EXPECT_NE(error.find("/dev/video0"), std::string::npos) << error;
  EXPECT_NE(error.find("asked for z16 640x480"), std::string::npos) << error;
  EXPECT_NE(error.find("driver offers YUYV 640x480"), std::string::npos) << error;
  EXPECT_EQ(dev.open_fds, 0);
  EXPECT_FALSE(cap.is_open());
}

TEST(V4l2Capture, SizeAdjustedByTheDriverIsRejected) {
  FakeV4l2Device dev;
  auto cfg = yuyv_config();
  cfg.width = 1280;
  cfg.height = 720;
  V4l2Capture cap(dev, cfg);
  std::string error;
  EXPECT_FALSE(cap.open(error));
  EXPECT_NE(error.find("driver offers YUYV 640x480"), std::string::npos) << error;
}

TEST(V4l2Capture, RateClampedOrUnsupportedStillStreams) {
  FakeV4l2Device dev;
  V4l2Capture cap(dev, yuyv_config(60));
  std::string error;
  ASSERT_TRUE(cap.open(error)) << error;
  EXPECT_EQ(cap.negotiated().interval_den, 30u);  // the device's maximum

  FakeV4l2Device fixed;
  fixed.s_parm_supported = false;
  V4l2Capture cap2(fixed, yuyv_config(60));
  ASSERT_TRUE(cap2.open(error)) << error;
  EXPECT_EQ(cap2.negotiated().interval_den, 0u);
}

TEST(V4l2Capture, FewerBuffersGrantedIsFineButOneIsNot) {
  FakeV4l2Device dev;
  dev.max_buffers = 2;
  V4l2Capture cap(dev, yuyv_config(15, 6));
  std::string error;
  ASSERT_TRUE(cap.open(error)) << error;
  EXPECT_EQ(cap.negotiated().buffer_count, 2u);

  FakeV4l2Device one;
  one.max_buffers = 1;
  V4l2Capture cap1(one, yuyv_config());
  EXPECT_FALSE(cap1.open(error));
  EXPECT_NE(error.find("granted 1 buffers"), std::string::npos) << error;
  EXPECT_EQ(one.mapped, 0);
}

TEST(V4l2Capture, NonCaptureNodeAndMissingDeviceAreErrors) {
  FakeV4l2Device dev;
  dev.device_caps = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING;
  V4l2Capture cap(dev, yuyv_config());
  std::string error;
  EXPECT_FALSE(cap.open(error));
  EXPECT_NE(error.find("not a streaming video capture node"), std::string::npos) << error;

  FakeV4l2Device none;
  auto cfg = yuyv_config();
  cfg.device = "/dev/video7";
  V4l2Capture cap2(none, cfg);
  EXPECT_FALSE(cap2.open(error));
  EXPECT_NE(error.find("/dev/video7: open failed: No such file"), std::string::npos) << error;
}

TEST(V4l2Capture, BuffersCycleThroughTheRingWithoutCopies) {
  FakeV4l2Device dev;
  V4l2Capture cap(dev, yuyv_config(15, 3));
  std::string error;
  ASSERT_TRUE(cap.open(error)) << error;
  for (std::uint32_t i = 0; i < 10; ++i) dev.add_frame(i, kYuyvBytes, static_cast<std::uint8_t>(i));
  std::vector<const std::byte*> addresses;
  for (std::uint32_t i = 0; i < 10; ++i) {
    V4l2Frame f;
    ASSERT_EQ(cap.next(f, kTimeout), CaptureStatus::kFrame) << i << " " << cap.last_error();
    EXPECT_EQ(f.sequence, i);
    EXPECT_EQ(f.buffer_index, i % 3);
    ASSERT_EQ(f.bytes.size(), kYuyvBytes);
    EXPECT_EQ(f.bytes.front(), static_cast<std::byte>(i));
    EXPECT_EQ(f.bytes.back(), static_cast<std::byte>(i));
    addresses.push_back(f.bytes.data());
    // While the frame is held, the driver owns the other two buffers only.
    EXPECT_EQ(dev.queued.size(), 2u);
  }
  // The bytes are the driver's mapping itself: three distinct addresses, reused in turn.
  EXPECT_EQ(addresses[0], addresses[3]);
  EXPECT_NE(addresses[0], addresses[1]);
  EXPECT_EQ(cap.counters().frames, 10u);
  EXPECT_EQ(cap.counters().dropped, 0u);
  cap.release();
  EXPECT_EQ(dev.queued.size(), 3u);
  EXPECT_EQ(dev.count("QBUF"), 3 + 10);
}

TEST(V4l2Capture, SequenceGapsAreCountedAsDrops) {
  FakeV4l2Device dev;
  V4l2Capture cap(dev, yuyv_config());
  std::string error;
  ASSERT_TRUE(cap.open(error)) << error;
  for (std::uint32_t s : {5u, 6u, 9u, 10u, 14u}) dev.add_frame(s, 16, 0);
  std::vector<std::uint32_t> dropped;
  V4l2Frame f;
  while (cap.next(f, kTimeout) == CaptureStatus::kFrame) dropped.push_back(f.dropped_before);
  EXPECT_EQ(dropped, (std::vector<std::uint32_t>{0, 0, 2, 0, 3}));
  EXPECT_EQ(cap.counters().dropped, 5u);
  EXPECT_EQ(cap.counters().frames, 5u);
  EXPECT_EQ(cap.counters().timeouts, 1u);  // the loop's last call
}

TEST(V4l2Capture, DriverTimestampsCarryTheirClockAndPartialFramesAreFlagged) {
  FakeV4l2Device dev;
  V4l2Capture cap(dev, yuyv_config());
  std::string error;
  ASSERT_TRUE(cap.open(error)) << error;
  dev.add_frame(0, 100, 1, 1'234'567'890);
  dev.add_frame(1, 50, 2, 1'234'600'000, V4L2_BUF_FLAG_ERROR);
  FakeEvent copy;
  copy.payload.assign(8, std::byte{3});
  copy.sequence = 2;
  copy.stamp_us = 7;
  copy.clock_flags = V4L2_BUF_FLAG_TIMESTAMP_COPY;
  dev.script.push_back(copy);
  FakeEvent unknown = copy;
  unknown.sequence = 3;
  unknown.clock_flags = V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN;
  dev.script.push_back(unknown);

  V4l2Frame f;
  ASSERT_EQ(cap.next(f, kTimeout), CaptureStatus::kFrame);
  EXPECT_EQ(f.clock, TimestampClock::kMonotonic);
  EXPECT_TRUE(f.stamp_at_start_of_exposure);
  EXPECT_EQ(f.driver_stamp.ns, 1'234'567'890'000);
  EXPECT_FALSE(f.partial);
  EXPECT_GT(f.host_receive.ns, 0);
  ASSERT_EQ(cap.next(f, kTimeout), CaptureStatus::kFrame);
  EXPECT_TRUE(f.partial);
  EXPECT_EQ(f.bytes.size(), 50u);  // bytesused, not the buffer length
  ASSERT_EQ(cap.next(f, kTimeout), CaptureStatus::kFrame);
  EXPECT_EQ(f.clock, TimestampClock::kCopy);
  EXPECT_FALSE(f.stamp_at_start_of_exposure);
  ASSERT_EQ(cap.next(f, kTimeout), CaptureStatus::kFrame);
  EXPECT_EQ(f.clock, TimestampClock::kUnknown);
  EXPECT_EQ(cap.counters().partial, 1u);
}

TEST(V4l2Capture, TimeoutsAreStatusesNotErrors) {
  FakeV4l2Device dev;
  V4l2Capture cap(dev, yuyv_config());
  std::string error;
  ASSERT_TRUE(cap.open(error)) << error;
  dev.add(FakeEvent::Kind::kTimeout);
  dev.add_frame(0, 10, 9);
  V4l2Frame f;
  EXPECT_EQ(cap.next(f, kTimeout), CaptureStatus::kTimeout);
  EXPECT_EQ(cap.next(f, kTimeout), CaptureStatus::kFrame);
  EXPECT_EQ(cap.next(f, kTimeout), CaptureStatus::kTimeout);  // script empty
  EXPECT_EQ(cap.counters().timeouts, 2u);
  EXPECT_EQ(cap.counters().errors, 0u);

  V4l2Capture never_opened(dev, yuyv_config());
  EXPECT_EQ(never_opened.next(f, kTimeout), CaptureStatus::kError);
}

TEST(V4l2Capture, DisappearingDeviceIsReopenedWhenItReturns) {
  FakeV4l2Device dev;
  dev.failing_opens_after_disconnect = 2;
  V4l2Capture cap(dev, yuyv_config());
  std::string error;
  ASSERT_TRUE(cap.open(error)) << error;
  dev.add_frame(100, 10, 1);
  dev.add_frame(101, 10, 2);
  dev.add(FakeEvent::Kind::kDisconnect);
  V4l2Frame f;
  EXPECT_EQ(cap.next(f, kTimeout), CaptureStatus::kFrame);
  EXPECT_EQ(cap.next(f, kTimeout), CaptureStatus::kFrame);
  EXPECT_EQ(cap.next(f, kTimeout), CaptureStatus::kDeviceLost);
  EXPECT_NE(cap.last_error().find("/dev/video0"), std::string::npos);
  EXPECT_FALSE(cap.is_open());
  EXPECT_EQ(dev.mapped, 0);    // mappings released
  EXPECT_EQ(dev.open_fds, 0);  // descriptor closed
  // Two attempts while unplugged: each waits (without a descriptor) and fails.
  EXPECT_EQ(cap.next(f, kTimeout), CaptureStatus::kDeviceLost);
  EXPECT_EQ(cap.next(f, kTimeout), CaptureStatus::kDeviceLost);
  EXPECT_EQ(dev.waits, 2);
  // Plugged back in: the driver restarts its sequence at 0; that is not a drop.
  dev.add_frame(0, 10, 3);
  dev.add_frame(1, 10, 4);
  ASSERT_EQ(cap.next(f, kTimeout), CaptureStatus::kFrame) << cap.last_error();
  EXPECT_EQ(f.bytes.front(), std::byte{3});
  ASSERT_EQ(cap.next(f, kTimeout), CaptureStatus::kFrame);
  EXPECT_EQ(f.sequence, 1u);
  EXPECT_EQ(cap.counters().lost, 1u);
  EXPECT_EQ(cap.counters().reopened, 1u);
  EXPECT_EQ(cap.counters().dropped, 0u);
  EXPECT_EQ(dev.mapped, 4);
}

TEST(V4l2Capture, MetadataNodeNegotiatesItsFormat) {
  FakeV4l2Device dev;
  dev.device_caps = V4L2_CAP_META_CAPTURE | V4L2_CAP_STREAMING;
  dev.meta_formats = {fourcc('U', 'V', 'C', 'H')};
  dev.meta_buffer_bytes = 10240;
  V4l2CaptureConfig cfg;
  cfg.device = "/dev/video0";
  cfg.kind = V4l2NodeKind::kMetadata;
  V4l2Capture cap(dev, cfg);
  std::string error;
  ASSERT_TRUE(cap.open(error)) << error;
  EXPECT_EQ(cap.negotiated().frame_bytes, 10240u);
  EXPECT_EQ(dev.count("S_PARM"), 0);  // rate belongs to the video node

  FakeV4l2Device other;
  other.device_caps = V4L2_CAP_META_CAPTURE | V4L2_CAP_STREAMING;
  other.meta_formats = {fourcc('D', '4', 'X', 'X')};
  V4l2Capture cap2(other, cfg);
  EXPECT_FALSE(cap2.open(error));
  EXPECT_NE(error.find("metadata format UVCH not offered (driver has D4XX)"), std::string::npos)
      << error;
}

TEST(V4l2Capture, SerialResolvesThroughByIdLinks) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("posed-by-id-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (const char* n : {"usb-Intel_R__RealSense_TM__Depth_Camera_435i_843112070123-video-index0",
                        "usb-Intel_R__RealSense_TM__Depth_Camera_435i_843112070123-video-index1",
                        "usb-Guide_PLUG617_GD0042-video-index0"}) {
    std::ofstream(dir / n).put('x');
  }
  std::string error;
  EXPECT_EQ(
      resolve_v4l2_device("serial:843112070123", dir.string(), error),
      (dir / "usb-Intel_R__RealSense_TM__Depth_Camera_435i_843112070123-video-index0").string());
  EXPECT_EQ(
      resolve_v4l2_device("serial:843112070123:1", dir.string(), error),
      (dir / "usb-Intel_R__RealSense_TM__Depth_Camera_435i_843112070123-video-index1").string());
  EXPECT_EQ(resolve_v4l2_device("/dev/video3", dir.string(), error), "/dev/video3");
  EXPECT_EQ(resolve_v4l2_device("serial:999", dir.string(), error), "");
  EXPECT_NE(error.find("no " + dir.string() + " entry with serial '999'"), std::string::npos)
      << error;
  EXPECT_EQ(resolve_v4l2_device("serial:0", dir.string(), error), "");  // ambiguous
  EXPECT_NE(error.find("matches 2 devices"), std::string::npos) << error;
  fs::remove_all(dir);
  EXPECT_EQ(resolve_v4l2_device("serial:1", dir.string(), error), "");
  EXPECT_NE(error.find("cannot list"), std::string::npos) << error;
}

}  // namespace
}  // namespace posed::drivers::camera

namespace posed::drivers::camera {
namespace {

TEST(V4l2Enumerate, FormatsSizesAndRatesOfANode) {
  test::FakeV4l2Device dev;
  dev.modes = {{fourcc('Y', 'U', 'Y', 'V'), 640, 480, 2},
               {fourcc('Y', 'U', 'Y', 'V'), 1280, 720, 2},
               {fourcc('Z', '1', '6', ' '), 848, 480, 2}};
  dev.frame_rates = {60, 30, 15};
  V4l2NodeInfo info;
  std::string error;
  ASSERT_TRUE(query_v4l2_node(dev, "/dev/video0", info, error)) << error;
  EXPECT_EQ(info.card, "Fake Camera");
  EXPECT_EQ(info.driver, "uvcvideo");
  EXPECT_TRUE(info.video_capture);
  ASSERT_EQ(info.formats.size(), 2u);
  EXPECT_EQ(info.formats[0].fourcc, fourcc('Y', 'U', 'Y', 'V'));
  ASSERT_EQ(info.formats[0].sizes.size(), 2u);
  EXPECT_EQ(info.formats[0].sizes[1].width, 1280u);
  EXPECT_EQ(info.formats[0].sizes[1].rates_hz, (std::vector<double>{60, 30, 15}));
  EXPECT_EQ(info.formats[1].sizes[0].height, 480u);
  EXPECT_EQ(dev.open_fds, 0);

  test::FakeV4l2Device meta;
  meta.device_caps = V4L2_CAP_META_CAPTURE | V4L2_CAP_STREAMING;
  meta.meta_formats = {fourcc('D', '4', 'X', 'X')};
  ASSERT_TRUE(query_v4l2_node(meta, "/dev/video0", info, error)) << error;
  EXPECT_TRUE(info.meta_capture);
  ASSERT_EQ(info.formats.size(), 1u);
  EXPECT_TRUE(info.formats[0].sizes.empty());

  EXPECT_FALSE(query_v4l2_node(dev, "/dev/video3", info, error));
  EXPECT_NE(error.find("/dev/video3: open failed"), std::string::npos) << error;
}

TEST(V4l2Enumerate, ListsVideoNodesInNumericOrder) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("posed-dev-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (const char* n : {"video10", "video2", "video0", "videoX", "vhci", "video"}) {
    std::ofstream(dir / n).put('x');
  }
  const auto nodes = list_v4l2_nodes(dir.string());
  ASSERT_EQ(nodes.size(), 3u);
  EXPECT_EQ(fs::path(nodes[0]).filename(), "video0");
  EXPECT_EQ(fs::path(nodes[1]).filename(), "video2");
  EXPECT_EQ(fs::path(nodes[2]).filename(), "video10");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace posed::drivers::camera
