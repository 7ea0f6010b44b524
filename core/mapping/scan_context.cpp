#include "core/mapping/scan_context.hpp"

#include <cmath>
#include <limits>
#include <numbers>

namespace posed::mapping {

ScanContext make_scan_context(std::span<const Eigen::Vector3f> points_level,
                              const ScanContextConfig& config) {
  ScanContext sc;
  sc.bins = Eigen::MatrixXf::Zero(config.rings, config.sectors);
  const double ring_width = config.max_range_m / config.rings;
  const double sector_width = 2.0 * std::numbers::pi / config.sectors;
  for (const Eigen::Vector3f& p : points_level) {
    const double range = std::hypot(p.x(), p.y());
    if (!std::isfinite(range) || range >= config.max_range_m || range < 1e-3) {
      continue;
    }
    const double height = p.z() + config.height_offset_m;
    if (!(height > 0.0)) {
      continue;  // below the floor the offset assumes: noise, or a ramp down
    }
    // Azimuth in [0, 2 pi): sector 0 starts at +x and sectors run counter-clockwise.
    double azimuth = std::atan2(p.y(), p.x());
    if (azimuth < 0) {
      azimuth += 2.0 * std::numbers::pi;
    }
    const int ring = std::min(config.rings - 1, static_cast<int>(range / ring_width));
    const int sector = std::min(config.sectors - 1, static_cast<int>(azimuth / sector_width));
    float& bin = sc.bins(ring, sector);
    bin = std::max(bin, static_cast<float>(height));
  }
  sc.ring_key = sc.bins.rowwise().mean();
  sc.sector_key = sc.bins.colwise().mean().transpose();
  return sc;
}

namespace {

/// Mean cosine distance between query columns j and candidate columns j + shift, over the
/// columns where both are non-empty.
double column_distance(const Eigen::MatrixXf& query, const Eigen::MatrixXf& candidate, int shift) {
  const int sectors = static_cast<int>(query.cols());
  double sum = 0.0;
  int columns = 0;
  for (int j = 0; j < sectors; ++j) {
    const int k = ((j + shift) % sectors + sectors) % sectors;
    const double nq = query.col(j).norm(), nc = candidate.col(k).norm();
    if (nq <= 0.0 || nc <= 0.0) {
      continue;
    }
    sum += 1.0 - query.col(j).dot(candidate.col(k)) / (nq * nc);
    ++columns;
  }
  return columns > 0 ? sum / columns : 1.0;
}

}  // namespace

ScanContextMatch match_scan_contexts(const ScanContext& query, const ScanContext& candidate,
                                     const ScanContextConfig& config) {
  const int sectors = config.sectors;
  // The sector keys give the shift cheaply; the full comparison then searches around it (the
  // keys blur bins together, so their best shift can be off by a sector or two).
  int key_shift = 0;
  double key_best = std::numeric_limits<double>::infinity();
  for (int shift = 0; shift < sectors; ++shift) {
    double d = 0.0;
    for (int j = 0; j < sectors; ++j) {
      const double diff = query.sector_key(j) - candidate.sector_key((j + shift) % sectors);
      d += diff * diff;
    }
    if (d < key_best) {
      key_best = d;
      key_shift = shift;
    }
  }
  ScanContextMatch best;
  for (int s = -config.shift_search; s <= config.shift_search; ++s) {
    const int shift = ((key_shift + s) % sectors + sectors) % sectors;
    const double d = column_distance(query.bins, candidate.bins, shift);
    if (d < best.distance) {
      best.distance = d;
      best.shift = shift;
    }
  }
  // Query column j sees what the candidate sees in column j + shift: the query's heading is the
  // candidate's turned by shift sectors.
  const int signed_shift = best.shift > sectors / 2 ? best.shift - sectors : best.shift;
  best.yaw_rad = signed_shift * 2.0 * std::numbers::pi / sectors;
  return best;
}

}  // namespace posed::mapping
