#include "drivers/velodyne/calibration.hpp"

#include <algorithm>
#include <array>
#include <numbers>
#include <numeric>

namespace posed::drivers::velodyne {
namespace {

// VLP-32C user manual table 9-2, by laser id: vertical angle [deg] and azimuth offset [deg].
constexpr std::array<double, 32> kVlp32cElevationDeg = {
    -25.0,  -1.0,   -1.667, -15.639, -11.31, 0.0,    -0.667, -8.843, -7.254, 0.333,  -0.333,
    -6.148, -5.333, 1.333,  0.667,   -4.0,   -4.667, 1.667,  1.0,    -3.667, -3.333, 3.333,
    2.333,  -2.667, -3.0,   7.0,     4.667,  -2.333, -2.0,   15.0,   10.333, -1.333};
constexpr std::array<double, 32> kVlp32cAzimuthOffsetDeg = {
    1.4, -4.2, 1.4, -1.4, 1.4, -1.4, 4.2, -1.4, 1.4, -4.2, 1.4, -1.4, 4.2, -1.4, 4.2, -1.4,
    1.4, -4.2, 1.4, -4.2, 4.2, -1.4, 1.4, -1.4, 1.4, -1.4, 1.4, -4.2, 4.2, -1.4, 1.4, -1.4};

// HDL-32E user manual, vertical angle by laser id [deg]; no azimuth offsets.
constexpr std::array<double, 32> kHdl32eElevationDeg = {
    -30.67, -9.33,  -29.33, -8.00,  -28.00, -6.67,  -26.67, -5.33,  -25.33, -4.00,  -24.00,
    -2.67,  -22.67, -1.33,  -21.33, 0.00,   -20.00, 1.33,   -18.67, 2.67,   -17.33, 4.00,
    -16.00, 5.33,   -14.67, 6.67,   -13.33, 8.00,   -12.00, 9.33,   -10.67, 10.67};

}  // namespace

Calibration builtin_calibration(ProductId product) {
  Calibration c;
  switch (product) {
    case ProductId::kVlp32c:
      c.source = "builtin VLP-32C";
      c.distance_resolution_m = 0.004;
      for (std::size_t i = 0; i < 32; ++i) {
        LaserCorrection l;
        l.vert_correction_rad = kVlp32cElevationDeg[i] * kDegToRad;
        l.rot_correction_rad = -kVlp32cAzimuthOffsetDeg[i] * kDegToRad;
        c.lasers.push_back(l);
      }
      break;
    case ProductId::kVlp16:
      // VLP-16 table 9-1: laser i at -15°, 1°, -13°, 3°, ... alternating, 2° apart.
      c.source = "builtin VLP-16";
      c.distance_resolution_m = 0.002;
      for (int i = 0; i < 16; ++i) {
        LaserCorrection l;
        const int deg = (i % 2 == 0) ? -15 + i : i;
        l.vert_correction_rad = deg * kDegToRad;
        c.lasers.push_back(l);
      }
      break;
    case ProductId::kHdl32e:
      c.source = "builtin HDL-32E";
      c.distance_resolution_m = 0.002;
      for (double deg : kHdl32eElevationDeg) {
        LaserCorrection l;
        l.vert_correction_rad = deg * kDegToRad;
        c.lasers.push_back(l);
      }
      break;
    case ProductId::kUnknown:
      break;
  }
  return c;
}

std::vector<std::uint16_t> rings_by_elevation(const Calibration& calibration) {
  const std::size_t n = calibration.lasers.size();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return calibration.lasers[a].vert_correction_rad < calibration.lasers[b].vert_correction_rad;
  });
  std::vector<std::uint16_t> ring(n);
  for (std::size_t r = 0; r < n; ++r) ring[order[r]] = static_cast<std::uint16_t>(r);
  return ring;
}

}  // namespace posed::drivers::velodyne
