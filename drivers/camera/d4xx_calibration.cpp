#include "drivers/camera/d4xx_calibration.hpp"

#include <Eigen/LU>
#include <bit>
#include <cmath>
#include <cstring>

#include "drivers/recording/crc32.hpp"

namespace posed::drivers::camera {
namespace {

std::uint32_t u32(std::span<const std::byte> b, std::size_t at) {
  return static_cast<std::uint32_t>(b[at]) | static_cast<std::uint32_t>(b[at + 1]) << 8 |
         static_cast<std::uint32_t>(b[at + 2]) << 16 | static_cast<std::uint32_t>(b[at + 3]) << 24;
}
std::uint16_t u16(std::span<const std::byte> b, std::size_t at) {
  return static_cast<std::uint16_t>(static_cast<std::uint32_t>(b[at]) |
                                    static_cast<std::uint32_t>(b[at + 1]) << 8);
}
double f32(std::span<const std::byte> b, std::size_t at) {
  return static_cast<double>(std::bit_cast<float>(u32(b, at)));
}
/// float3x3 at `at`, column-major: element (row i, column j) is float 3j + i.
Eigen::Matrix3d mat3(std::span<const std::byte> b, std::size_t at) {
  Eigen::Matrix3d m;
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) m(i, j) = f32(b, at + 4 * static_cast<std::size_t>(3 * j + i));
  }
  return m;
}

std::string where(D4xxTableId id) {
  return "calibration table " + std::to_string(static_cast<int>(id));
}

// ds_rect_resolutions order (src/ds/ds-private.h), the index into rect_params.
constexpr std::uint32_t kRectSizes[16][2] = {{1920, 1080}, {1280, 720}, {640, 480}, {848, 480},
                                             {640, 360},   {424, 240},  {320, 240}, {480, 270},
                                             {1280, 800},  {960, 540},  {0, 0},     {0, 0},
                                             {640, 400},   {576, 576},  {720, 720}, {1152, 1152}};

// Offsets in d400_coefficients_table [B].
constexpr std::size_t kBaselineAt = 16 + 4 * 36;
constexpr std::size_t kRectParamsAt = kBaselineAt + 4 + 4 + 88;
// Offsets in d400_rgb_calibration_table [B].
constexpr std::size_t kRgbIntrinsicAt = 16;
constexpr std::size_t kRgbDistortionAt = kRgbIntrinsicAt + 36;
constexpr std::size_t kRgbCalibSizeAt = kRgbDistortionAt + 20 + 12 + 12 + 48;
constexpr std::size_t kRgbRotationRectAt = kRgbCalibSizeAt + 4 + 36;
constexpr std::size_t kRgbTranslationRectAt = kRgbRotationRectAt + 36;

bool check_size(std::span<const std::byte> t, std::size_t need, D4xxTableId id,
                std::string& error) {
  if (t.size() >= need) return true;
  error = where(id) + ": " + std::to_string(t.size()) + " bytes, the table needs " +
          std::to_string(need) + " (reply cut at offset " + std::to_string(t.size()) + ")";
  return false;
}

}  // namespace

bool check_d4xx_table(std::span<const std::byte> t, D4xxTableId id, D4xxTableHeader& h,
                      std::string& error) {
  if (!check_size(t, kD4xxTableHeaderBytes, id, error)) return false;
  // version is big-endian (big_endian<uint16_t> in table_header); the rest little-endian.
  h.version = static_cast<std::uint16_t>(static_cast<std::uint32_t>(t[0]) << 8 |
                                         static_cast<std::uint32_t>(t[1]));
  h.table_type = u16(t, 2);
  h.table_size = u32(t, 4);
  h.param = u32(t, 8);
  h.crc32 = u32(t, 12);
  if (h.table_type != static_cast<std::uint16_t>(id)) {
    error = where(id) + ": header at offset 2 names table " + std::to_string(h.table_type);
    return false;
  }
  // ds::check_calib: the CRC covers every byte after the header.
  const std::uint32_t crc = recording::crc32(t.subspan(kD4xxTableHeaderBytes));
  if (crc != h.crc32) {
    char buf[96];
    std::snprintf(buf, sizeof buf,
                  ": CRC-32 0x%08x over bytes 16..%zu, header (offset 12) says 0x%08x", crc,
                  t.size(), h.crc32);
    error = where(id) + buf;
    return false;
  }
  return true;
}

