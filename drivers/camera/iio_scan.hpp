#pragma once
// Linux IIO buffered capture records ("scans"): what each enabled scan element is (sysfs
// scan_elements/in_<name>_type, e.g. "le:s16/32>>0"), where it sits in a record, and how to
// pull its value out. Pure: the sysfs reading is iio_hid_device's job.
//
// The type string is "[be|le]:[s|u]<realbits>/<storagebits>[X<repeat>]>><shift>"
// (Documentation/ABI/testing/sysfs-bus-iio, in_voltageY_type). Elements are laid out in
// scan_index order, each aligned to its own storage size, and the record is padded to the
// largest element (the kernel's iio_compute_scan_bytes; librealsense src/linux/backend-hid.cpp,
// iio_hid_sensor::get_channel_size, lays them out the same way). The D435i's accel_3d and
// gyro_3d devices give x, y, z as "le:s16/32>>0" (or s32/32 on newer kernels) at offsets 0, 4,
// 8 and the timestamp "le:s64/64>>0" at 16: 24-byte records (librealsense reads the timestamp
// at p_raw_data[16]).

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace posed::drivers::camera {

struct IioScanType {
  bool big_endian = false;
  bool is_signed = false;
  std::uint32_t realbits = 0;     ///< significant bits [bit]
  std::uint32_t storagebits = 0;  ///< bits the element occupies in a record [bit]: 8/16/32/64
  std::uint32_t shift = 0;        ///< right shift before masking [bit]
  std::uint32_t repeat = 1;       ///< consecutive values of this element
};

/// Parses a sysfs scan element type; false if malformed (storage not 8/16/32/64, realbits
/// beyond storage, shift + realbits beyond storage, repeat 0 or above 255).
bool parse_iio_scan_type(std::string_view text, IioScanType& out);
/// The canonical text of a type ("le:s16/32>>0").
std::string to_string(const IioScanType& type);

struct IioScanElement {
  std::string name;         ///< sysfs name without "_en" etc., e.g. "in_accel_x"
  std::uint32_t index = 0;  ///< scan_elements/<name>_index
  IioScanType type;
  std::uint32_t offset = 0;  ///< [B] from the record start (set by layout_iio_scan)
};

struct IioScanLayout {
  std::vector<IioScanElement> elements;  ///< enabled elements, scan_index order
  std::uint32_t record_bytes = 0;        ///< [B]
  /// the element called `name`, or nullptr
  const IioScanElement* find(std::string_view name) const;
};

/// Largest record layout_iio_scan() accepts [B]; the kernel's are tens of bytes.
inline constexpr std::uint32_t kMaxRecordBytes = 65536;

/// Sorts `elements` by index and computes offsets and the record size as the kernel does.
/// false with `error` on an empty set, duplicate indices, an invalid type or a record beyond
/// kMaxRecordBytes.
bool layout_iio_scan(std::vector<IioScanElement> elements, IioScanLayout& out, std::string& error);

/// The layout as a wire-format suffix: "<prefix>;in_accel_x:le:s16/32>>0;..." (scan order).
std::string describe_iio_layout(std::string_view prefix, const IioScanLayout& layout);
/// Parses describe_iio_layout()'s text back (indices are the positions); false with `error` on
/// a wrong prefix or a bad element.
bool parse_iio_layout(std::string_view text, std::string_view prefix, IioScanLayout& out,
                      std::string& error);

/// The value of `element` (its first repeat) in `record`, shifted, masked to realbits and sign
/// extended. `record` must hold at least element.offset + storagebits/8 bytes.
std::int64_t iio_element_value(const std::byte* record, const IioScanElement& element);

}  // namespace posed::drivers::camera
