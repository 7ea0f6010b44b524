// Bad input is a status and a counter, never a crash: short, oversized, foreign and corrupted
// datagrams, and random bytes.

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "drivers/velodyne/packet_decoder.hpp"
#include "tests/unit/velodyne/packet_builder.hpp"

namespace posed::drivers::velodyne {
namespace {

TEST(VelodyneMalformed, EachKindIsCountedSeparately) {
  PacketDecoder decoder;
  auto out = std::make_unique<DecodedPacket>();
  const auto good = test::make_packet({});
  ASSERT_EQ(decoder.decode(good, *out), DecodeStatus::kOk);

  EXPECT_EQ(decoder.decode(std::span(good).first(1205), *out), DecodeStatus::kWrongSize);
  EXPECT_EQ(decoder.decode({}, *out), DecodeStatus::kWrongSize);
  std::vector<std::byte> big(good);
  big.push_back(std::byte{0});
  EXPECT_EQ(decoder.decode(big, *out), DecodeStatus::kWrongSize);
  EXPECT_EQ(decoder.decode(std::vector<std::byte>(512), *out), DecodeStatus::kWrongSize);

  auto flag = good;
  flag[5 * kBlockBytes + 1] = std::byte{0xDD};  // an HDL-64 lower-block flag
  EXPECT_EQ(decoder.decode(flag, *out), DecodeStatus::kBadBlockFlag);
  auto az = good;
  az[3 * kBlockBytes + 2] = std::byte{0xFF};
  az[3 * kBlockBytes + 3] = std::byte{0xFF};
  EXPECT_EQ(decoder.decode(az, *out), DecodeStatus::kBadAzimuth);
  auto mode = good;
  mode[kReturnModeOffset] = std::byte{0x40};
  EXPECT_EQ(decoder.decode(mode, *out), DecodeStatus::kUnknownReturnMode);
  auto product = good;
  product[kProductIdOffset] = std::byte{0xA0};  // not a 32/16-laser product we decode
  EXPECT_EQ(decoder.decode(product, *out), DecodeStatus::kUnknownProduct);
  // Locked onto the VLP-32C: a VLP-16 on the same port is foreign.
  EXPECT_EQ(decoder.decode(test::make_packet({.product = 0x22}), *out),
            DecodeStatus::kModelMismatch);

  const auto& c = decoder.counters();
  EXPECT_EQ(c.packets_ok, 1u);
  EXPECT_EQ(c.wrong_size, 4u);
  EXPECT_EQ(c.bad_block_flag, 1u);
  EXPECT_EQ(c.bad_azimuth, 1u);
  EXPECT_EQ(c.unknown_return_mode, 1u);
  EXPECT_EQ(c.unknown_product, 1u);
  EXPECT_EQ(c.model_mismatch, 1u);
  EXPECT_EQ(c.malformed(), 9u);
  // Still decodes good packets afterwards.
  EXPECT_EQ(decoder.decode(good, *out), DecodeStatus::kOk);
  EXPECT_EQ(out->point_count, 384u);
}

TEST(VelodyneMalformed, GarbageAzimuthsStayBounded) {
  PacketDecoder decoder;
  auto out = std::make_unique<DecodedPacket>();
  std::minstd_rand rng(7);
  for (int i = 0; i < 2000; ++i) {
    test::PacketSpec s;
    s.azimuth_cdeg = static_cast<std::uint32_t>(rng() % 36000);
    s.step_cdeg = static_cast<std::uint32_t>(rng() % 36000);  // wild jumps between blocks
    s.distance = [&](std::uint32_t, std::uint32_t) {
      return static_cast<std::uint16_t>(rng() & 0xFFFF);
    };
    ASSERT_EQ(decoder.decode(test::make_packet(s), *out), DecodeStatus::kOk);
    for (std::uint32_t k = 0; k < out->point_count; ++k) {
      const auto& p = out->points[k];
      ASSERT_LT(p.azimuth_cdeg, 36000);
      ASSERT_LE(std::fabs(p.x_m), 263.f);
      ASSERT_LE(std::fabs(p.y_m), 263.f);
      ASSERT_LE(std::fabs(p.z_m), 263.f);
    }
  }
}

TEST(VelodyneMalformed, RandomBytesNeverCrash) {
  PacketDecoder decoder;
  auto out = std::make_unique<DecodedPacket>();
  std::minstd_rand rng(42);
  std::uint64_t calls = 0;
  for (int i = 0; i < 3000; ++i) {
    std::vector<std::byte> bytes(i % 3 == 0 ? kDataPacketBytes
                                            : static_cast<std::size_t>(rng() % 1500));
    for (auto& b : bytes) b = static_cast<std::byte>(rng() & 0xFF);
    if (i % 2 == 0 && bytes.size() == kDataPacketBytes) {
      // mostly valid framing so the body gets exercised
      for (std::size_t blk = 0; blk < 12; ++blk) {
        bytes[blk * 100] = std::byte{0xFF};
        bytes[blk * 100 + 1] = std::byte{0xEE};
        bytes[blk * 100 + 3] = static_cast<std::byte>(rng() % 0x8C);
      }
      bytes[kReturnModeOffset] = std::byte{0x39};
      bytes[kProductIdOffset] = std::byte{0x28};
    }
    (void)decoder.decode(bytes, *out);
    ++calls;
  }
  const auto& c = decoder.counters();
  EXPECT_EQ(c.packets_ok + c.malformed(), calls);
  EXPECT_GT(c.packets_ok, 0u);
}

}  // namespace
}  // namespace posed::drivers::velodyne
