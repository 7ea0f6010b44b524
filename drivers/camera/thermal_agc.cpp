#include "drivers/camera/thermal_agc.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace posed::drivers::camera {
namespace {
constexpr std::size_t kBins = 65536;

/// Smallest count c with (pixels <= c) >= rank, scanning bins [lo, hi].
std::uint32_t count_at_rank(const std::uint32_t* hist, std::uint32_t lo, std::uint32_t hi,
                            std::uint64_t rank) {
  std::uint64_t cum = 0;
  for (std::uint32_t c = lo; c <= hi; ++c) {
    cum += hist[c];
    if (cum >= rank) return c;
  }
  return hi;
}
}  // namespace

std::string_view to_string(AgcMode m) {
  return m == AgcMode::kPercentileStretch ? "percentile" : "equalise";
}

ThermalAgc::ThermalAgc(AgcConfig config)
    : config_(config),
      histogram_(std::make_unique<std::uint32_t[]>(kBins)),
      lut_(std::make_unique<std::uint8_t[]>(kBins)) {
  config_.low_percentile = std::clamp(config_.low_percentile, 0.0, 100.0);
  config_.high_percentile = std::clamp(config_.high_percentile, config_.low_percentile, 100.0);
}

AgcStats ThermalAgc::apply(const std::uint16_t* src, std::uint32_t src_stride_bytes,
                           std::uint8_t* dst, std::uint32_t dst_stride_bytes, std::uint32_t width,
                           std::uint32_t height) {
  AgcStats stats;
  const std::uint64_t n = static_cast<std::uint64_t>(width) * height;
  if (n == 0) return stats;
  std::uint32_t* hist = histogram_.get();
  std::memset(hist, 0, kBins * sizeof(std::uint32_t));
  for (std::uint32_t r = 0; r < height; ++r) {
    const auto* s =
        reinterpret_cast<const std::uint16_t*>(reinterpret_cast<const std::uint8_t*>(src) +
                                               static_cast<std::size_t>(r) * src_stride_bytes);
    for (std::uint32_t x = 0; x < width; ++x) ++hist[s[x]];
  }
  // Bounds from the histogram rather than per pixel: one pass over 64k bins beats a compare per
  // pixel, and the later scans then only cover the occupied band.
  std::uint32_t lo_seen = 0;
  while (hist[lo_seen] == 0) ++lo_seen;  // terminates: n > 0 pixels were counted
  std::uint32_t hi_seen = 0xFFFF;
  while (hist[hi_seen] == 0) --hi_seen;
  stats.min_count = static_cast<std::uint16_t>(lo_seen);
  stats.max_count = static_cast<std::uint16_t>(hi_seen);

  std::uint8_t* lut = lut_.get();
  if (config_.mode == AgcMode::kPercentileStretch) {
    // Nearest-rank percentiles: at least p% of pixels lie at or below the chosen count.
    const auto rank = [&](double p) {
      return std::max<std::uint64_t>(
          1, static_cast<std::uint64_t>(std::ceil(p / 100.0 * static_cast<double>(n))));
    };
    std::uint32_t lo = count_at_rank(hist, lo_seen, hi_seen, rank(config_.low_percentile));
    std::uint32_t hi = count_at_rank(hist, lo_seen, hi_seen, rank(config_.high_percentile));
    if (hi - lo < config_.min_span_counts) {
      // Widen around the middle so a flat scene stays grey instead of amplifying noise.
      const std::uint32_t mid = (lo + hi) / 2;
      const std::uint32_t half = (config_.min_span_counts + 1) / 2;
      lo = mid > half ? mid - half : 0;
      hi = std::min<std::uint32_t>(0xFFFF, lo + config_.min_span_counts);
    }
    stats.low_count = static_cast<std::uint16_t>(lo);
    stats.high_count = static_cast<std::uint16_t>(hi);
    const std::uint32_t span = std::max<std::uint32_t>(1, hi - lo);
    // Only the occupied band needs LUT entries; pixels outside it do not exist in this frame.
    for (std::uint32_t c = lo_seen; c <= hi_seen; ++c) {
      if (c <= lo) {
        lut[c] = 0;
      } else if (c >= hi) {
        lut[c] = 255;
      } else {
        lut[c] = static_cast<std::uint8_t>(((c - lo) * 255u + span / 2) / span);
      }
    }
  } else {
    // Classic equalisation: out = round(255 * (cdf(c) - cdf_min) / (n - cdf_min)).
    const std::uint64_t cdf_min = hist[lo_seen];
    const std::uint64_t denom = n > cdf_min ? n - cdf_min : 1;
    std::uint64_t cum = 0;
    for (std::uint32_t c = lo_seen; c <= hi_seen; ++c) {
      cum += hist[c];
      lut[c] = static_cast<std::uint8_t>(((cum - cdf_min) * 255u + denom / 2) / denom);
    }
    stats.low_count = static_cast<std::uint16_t>(lo_seen);
    stats.high_count = static_cast<std::uint16_t>(hi_seen);
  }
  for (std::uint32_t r = 0; r < height; ++r) {
    const auto* s =
        reinterpret_cast<const std::uint16_t*>(reinterpret_cast<const std::uint8_t*>(src) +
                                               static_cast<std::size_t>(r) * src_stride_bytes);
    std::uint8_t* d = dst + static_cast<std::size_t>(r) * dst_stride_bytes;
    for (std::uint32_t x = 0; x < width; ++x) d[x] = lut[s[x]];
  }
  return stats;
}

}  // namespace posed::drivers::camera