bool parse_d4xx_coefficients_table(std::span<const std::byte> t, std::uint32_t width,
                                   std::uint32_t height, D4xxDepthCalibration& out,
                                   std::string& error) {
  constexpr auto id = D4xxTableId::kCoefficients;
  D4xxTableHeader h;
  if (!check_size(t, kD4xxCoefficientsTableBytes, id, error) ||
      !check_d4xx_table(t, id, h, error)) {
    return false;
  }
  out = {};
  // librealsense get_stereo_baseline_mm: fabs(table->baseline); the sign is the firmware's.
  out.baseline_m = std::fabs(f32(t, kBaselineAt)) * 1e-3;
  std::size_t entry = 0;  // 1920x1080, scaled, when the size has no entry of its own
  bool exact = false;
  for (std::size_t r = 0; r < 16; ++r) {
    if (kRectSizes[r][0] == width && kRectSizes[r][1] == height) {
      entry = r;
      exact = true;
      break;
    }
  }
  const std::size_t at = kRectParamsAt + 16 * entry;
  double p[4] = {f32(t, at), f32(t, at + 4), f32(t, at + 8), f32(t, at + 12)};
  const double ref_w = kRectSizes[entry][0], ref_h = kRectSizes[entry][1];
  if (p[0] == p[1] && p[2] == p[3]) {
    // An unfilled entry (DS5U): librealsense assumes ideal optics for it.
    p[0] = p[1] = ref_w * 1.5;
    p[2] = ref_w * 0.5;
    p[3] = ref_h * 0.5;
  }
  const double sx = exact ? 1.0 : width / ref_w, sy = exact ? 1.0 : height / ref_h;
  out.depth.width = width;
  out.depth.height = height;
  out.depth.fx = p[0] * sx;
  out.depth.fy = p[1] * sy;
  out.depth.cx = p[2] * sx;
  out.depth.cy = p[3] * sy;
  if (!std::isfinite(out.depth.fx) || out.depth.fx <= 0 || !std::isfinite(out.baseline_m)) {
    error = where(id) + ": implausible rect_params at offset " + std::to_string(at);
    return false;
  }
  return true;
}

bool parse_d4xx_rgb_table(std::span<const std::byte> t, std::uint32_t width, std::uint32_t height,
                          D4xxColourCalibration& out, std::string& error) {
  constexpr auto id = D4xxTableId::kRgbCalibration;
  D4xxTableHeader h;
  if (!check_size(t, kD4xxRgbTableBytes, id, error) || !check_d4xx_table(t, id, h, error)) {
    return false;
  }
  out = {};
  Eigen::Matrix3d k = mat3(t, kRgbIntrinsicAt);
  const std::uint16_t calib_w = u16(t, kRgbCalibSizeAt), calib_h = u16(t, kRgbCalibSizeAt + 2);
  // The normalised matrix holds for the calibrated aspect ratio; other modes crop it.
  const double calib_aspect = calib_w != 0 && calib_h != 0 ? double(calib_h) / calib_w : 9.0 / 16.0;
  const double aspect = double(height) / width;
  if (aspect < calib_aspect) {
    k(1, 1) *= calib_aspect / aspect;
    k(2, 1) *= calib_aspect / aspect;
  } else {
    k(0, 0) *= aspect / calib_aspect;
    k(2, 0) *= aspect / calib_aspect;
  }
  out.colour.width = width;
  out.colour.height = height;
  out.colour.cx = (1 + k(2, 0)) * width / 2.0;
  out.colour.cy = (1 + k(2, 1)) * height / 2.0;
  out.colour.fx = k(0, 0) * width / 2.0;
  out.colour.fy = k(1, 1) * height / 2.0;
  for (std::size_t i = 0; i < 5; ++i) out.colour.distortion[i] = f32(t, kRgbDistortionAt + 4 * i);
  const Eigen::Matrix3d R = mat3(t, kRgbRotationRectAt);
  Eigen::Vector3d tr;
  for (int i = 0; i < 3; ++i) tr[i] = -1e-3 * f32(t, kRgbTranslationRectAt + 4 * std::size_t(i));
  if (!R.allFinite() || std::abs(R.determinant() - 1.0) > 1e-3 || !tr.allFinite() ||
      !std::isfinite(out.colour.fx) || out.colour.fx <= 0) {
    error = where(id) + ": rotation_matrix_rect at offset " + std::to_string(kRgbRotationRectAt) +
            " is not a rotation, or the intrinsics at offset 16 are implausible";
    return false;
  }
  out.T_depth_colour.topLeftCorner<3, 3>() = R;
  out.T_depth_colour.topRightCorner<3, 1>() = tr;
  out.T_colour_depth.topLeftCorner<3, 3>() = R.transpose();
  out.T_colour_depth.topRightCorner<3, 1>() = -R.transpose() * tr;
  return true;
}

}  // namespace posed::drivers::camera
