// D4xx metadata on byte layouts built field by field from librealsense src/metadata.h and
// linux/uvcvideo.h (struct uvc_meta_buf), as a D435i depth node delivers them.
#include "drivers/camera/d4xx_metadata.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "tests/unit/camera/d4xx_metadata_bytes.hpp"

namespace posed::drivers::camera {
namespace {

using test::Bytes;
using test::depth_metadata;

TEST(D4xxMetadata, ParsesDepthFrameBlocks) {
  for (std::uint32_t extra : {0u, 8u}) {  // md_size without / with the header counted
    const Bytes b = depth_metadata(extra);
    D4xxFrameMetadata md;
    ASSERT_EQ(parse_d4xx_metadata(b.v, md), MetadataStatus::kOk) << extra;
    EXPECT_EQ(md.host_sof_ns, 123'456'789'000u);
    EXPECT_EQ(md.usb_sof, 0x2A5);
    EXPECT_TRUE(md.has_pts);
    EXPECT_EQ(md.pts_us, 0x89ABCDEFu);
    EXPECT_TRUE(md.has_scr);
    EXPECT_EQ(md.scr_stc_us, 0x01020304u);
    EXPECT_EQ(md.scr_sof, 0x0456);
    ASSERT_TRUE(md.has_capture_timing);
    EXPECT_EQ(md.frame_counter, 4242u);
    EXPECT_EQ(md.sensor_timestamp_us, 0xFFFFFF00u);
    EXPECT_EQ(md.readout_time_us, 15000u);
    EXPECT_EQ(md.exposure_time_us, 8250u);
    EXPECT_EQ(md.frame_interval_us, 33333u);
    EXPECT_EQ(md.pipe_latency_us, 900u);
    ASSERT_TRUE(md.has_gain);
    EXPECT_EQ(md.gain, 16u);
    EXPECT_EQ(md.control_exposure, 33000u);
    EXPECT_EQ(md.laser_power, 150u);
    EXPECT_EQ(md.auto_exposure_mode, 1u);
    ASSERT_TRUE(md.has_configuration);
    EXPECT_EQ(md.width_px, 848);
    EXPECT_EQ(md.height_px, 480);
    EXPECT_EQ(md.fps, 30);
    EXPECT_EQ(md.format, 0x0B);
    EXPECT_EQ(md.calibration_count, 5);
  }
}

TEST(D4xxMetadata, RgbControlGainAndExposure) {
  Bytes b;
  b.u64(1);
  b.u16(2);
  b.u8(2 + 8 + 64);
  b.u8(0x80);  // EOH only: no PTS/SCR
  b.u32(kMdRgbControlId);
  b.u32(64);
  const std::uint32_t fields[16] = {2,  0x3FFF, 10,  50, 64,  50,   1, 4600,
                                    64, 0,      300, 0,  156, 4600, 1, 0};
  for (auto f : fields) b.u32(f);
  D4xxFrameMetadata md;
  ASSERT_EQ(parse_d4xx_metadata(b.v, md), MetadataStatus::kOk);
  EXPECT_FALSE(md.has_pts);
  EXPECT_FALSE(md.has_capture_timing);
  EXPECT_EQ(md.auto_exposure_mode, 1u);
  EXPECT_EQ(md.gain, 64u);
  EXPECT_EQ(md.control_exposure, 156u);
}

TEST(D4xxMetadata, BadInputIsAStatus) {
  D4xxFrameMetadata md;
  EXPECT_EQ(parse_d4xx_metadata({}, md), MetadataStatus::kTooShort);
  Bytes b = depth_metadata(0);
  // bHeaderLength longer than the buffer
  auto cut = b.v;
  cut.resize(60);
  EXPECT_EQ(parse_d4xx_metadata(cut, md), MetadataStatus::kTooShort);
  // A block running past bHeaderLength
  auto bad = b.v;
  bad[10] = static_cast<std::byte>(2 + 10 + 20);
  EXPECT_EQ(parse_d4xx_metadata(bad, md), MetadataStatus::kMalformed);
  // Plain UVC header (metadata disabled in firmware): no Intel blocks
  Bytes plain;
  plain.u64(5);
  plain.u16(6);
  plain.u8(12);
  plain.u8(0x8C);
  plain.zeros(10);
  EXPECT_EQ(parse_d4xx_metadata(plain.v, md), MetadataStatus::kNoIntelBlocks);
  EXPECT_EQ(md.host_sof_ns, 5u);
  EXPECT_TRUE(md.has_pts);
}

}  // namespace
}  // namespace posed::drivers::camera
