#pragma once
// D4xx factory calibration tables as GETINTCAL returns them, parsed into depth intrinsics and
// baseline, colour intrinsics and the depth/colour extrinsics. Pure; errors name the table id
// and the byte offset.
//
// Every table starts with table_header (librealsense src/ds/ds-private.h, packed):
//   u16 version (big-endian major.minor), u16 table_type (the table id), u32 table_size,
//   u32 param, u32 crc32 (CRC-32 of every byte after the header; ds::check_calib).
// Tables (src/ds/d400/d400-private.h, d400_calibration_table_id):
//   25 coefficients (d400_coefficients_table): float3x3 intrinsic_left, intrinsic_right,
//      world2left_rot, world2right_rot; float baseline [mm]; u32 brown_model; u8 reserved1[88];
//      float4 rect_params[16] (fx, fy, ppx, ppy per ds_rect_resolutions); u8 reserved2[64].
//   32 RGB calibration (d400_rgb_calibration_table): float3x3 intrinsic (normalised to
//      [-1, 1]); float distortion[5] (Brown); float3 rotation (Rodrigues); float3 translation
//      [mm]; float projection[12]; u16 calib_width, calib_height; float3x3
//      intrinsic_matrix_rect; float3x3 rotation_matrix_rect; float3 translation_rect [mm];
//      u8 reserved[24].
// float3x3 is column-major (librealsense types.h: operator()(i, j) = (&x)[j][i]).

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

namespace posed::drivers::camera {

enum class D4xxTableId : std::uint16_t {
  kCoefficients = 25,    ///< depth: rectified intrinsics per resolution, stereo baseline
  kRgbCalibration = 32,  ///< colour: intrinsics, distortion, extrinsics to depth
};

/// sizeof(table_header) [B]
inline constexpr std::size_t kD4xxTableHeaderBytes = 16;
/// sizeof(d400_coefficients_table) [B]
inline constexpr std::size_t kD4xxCoefficientsTableBytes = 16 + 4 * 36 + 4 + 4 + 88 + 16 * 16 + 64;
/// sizeof(d400_rgb_calibration_table) [B]
inline constexpr std::size_t kD4xxRgbTableBytes =
    16 + 36 + 20 + 12 + 12 + 48 + 4 + 36 + 36 + 12 + 24;

struct D4xxTableHeader {
  std::uint16_t version = 0;  ///< major << 8 | minor
  std::uint16_t table_type = 0;
  std::uint32_t table_size = 0;  ///< [B] as the firmware states it
  std::uint32_t param = 0;
  std::uint32_t crc32 = 0;
};

/// Pinhole intrinsics with Brown-Conrady distortion (k1, k2, p1, p2, k3).
struct PinholeIntrinsics {
  std::uint32_t width = 0;   ///< [px]
  std::uint32_t height = 0;  ///< [px]
  double fx = 0, fy = 0;     ///< focal lengths [px]
  double cx = 0, cy = 0;     ///< principal point [px]
  /// librealsense: zero for rectified depth; colour's are inverse Brown-Conrady
  std::array<double, 5> distortion{};
};

struct D4xxDepthCalibration {
  PinholeIntrinsics depth;  ///< rectified depth (left imager) intrinsics at the stream size
  double baseline_m = 0;    ///< left-right imager distance [m]
};

struct D4xxColourCalibration {
  PinholeIntrinsics colour;  ///< at the stream size
  /// pose of the colour camera in the depth frame: p_depth = T_depth_colour * p_colour
  /// (librealsense registers this table's extrinsic from colour to depth)
  Eigen::Matrix4d T_depth_colour = Eigen::Matrix4d::Identity();
  /// the inverse: p_colour = T_colour_depth * p_depth (rs2 "depth to colour" extrinsics)
  Eigen::Matrix4d T_colour_depth = Eigen::Matrix4d::Identity();
};

/// Checks a table's header against `id` and its CRC. false with `error` ("table 25: ...").
bool check_d4xx_table(std::span<const std::byte> table, D4xxTableId id, D4xxTableHeader& header,
                      std::string& error);

/// The depth stream's rectified intrinsics for width x height from table 25
/// (get_d400_intrinsic_by_resolution_coefficients_table: the rect_params entry of that size,
/// else the 1920x1080 entry scaled) and the baseline.
bool parse_d4xx_coefficients_table(std::span<const std::byte> table, std::uint32_t width,
                                   std::uint32_t height, D4xxDepthCalibration& out,
                                   std::string& error);

/// The colour stream's intrinsics for width x height (get_d400_color_stream_intrinsic: the
/// normalised matrix corrected for the aspect ratio of the calibrated size) and extrinsics
/// (get_d400_color_stream_extrinsic: rotation_matrix_rect, translation_rect * -0.001) from
/// table 32.
bool parse_d4xx_rgb_table(std::span<const std::byte> table, std::uint32_t width,
                          std::uint32_t height, D4xxColourCalibration& out, std::string& error);

}  // namespace posed::drivers::camera
