#pragma once
// What differs between the sensors that share the Velodyne packet layout: how many lasers, the
// distance unit, and when each channel of a block fires. The firing timings are the user
// manuals' ("Laser Firing Sequence Timing" / "Precision Azimuth Calculation" sections):
//   VLP-32C: lasers fire in pairs, 2.304 µs apart; 16 pair firings + recharge = 55.296 µs per
//            firing cycle; one cycle per data block (channel c fires at floor(c/2)·2.304 µs).
//   VLP-16:  one laser every 2.304 µs, 55.296 µs per cycle, two cycles per data block
//            (channels 0-15 then 16-31 for lasers 0-15 again).
//   HDL-32E: one laser every 1.152 µs, 46.08 µs per cycle, one cycle per data block.
// In dual return mode the blocks come in pairs holding the same firing (manual 9.3.1.5).

#include <array>
#include <cstdint>
#include <string_view>

#include "drivers/velodyne/packet_format.hpp"

namespace posed::drivers::velodyne {

struct SensorModel {
  /// the product id byte this model sends
  ProductId product = ProductId::kUnknown;
  /// distinct lasers (a VLP-16 block carries each laser twice)
  std::uint32_t laser_count = 0;
  /// distance LSB [m] (4 mm VLP-32C, 2 mm VLP-16 and HDL-32E)
  double distance_resolution_m = 0.0;
  /// time from one block's first firing to the next block's, single return [ns]
  std::int32_t block_period_ns = 0;
  /// firing time of each channel of a block relative to the block's first firing [ns]
  std::array<std::int32_t, kChannelsPerBlock> channel_offset_ns{};
  /// laser id fired by each channel of a block
  std::array<std::uint8_t, kChannelsPerBlock> laser_of_channel{};
};

/// The model for a product id byte, or nullptr for one this driver does not decode.
const SensorModel* sensor_model(ProductId product);

/// Parses "VLP-32C", "vlp32c", "VLP-16", "HDL-32E" (case and dashes ignored); kUnknown otherwise.
ProductId parse_product(std::string_view name);

}  // namespace posed::drivers::velodyne
