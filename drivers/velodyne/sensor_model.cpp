#include "drivers/velodyne/sensor_model.hpp"

#include <cctype>
#include <string>

namespace posed::drivers::velodyne {
namespace {

SensorModel make_vlp32c() {
  SensorModel m;
  m.product = ProductId::kVlp32c;
  m.laser_count = 32;
  m.distance_resolution_m = 0.004;
  m.block_period_ns = 55'296;
  for (std::uint32_t c = 0; c < kChannelsPerBlock; ++c) {
    m.channel_offset_ns[c] = static_cast<std::int32_t>(c / 2) * 2'304;  // pairs fire together
    m.laser_of_channel[c] = static_cast<std::uint8_t>(c);
  }
  return m;
}

SensorModel make_vlp16() {
  SensorModel m;
  m.product = ProductId::kVlp16;
  m.laser_count = 16;
  m.distance_resolution_m = 0.002;
  m.block_period_ns = 2 * 55'296;  // two firing sequences per block
  for (std::uint32_t c = 0; c < kChannelsPerBlock; ++c) {
    m.channel_offset_ns[c] =
        static_cast<std::int32_t>(c / 16) * 55'296 + static_cast<std::int32_t>(c % 16) * 2'304;
    m.laser_of_channel[c] = static_cast<std::uint8_t>(c % 16);
  }
  return m;
}

SensorModel make_hdl32e() {
  SensorModel m;
  m.product = ProductId::kHdl32e;
  m.laser_count = 32;
  m.distance_resolution_m = 0.002;
  m.block_period_ns = 46'080;
  for (std::uint32_t c = 0; c < kChannelsPerBlock; ++c) {
    m.channel_offset_ns[c] = static_cast<std::int32_t>(c) * 1'152;
    m.laser_of_channel[c] = static_cast<std::uint8_t>(c);
  }
  return m;
}

const SensorModel kVlp32c = make_vlp32c();
const SensorModel kVlp16 = make_vlp16();
const SensorModel kHdl32e = make_hdl32e();

}  // namespace

const SensorModel* sensor_model(ProductId product) {
  switch (product) {
    case ProductId::kVlp32c:
      return &kVlp32c;
    case ProductId::kVlp16:
      return &kVlp16;
    case ProductId::kHdl32e:
      return &kHdl32e;
    case ProductId::kUnknown:
      break;
  }
  return nullptr;
}

ProductId parse_product(std::string_view name) {
  std::string key;
  for (char ch : name) {
    if (ch == '-' || ch == '_' || ch == ' ') continue;
    key += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  }
  if (key == "vlp32c" || key == "vlp32") return ProductId::kVlp32c;
  if (key == "vlp16") return ProductId::kVlp16;
  if (key == "hdl32e" || key == "hdl32") return ProductId::kHdl32e;
  return ProductId::kUnknown;
}

}  // namespace posed::drivers::velodyne
