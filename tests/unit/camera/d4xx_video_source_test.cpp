// D4xxVideoSource: a D435i video node and its uvcvideo metadata node, both fakes on one bus,
// paired by sequence; metadata goes out on channel 1 just before its frame on channel 0.
#include "drivers/camera/d4xx_video_source.hpp"

#include <gtest/gtest.h>

#include "drivers/camera/d4xx_metadata_latch.hpp"
#include "drivers/common/wire_format.hpp"
#include "tests/unit/camera/d4xx_metadata_bytes.hpp"
#include "tests/unit/camera/fake_v4l2_device.hpp"

namespace posed::drivers::camera {
namespace {

using test::FakeEvent;
using test::FakeV4l2Bus;
using test::FakeV4l2Device;

constexpr std::size_t kDepthBytes = 8 * 4 * 2;

struct Rig {
  FakeV4l2Bus bus;
  FakeV4l2Device video, meta;
  D4xxVideoConfig cfg;
  Rig() {
    video.modes = {{fourcc('Z', '1', '6', ' '), 8, 4, 2}};
    meta.device_caps = V4L2_CAP_META_CAPTURE | V4L2_CAP_STREAMING;
    meta.meta_formats = {fourcc('D', '4', 'X', 'X')};
    meta.meta_buffer_bytes = 4096;
    bus.attach("/dev/video0", video);
    bus.attach("/dev/video1", meta);
    cfg.video.device = "/dev/video0";
    cfg.video.format = WireFormat::kZ16;
    cfg.video.width = 8;
    cfg.video.height = 4;
  }
  void frame(std::uint32_t seq) {
    video.add_frame(seq, kDepthBytes, static_cast<std::uint8_t>(seq));
  }
  void metadata(std::uint32_t seq) {
    FakeEvent e;
    e.payload = test::depth_metadata(0, /*frame_counter=*/1000 + seq).v;
    e.sequence = seq;
    meta.script.push_back(std::move(e));
  }
};

const Duration kReadTimeout = Duration::from_ms(50);

TEST(CompanionMetadataNode, FollowsUvcvideoNodeOrder) {
  EXPECT_EQ(companion_metadata_node("/dev/video4"), "/dev/video5");
  EXPECT_EQ(companion_metadata_node("/dev/v4l/by-id/usb-Intel_D435I_123-video-index2"),
            "/dev/v4l/by-id/usb-Intel_D435I_123-video-index3");
  EXPECT_EQ(companion_metadata_node("serial:843112070123"), "serial:843112070123:1");
  EXPECT_EQ(companion_metadata_node("serial:843112070123:2"), "serial:843112070123:3");
  EXPECT_EQ(companion_metadata_node("/dev/camera"), "");
  EXPECT_EQ(companion_metadata_node("/dev/sda1"), "");
}

TEST(D4xxVideoSource, MetadataPrecedesItsFrameAndTheLatchHandsItOver) {
  Rig r;
  D4xxVideoSource source("depth", r.bus, r.cfg);
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  EXPECT_EQ(source.metadata_capture().path(), "/dev/video1");
  EXPECT_EQ(source.metadata_capture().negotiated().fourcc, fourcc('D', '4', 'X', 'X'));
  EXPECT_EQ(source.wire_format(0), "z16");
  EXPECT_EQ(source.wire_format(1), wire::kUvcMetaD4xx);
  for (std::uint32_t s = 0; s < 3; ++s) {
    r.frame(s);
    r.metadata(s);
  }
  D4xxMetadataLatch latch;
  for (std::uint32_t s = 0; s < 3; ++s) {
    RawChunk chunk;
    ASSERT_EQ(source.read(chunk, kReadTimeout), ReadStatus::kData);
    ASSERT_EQ(chunk.channel, 1u) << s;
    EXPECT_EQ(source.last_metadata().sequence, s);
    EXPECT_EQ(latch.on_metadata(chunk.bytes), MetadataStatus::kOk);
    ASSERT_EQ(source.read(chunk, kReadTimeout), ReadStatus::kData);
    ASSERT_EQ(chunk.channel, 0u);
    EXPECT_EQ(chunk.bytes.size(), kDepthBytes);
    EXPECT_EQ(chunk.bytes.front(), static_cast<std::byte>(s));
    const D4xxFrameMetadata* md = latch.on_frame();
    ASSERT_NE(md, nullptr);
    EXPECT_EQ(md->frame_counter, 1000 + s);
  }
  EXPECT_EQ(source.pairing_counters().frames_with_metadata, 3u);
  EXPECT_EQ(source.pairing_counters().frames_without_metadata, 0u);
  EXPECT_EQ(source.counters().chunks, 6u);
  RawChunk chunk;
  EXPECT_EQ(source.read(chunk, kReadTimeout), ReadStatus::kTimeout);
  source.request_stop();
  EXPECT_EQ(source.read(chunk, kReadTimeout), ReadStatus::kEndOfStream);
  EXPECT_EQ(r.video.open_fds + r.meta.open_fds, 0);
}

TEST(D4xxVideoSource, MissingMetadataBufferLeavesTheFrameAloneAndKeepsLaterPairs) {
  Rig r;
  D4xxVideoSource source("colour", r.bus, r.cfg);
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  // Frames 0..3; the metadata node lost the buffer of frame 1.
  for (std::uint32_t s = 0; s < 4; ++s) r.frame(s);
  for (std::uint32_t s : {0u, 2u, 3u}) r.metadata(s);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> got;  // (channel, sequence)
  D4xxMetadataLatch latch;
  std::vector<bool> frame_had_metadata;
  RawChunk chunk;
  while (source.read(chunk, kReadTimeout) == ReadStatus::kData) {
    if (chunk.channel == 1) {
      latch.on_metadata(chunk.bytes);
      got.emplace_back(1, source.last_metadata().sequence);
    } else {
      frame_had_metadata.push_back(latch.on_frame() != nullptr);
      got.emplace_back(0, source.last_frame().sequence);
    }
  }
  const std::vector<std::pair<std::uint32_t, std::uint32_t>> expected{
      {1, 0}, {0, 0}, {0, 1}, {1, 2}, {0, 2}, {1, 3}, {0, 3}};
  EXPECT_EQ(got, expected);
  EXPECT_EQ(frame_had_metadata, (std::vector<bool>{true, false, true, true}));
  EXPECT_EQ(source.pairing_counters().frames_without_metadata, 1u);
  EXPECT_EQ(source.pairing_counters().frames_with_metadata, 3u);
  EXPECT_EQ(latch.counters().frames_without, 1u);
}

TEST(D4xxVideoSource, DroppedFramesOrphanTheirMetadataWithoutShiftingThePairs) {
  Rig r;
  D4xxVideoSource source("depth", r.bus, r.cfg);
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  // The video node dropped frames 1 and 2 (no free buffer); the metadata node delivered them.
  for (std::uint32_t s : {0u, 3u, 4u}) r.frame(s);
  for (std::uint32_t s = 0; s < 5; ++s) r.metadata(s);
  std::vector<std::uint32_t> paired;
  RawChunk chunk;
  std::uint32_t md_seq = 0;
  while (source.read(chunk, kReadTimeout) == ReadStatus::kData) {
    if (chunk.channel == 1) {
      md_seq = source.last_metadata().sequence;
    } else {
      EXPECT_EQ(md_seq, source.last_frame().sequence);
      paired.push_back(source.last_frame().sequence);
    }
  }
  EXPECT_EQ(paired, (std::vector<std::uint32_t>{0, 3, 4}));
  EXPECT_EQ(source.pairing_counters().metadata_orphaned, 2u);
  EXPECT_EQ(source.video_capture().counters().dropped, 2u);
  EXPECT_EQ(source.pairing_counters().frames_with_metadata, 3u);
}

TEST(D4xxVideoSource, MetadataNodeMissingIsLoggedOnceAndFramesStillFlow) {
  Rig r;
  r.cfg.metadata_device = "/dev/video9";  // not there
  D4xxVideoSource source("colour", r.bus, r.cfg);
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  EXPECT_EQ(source.pairing_counters().metadata_open_failures, 1u);
  r.frame(0);
  r.frame(1);
  RawChunk chunk;
  ASSERT_EQ(source.read(chunk, kReadTimeout), ReadStatus::kData);
  EXPECT_EQ(chunk.channel, 0u);
  ASSERT_EQ(source.read(chunk, kReadTimeout), ReadStatus::kData);
  EXPECT_EQ(chunk.channel, 0u);
  EXPECT_EQ(source.pairing_counters().frames_without_metadata, 2u);
}

TEST(D4xxVideoSource, MetadataNodeOfferingUvchIsAcceptedAndDisabledMetadataSkipsIt) {
  Rig r;
  r.meta.meta_formats = {fourcc('U', 'V', 'C', 'H')};
  D4xxVideoSource source("depth", r.bus, r.cfg);
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  EXPECT_TRUE(source.metadata_capture().is_open());
  EXPECT_EQ(source.metadata_capture().negotiated().fourcc, fourcc('U', 'V', 'C', 'H'));

  Rig off;
  off.cfg.metadata = false;
  D4xxVideoSource plain("depth", off.bus, off.cfg);
  ASSERT_TRUE(plain.open(error)) << error;
  EXPECT_FALSE(plain.metadata_capture().is_open());
  EXPECT_EQ(plain.wire_format(1), "");
  off.frame(0);
  off.metadata(0);
  RawChunk chunk;
  ASSERT_EQ(plain.read(chunk, kReadTimeout), ReadStatus::kData);
  EXPECT_EQ(chunk.channel, 0u);
}

TEST(D4xxVideoSource, UnplugClosesBothNodesAndReplugPairsAgainFromSequenceZero) {
  Rig r;
  D4xxVideoSource source("depth", r.bus, r.cfg);
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  r.frame(7);
  r.metadata(7);
  r.video.add(FakeEvent::Kind::kDisconnect);
  RawChunk chunk;
  ASSERT_EQ(source.read(chunk, kReadTimeout), ReadStatus::kData);
  ASSERT_EQ(source.read(chunk, kReadTimeout), ReadStatus::kData);
  EXPECT_EQ(source.read(chunk, kReadTimeout), ReadStatus::kDeviceLost);
  EXPECT_EQ(r.video.open_fds, 0);
  EXPECT_EQ(r.meta.open_fds, 0);  // closed with the video node
  // Back: both nodes restart at sequence 0.
  r.frame(0);
  r.metadata(0);
  ASSERT_EQ(source.read(chunk, kReadTimeout), ReadStatus::kData);
  EXPECT_EQ(chunk.channel, 1u);
  ASSERT_EQ(source.read(chunk, kReadTimeout), ReadStatus::kData);
  EXPECT_EQ(chunk.channel, 0u);
  EXPECT_EQ(source.counters().reopened, 1u);
  EXPECT_EQ(source.pairing_counters().frames_with_metadata, 2u);
}

TEST(D4xxMetadataLatch, BadAndUnusedMetadataAreCounted) {
  D4xxMetadataLatch latch;
  const std::vector<std::byte> junk(5, std::byte{1});
  EXPECT_EQ(latch.on_metadata(junk), MetadataStatus::kTooShort);
  EXPECT_EQ(latch.on_frame(), nullptr);
  const auto good = test::depth_metadata(0).v;
  latch.on_metadata(good);
  latch.on_metadata(good);  // the first one never met a frame
  EXPECT_NE(latch.on_frame(), nullptr);
  EXPECT_EQ(latch.on_frame(), nullptr);
  EXPECT_EQ(latch.counters().metadata_bad, 1u);
  EXPECT_EQ(latch.counters().metadata_unused, 1u);
  EXPECT_EQ(latch.counters().frames_with, 1u);
  EXPECT_EQ(latch.counters().frames_without, 2u);
}

}  // namespace
}  // namespace posed::drivers::camera
