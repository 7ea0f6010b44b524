#include "core/lidar/feature_extractor.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace posed::lidar {
namespace {

constexpr int kHalfWindow = 5;  // neighbours each side for the smoothness (LOAM)
// Pixels further apart than this along a ring are not neighbours (a gap in the returns).
constexpr int kMaxNeighbourColumns = 2 * kHalfWindow + 10;

std::uint64_t voxel_key(const Eigen::Vector3f& p, float inv_voxel) {
  // 21 bits per axis, offset to be non-negative: ±2^20 voxels, ±600 km at 0.6 m.
  const auto axis = [inv_voxel](float v) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(v * inv_voxel)) +
                                      (1 << 20)) &
           0x1FFFFF;
  };
  return (axis(p.x()) << 42) | (axis(p.y()) << 21) | axis(p.z());
}

}  // namespace

void voxel_downsample(std::vector<Eigen::Vector3f>& points, double voxel_m,
                      std::vector<std::uint64_t>& keys) {
  if (points.size() < 2 || voxel_m <= 0) return;
  const float inv = static_cast<float>(1.0 / voxel_m);
  // Sort point indices by voxel key (stable: ties keep scan order), keep the first per voxel.
  keys.resize(points.size());
  std::vector<std::uint32_t> order(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    keys[i] = voxel_key(points[i], inv);
    order[i] = static_cast<std::uint32_t>(i);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b]; });
  std::vector<Eigen::Vector3f> kept;
  kept.reserve(points.size() / 4 + 1);
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (k > 0 && keys[order[k]] == keys[order[k - 1]]) continue;
    kept.push_back(points[order[k]]);
  }
  points.swap(kept);
}

FeatureExtractor::FeatureExtractor(const FeatureConfig& config) : config_(config) {
  pixel_.resize(static_cast<std::size_t>(config.rows) * static_cast<std::size_t>(config.columns));
}

void FeatureExtractor::ring_features(const std::vector<ScanPoint>& points, int r,
                                     RingPart& part) const {
  const int cols = config_.columns;
  std::vector<std::int32_t>& ring_points = part.ring_points;
  std::vector<float>& smoothness = part.smoothness;
  std::vector<std::uint8_t>& excluded = part.excluded;
  std::vector<std::int32_t>& order = part.order;
  ring_points.clear();
  for (int c = 0; c < cols; ++c) {
    const std::int32_t i = pixel_[static_cast<std::size_t>(r * cols + c)];
    if (i >= 0) ring_points.push_back(i);
  }
  const int n = static_cast<int>(ring_points.size());
  if (n < 2 * kHalfWindow + 1) return;
  const auto pt = [&](int k) -> const ScanPoint& {
    return points[static_cast<std::size_t>(ring_points[static_cast<std::size_t>(k)])];
  };
  smoothness.assign(static_cast<std::size_t>(n), 0.0f);
  excluded.assign(static_cast<std::size_t>(n), 0);
  for (int k = 0; k < n; ++k) {
    if (k < kHalfWindow || k >= n - kHalfWindow ||
        pt(k + kHalfWindow).column - pt(k - kHalfWindow).column > kMaxNeighbourColumns) {
      excluded[static_cast<std::size_t>(k)] = 1;  // no full window of neighbours
      continue;
    }
    float sum = 0;
    for (int j = -kHalfWindow; j <= kHalfWindow; ++j) sum += pt(k + j).range_m;
    const float ri = pt(k).range_m;
    // How far the point lies from the mean of its neighbours along the ring [m], as a fraction
    // of its range; the range noise sets a floor under which nothing can be told apart.
    const float deviation_m = std::abs(sum - static_cast<float>(2 * kHalfWindow + 1) * ri) /
                              static_cast<float>(2 * kHalfWindow);
    const float noise_floor_m = static_cast<float>(3.0 * config_.range_noise_m);
    smoothness[static_cast<std::size_t>(k)] = std::max(deviation_m - noise_floor_m, 0.0f) / ri;
  }
  // Occlusions and grazing beams (LOAM §V-A).
  for (int k = 1; k + 1 < n; ++k) {
    const float r0 = pt(k - 1).range_m, r1 = pt(k).range_m, r2 = pt(k + 1).range_m;
    if (pt(k + 1).column - pt(k).column <= 2 &&
        std::abs(r2 - r1) > static_cast<float>(config_.occlusion_jump_m)) {
      // The farther side is the one whose surface may be hidden behind the nearer.
      if (r1 > r2) {
        for (int j = std::max(0, k - kHalfWindow); j <= k; ++j)
          excluded[static_cast<std::size_t>(j)] = 1;
      } else {
        for (int j = k + 1; j <= std::min(n - 1, k + 1 + kHalfWindow); ++j) {
          excluded[static_cast<std::size_t>(j)] = 1;
        }
      }
    }
    const float ratio = static_cast<float>(config_.parallel_beam_ratio) * r1;
    if (std::abs(r1 - r0) > ratio && std::abs(r2 - r1) > ratio) {
      excluded[static_cast<std::size_t>(k)] = 1;
    }
  }

  for (int s = 0; s < config_.sectors; ++s) {
    const int begin = kHalfWindow + (n - 2 * kHalfWindow) * s / config_.sectors;
    const int end = kHalfWindow + (n - 2 * kHalfWindow) * (s + 1) / config_.sectors;
    // Edge candidates, sharpest first.
    order.clear();
    for (int k = begin; k < end; ++k) {
      const auto ks = static_cast<std::size_t>(k);
      if (!excluded[ks] && !ground_[static_cast<std::size_t>(ring_points[ks])] &&
          smoothness[ks] > static_cast<float>(config_.edge_threshold)) {
        order.push_back(k);
      }
    }
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      return smoothness[static_cast<std::size_t>(a)] > smoothness[static_cast<std::size_t>(b)];
    });
    int taken = 0;
    for (const int k : order) {
      if (taken >= config_.edges_per_sector) break;
      if (excluded[static_cast<std::size_t>(k)]) continue;  // next to an edge taken
      part.edges.push_back(pt(k).p);
      ++taken;
      for (int j = std::max(0, k - kHalfWindow); j <= std::min(n - 1, k + kHalfWindow); ++j) {
        if (std::abs(pt(j).column - pt(k).column) <= kMaxNeighbourColumns) {
          excluded[static_cast<std::size_t>(j)] = 1;
        }
      }
    }
    for (int k = begin; k < end; ++k) {
      const auto ks = static_cast<std::size_t>(k);
      if (!excluded[ks] && smoothness[ks] < static_cast<float>(config_.plane_threshold)) {
        part.planes.push_back(pt(k).p);
      }
    }
  }
}

