// The Aravis path end to end against Aravis's own GigE Vision fake camera, run in this process
// on loopback (GVCP control + GVSP stream over real UDP sockets): discovery, feature
// configuration, buffer cycling, frame ids and device stamps, and injected packet loss
// (the fake's "gvsp-lost-ratio") arriving as a frame status rather than an error.

#include <arv.h>
#include <gtest/gtest.h>

#include "drivers/camera/aravis_source.hpp"
#include "drivers/camera/frame_decoder.hpp"

namespace posed::drivers::camera {
namespace {

struct FakeGvCamera {
  explicit FakeGvCamera(const char* serial, double lost_ratio = 0.0) {
    fake = ARV_GV_FAKE_CAMERA(g_object_new(ARV_TYPE_GV_FAKE_CAMERA, "interface-name", "127.0.0.1",
                                           "serial-number", serial, "gvsp-lost-ratio", lost_ratio,
                                           nullptr));
  }
  ~FakeGvCamera() { g_clear_object(&fake); }
  ArvGvFakeCamera* fake = nullptr;
};

std::string find_id(const std::string& serial) {
  for (const auto& d : list_aravis_devices(false)) {
    if (d.serial == serial) return d.id;
  }
  return {};
}

TEST(AravisFakeCamera, StreamsMono16FramesWithConfiguredFeatures) {
  FakeGvCamera sim("POSED1");
  if (sim.fake == nullptr || !arv_gv_fake_camera_is_running(sim.fake)) {
    GTEST_SKIP() << "Aravis GigE fake camera could not bind 127.0.0.1 (no loopback?)";
  }
  const std::string id = find_id("POSED1");
  ASSERT_FALSE(id.empty()) << "fake camera not discovered on loopback";

  AravisConfig cfg;
  cfg.camera_id = id;
  cfg.pixel_format = "Mono16";
  cfg.width = 640;
  cfg.height = 512;
  cfg.frame_rate_hz = 50;
  cfg.exposure_time_us = 2000;
  cfg.buffer_count = 4;
  // A feature the camera does not have fails the open, naming it (the fake has GainRaw only).
  cfg.features = {"Gain=3"};
  std::string error;
  {
    AravisSource bad("thermal", cfg);
    EXPECT_FALSE(bad.open(error));
    EXPECT_NE(error.find("feature Gain=3"), std::string::npos) << error;
  }
  cfg.features = {"GainRaw=3"};
  AravisSource source("thermal", cfg);
  ASSERT_TRUE(source.open(error)) << error;
  EXPECT_EQ(source.width(), 640u);
  EXPECT_EQ(source.height(), 512u);
  EXPECT_EQ(source.format(), WireFormat::kY16);

  FrameDecoderConfig dc;
  dc.format = source.format();
  dc.width = source.width();
  dc.height = source.height();
  dc.y16_agc_to_mono8 = true;
  FrameDecoder decoder(dc);
  PayloadPool pool(2, decoder.output_bytes());

  int frames = 0;
  std::uint64_t last_id = 0;
  std::int64_t last_stamp = 0;
#if defined(__SANITIZE_THREAD__)
  // ThreadSanitizer slows the fake camera's 0.66 MB frames through loopback UDP to a few a
  // minute; give it ten times the reads, as tools/sanitize-pipeline gives its tests 10x time.
  constexpr int kReads = 1000;
#else
  constexpr int kReads = 100;
#endif
  for (int attempt = 0; attempt < kReads && frames < 8; ++attempt) {
    RawChunk chunk;
    const ReadStatus s = source.read(chunk, Duration::from_ms(500));
    if (s == ReadStatus::kTimeout) continue;
    ASSERT_EQ(s, ReadStatus::kData);
    const AravisFrame& f = source.last_frame();
    EXPECT_EQ(f.status, AravisFrameStatus::kComplete);
    EXPECT_EQ(chunk.bytes.size(), 640u * 512u * 2u);
    EXPECT_EQ(f.width, 640u);
    if (frames > 0) {
      EXPECT_GT(f.frame_id, last_id);
      EXPECT_GT(f.device_stamp.ns, last_stamp);
    }
    last_id = f.frame_id;
    last_stamp = f.device_stamp.ns;
    Image img;
    EXPECT_EQ(decoder.decode(chunk.bytes, f.frame_id, pool, img), DecodeStatus::kOk);
    ++frames;
  }
  EXPECT_EQ(frames, 8);
  EXPECT_EQ(source.frame_counters().incomplete, 0u);
  EXPECT_EQ(source.counters().chunks, 8u);
  source.request_stop();
  RawChunk chunk;
  EXPECT_EQ(source.read(chunk, Duration::from_ms(10)), ReadStatus::kEndOfStream);
}

TEST(AravisFakeCamera, PacketLossIsAFrameStatusNotAnError) {
  FakeGvCamera sim("POSED2", 0.05);
  if (sim.fake == nullptr || !arv_gv_fake_camera_is_running(sim.fake)) {
    GTEST_SKIP() << "Aravis GigE fake camera could not bind 127.0.0.1 (no loopback?)";
  }
  const std::string id = find_id("POSED2");
  ASSERT_FALSE(id.empty());
  AravisConfig cfg;
  cfg.camera_id = id;
  cfg.pixel_format = "Mono8";
  cfg.width = 640;
  cfg.height = 512;
  cfg.frame_rate_hz = 50;
  cfg.packet_resend = false;  // report the loss instead of recovering it
  AravisSource source("thermal", cfg);
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  EXPECT_EQ(source.format(), WireFormat::kY8);
  int data = 0, partial = 0;
  for (int attempt = 0; attempt < 100 && data < 10; ++attempt) {
    RawChunk chunk;
    const ReadStatus s = source.read(chunk, Duration::from_ms(500));
    if (s == ReadStatus::kTimeout) continue;
    ASSERT_EQ(s, ReadStatus::kData);  // never an error
    ++data;
    if (source.last_frame().status != AravisFrameStatus::kComplete) ++partial;
  }
  EXPECT_EQ(data, 10);
  // 5 % of ~400 packets per frame lost: practically every frame misses some.
  EXPECT_GT(partial, 5);
  EXPECT_EQ(source.frame_counters().incomplete, static_cast<std::uint64_t>(partial));
}

TEST(AravisFakeCamera, UnknownCameraFailsWithItsName) {
  AravisConfig cfg;
  cfg.camera_id = "NoSuchVendor-NOPE42";
  AravisSource source("thermal", cfg);
  std::string error;
  EXPECT_FALSE(source.open(error));
  EXPECT_NE(error.find("NoSuchVendor-NOPE42"), std::string::npos) << error;
}

}  // namespace
}  // namespace posed::drivers::camera
