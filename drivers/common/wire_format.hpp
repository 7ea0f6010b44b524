#pragma once
// Names of what a Source's bytes are (DESIGN.md, Data flow): a stage picks its decoder by the
// wire format of the channel a chunk came from, and a recording stores it in each raw channel's
// metadata (drivers/recording/raw_channels.hpp), so a replay decodes the bytes as the live
// pipeline did. Camera pixel formats are named by drivers/camera/pixel_formats.hpp ("yuyv",
// "mjpeg", "y16", ...).

#include <string_view>

namespace posed::drivers::wire {

/// A9 serial byte stream (`AA 55 LEN ... CRC16`), as read from the tty
inline constexpr std::string_view kA9Serial = "a9-serial";
/// one 1206-byte Velodyne data-port UDP payload per chunk
inline constexpr std::string_view kVelodyneData = "velodyne-udp-data";
/// one 512-byte Velodyne position-port UDP payload per chunk
inline constexpr std::string_view kVelodynePosition = "velodyne-udp-position";
/// one Linux struct can_frame / canfd_frame (drivers/imu/can_frame.hpp) per chunk
inline constexpr std::string_view kCanFrame = "linux-can-frame";
/// one D4xx frame-metadata buffer (struct uvc_meta_buf + UVC payload header + Intel blocks,
/// drivers/camera/d4xx_metadata.hpp) per chunk, delivered just before the frame it describes
inline constexpr std::string_view kUvcMetaD4xx = "uvc-meta-d4xx";
/// whole IIO scan records of a hid-sensor-accel-3d device as read from /dev/iio:deviceN. The
/// record layout follows the name: `iio-hid-accel-3d;in_accel_x:le:s16/32>>0;...` lists the
/// enabled scan elements in index order with their sysfs `_type` (drivers/camera/iio_scan.hpp)
inline constexpr std::string_view kIioAccel3d = "iio-hid-accel-3d";
/// the same for a hid-sensor-gyro-3d device (`in_anglvel_*` elements)
inline constexpr std::string_view kIioGyro3d = "iio-hid-gyro-3d";

}  // namespace posed::drivers::wire