void FeatureExtractor::extract(const std::vector<ScanPoint>& points, ScanFeatures& out) {
  out.clear();
  const int rows = config_.rows, cols = config_.columns;
  std::fill(pixel_.begin(), pixel_.end(), -1);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const ScanPoint& p = points[i];
    if (p.ring >= rows || p.column >= cols) continue;
    std::int32_t& px =
        pixel_[static_cast<std::size_t>(p.ring) * static_cast<std::size_t>(cols) + p.column];
    // Two returns in one pixel (dual return, or a cut azimuth): keep the nearer.
    if (px < 0 || p.range_m < points[static_cast<std::size_t>(px)].range_m) {
      if (px < 0) ++out.valid_pixels;
      px = static_cast<std::int32_t>(i);
    }
  }

  // Ground: the slope between vertically adjacent returns of the lower rings.
  ground_.assign(points.size(), 0);
  const double max_slope = std::tan(config_.ground_max_slope_deg * std::numbers::pi / 180.0);
  for (int c = 0; c < cols; ++c) {
    for (int r = 0; r + 1 < std::min(config_.ground_rows, rows); ++r) {
      const std::int32_t a = pixel_[static_cast<std::size_t>(r * cols + c)];
      const std::int32_t b = pixel_[static_cast<std::size_t>((r + 1) * cols + c)];
      if (a < 0 || b < 0) continue;
      const Eigen::Vector3f d =
          points[static_cast<std::size_t>(b)].p - points[static_cast<std::size_t>(a)].p;
      const double horizontal = std::hypot(d.x(), d.y());
      if (std::abs(d.z()) <= max_slope * horizontal) {
        ground_[static_cast<std::size_t>(a)] = ground_[static_cast<std::size_t>(b)] = 1;
      }
    }
  }

  // Rings are independent from here on: each part of them into its own outputs.
  run_parts(splitter_, kParts, [&](std::size_t p) {
    RingPart& part = parts_[p];
    part.edges.clear();
    part.planes.clear();
    const PartRange range = part_range(static_cast<std::size_t>(rows), p, kParts);
    for (std::size_t r = range.begin; r < range.end; ++r) {
      ring_features(points, static_cast<int>(r), part);
    }
  });
  for (const RingPart& part : parts_) {
    out.edges.insert(out.edges.end(), part.edges.begin(), part.edges.end());
    out.planes.insert(out.planes.end(), part.planes.begin(), part.planes.end());
  }
  for (const std::uint8_t g : ground_) out.ground_pixels += g;
  run_parts(splitter_, 2, [&](std::size_t p) {
    if (p == 0) voxel_downsample(out.planes, config_.plane_voxel_m, voxel_keys_[0]);
    if (p == 1) voxel_downsample(out.edges, config_.edge_voxel_m, voxel_keys_[1]);
  });
}

}  // namespace posed::lidar
