#include "drivers/camera/thermal_agc.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <vector>

#include "tests/common/realdata.hpp"

namespace posed::drivers::camera {
namespace {

constexpr std::uint32_t kW = 640, kH = 512;

std::vector<std::uint16_t> load_real_frame() {
  const auto dir = test::realdata_dir();
  if (dir.empty()) return {};
  const auto raw = test::read_bytes(dir / "thermal_16bit" / "frame_000000_640x512_u16le.raw");
  if (raw.size() != kW * kH * 2) return {};
  std::vector<std::uint16_t> px(kW * kH);
  for (std::size_t i = 0; i < px.size(); ++i) {
    px[i] = static_cast<std::uint16_t>(raw[2 * i] | (raw[2 * i + 1] << 8));
  }
  return px;
}

#define LOAD_OR_SKIP(px)                                                      \
  const auto px = load_real_frame();                                          \
  if (px.empty())                                                             \
    GTEST_SKIP() << "thermal_16bit/frame_000000_640x512_u16le.raw not found " \
                    "($POSED_REALDATA or $POSED_SOURCE_DIR/../shared/realdata)";

std::array<std::uint64_t, 256> histogram8(const std::vector<std::uint8_t>& v) {
  std::array<std::uint64_t, 256> h{};
  for (auto x : v) ++h[x];
  return h;
}

TEST(ThermalAgc, PercentileStretchOnRealFrame) {
  LOAD_OR_SKIP(px);
  AgcConfig cfg;
  cfg.low_percentile = 2.0;
  cfg.high_percentile = 98.0;
  ThermalAgc agc(cfg);
  std::vector<std::uint8_t> out(kW * kH);
  const AgcStats s = agc.apply(px.data(), kW * 2, out.data(), kW, kW, kH);

  // The raw frame really is 16-bit counts in a narrow band (not already 8-bit).
  EXPECT_LT(s.min_count, s.low_count);
  EXPECT_LT(s.low_count, s.high_count);
  EXPECT_LT(s.high_count, s.max_count);
  EXPECT_GT(s.max_count, 255);
  // Percentiles as configured, measured on the raw counts independently of the AGC.
  auto sorted = px;
  std::sort(sorted.begin(), sorted.end());
  const auto n = static_cast<double>(sorted.size());
  EXPECT_EQ(s.low_count, sorted[static_cast<std::size_t>(std::ceil(0.02 * n)) - 1]);
  EXPECT_EQ(s.high_count, sorted[static_cast<std::size_t>(std::ceil(0.98 * n)) - 1]);

  // Full range used, and the clipped tails hold ~2 % each (ties at the percentile count may
  // add a little).
  const auto h = histogram8(out);
  const double frac0 = static_cast<double>(h[0]) / n;
  const double frac255 = static_cast<double>(h[255]) / n;
  EXPECT_GE(frac0, 0.02);
  EXPECT_LT(frac0, 0.03);
  EXPECT_GE(frac255, 0.02 - 1.0 / n);
  EXPECT_LT(frac255, 0.03);
  // This scene spans only ~60 counts between the percentiles (115 distinct counts in all), so
  // the stretch must keep every distinct count inside the band distinct (255 levels > 60 counts):
  // no posterisation beyond what the sensor delivered.
  int used = 0;
  for (auto c : h) used += c > 0 ? 1 : 0;
  std::vector<std::uint16_t> band;
  for (auto c : sorted) {
    if (c >= s.low_count && c <= s.high_count && (band.empty() || band.back() != c)) {
      band.push_back(c);
    }
  }
  EXPECT_EQ(used, static_cast<int>(band.size()));
  EXPECT_GT(used, 40);

  // A function of the count alone, and monotonic: brighter counts never map darker.
  std::vector<int> mapped(65536, -1);
  for (std::size_t i = 0; i < px.size(); ++i) {
    ASSERT_TRUE(mapped[px[i]] < 0 || mapped[px[i]] == out[i]);
    mapped[px[i]] = out[i];
  }
  int last = 0;
  for (int m : mapped) {
    if (m < 0) continue;
    EXPECT_GE(m, last);
    last = m;
  }

  // Deterministic: a second run (same object, and a fresh one) gives identical bytes.
  std::vector<std::uint8_t> again(kW * kH), fresh(kW * kH);
  agc.apply(px.data(), kW * 2, again.data(), kW, kW, kH);
  ThermalAgc(cfg).apply(px.data(), kW * 2, fresh.data(), kW, kW, kH);
  EXPECT_EQ(out, again);
  EXPECT_EQ(out, fresh);
}

TEST(ThermalAgc, HistogramEqualisationOnRealFrame) {
  LOAD_OR_SKIP(px);
  AgcConfig cfg;
  cfg.mode = AgcMode::kHistogramEqualisation;
  ThermalAgc agc(cfg);
  std::vector<std::uint8_t> out(kW * kH);
  agc.apply(px.data(), kW * 2, out.data(), kW, kW, kH);
  const auto h = histogram8(out);
  EXPECT_GT(h[0], 0u);
  EXPECT_GT(h[255], 0u);
  // Equalised: the output CDF is close to linear, e.g. ~half the pixels below 128.
  std::uint64_t below = 0;
  for (int i = 0; i < 128; ++i) below += h[static_cast<std::size_t>(i)];
  const double frac = static_cast<double>(below) / static_cast<double>(out.size());
  EXPECT_NEAR(frac, 0.5, 0.05);
  std::uint64_t below64 = 0;
  for (int i = 0; i < 64; ++i) below64 += h[static_cast<std::size_t>(i)];
  EXPECT_NEAR(static_cast<double>(below64) / static_cast<double>(out.size()), 0.25, 0.05);
}

TEST(ThermalAgc, FlatSceneStaysGreyAndStridesWork) {
  // 4x2 frame, all 1000 counts except one 1004, with 4 bytes of padding per source row.
  std::vector<std::uint16_t> src(6 * 2, 0xBEEF);
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 4; ++c) src[static_cast<std::size_t>(r * 6 + c)] = 1000;
  src[5 * 0 + 1] = 1004;
  std::vector<std::uint8_t> out(5 * 2, 0xAA);
  ThermalAgc agc;  // min span 16 counts
  const auto s = agc.apply(src.data(), 12, out.data(), 5, 4, 2);
  EXPECT_EQ(s.min_count, 1000);
  EXPECT_EQ(s.max_count, 1004);
  EXPECT_EQ(s.high_count - s.low_count, 16);
  // 1000 maps to mid-grey, not to black; 4 counts of noise are not stretched to white.
  EXPECT_GT(out[0], 64);
  EXPECT_LT(out[0], 192);
  EXPECT_LT(out[1] - out[0], 80);
  EXPECT_GT(out[1], out[0]);
  EXPECT_EQ(out[4], 0xAA);  // destination padding untouched
}

}  // namespace
}  // namespace posed::drivers::camera
