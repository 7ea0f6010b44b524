// libFuzzer target: the text files posed reads, each input through both loaders:
//  - posed's YAML configuration (load_config_text, schema, CAN mapping);
//  - a Velodyne calibration file: VeloView XML or ros-drivers/velodyne_decoder YAML
//    (parse_calibration_text, chosen by content as load_calibration does).
// Bad text must come back as errors, never as an exception, a crash or a hang. Contracts: every
// error has a reason; a configuration that loads has a CAN mapping that passes validate() and
// reads back from can_mapping_yaml(); a calibration that loads has 16 or 32 finite lasers.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "daemon/config/config_loader.hpp"
#include "drivers/velodyne/calibration_loader.hpp"

namespace {

void check(bool ok) {
  if (!ok) std::abort();
}

void posed_config(std::string_view text) {
  const posed::config::LoadResult r = posed::config::load_config_text(text, "fuzz.yaml");
  for (const auto& e : r.errors) check(!e.reason.empty() && !e.to_string().empty());
  if (!r.ok()) return;
  const auto& mapping = r.config.imu.can_mapping;
  if (mapping.fields.empty()) return;
  std::string why;
  check(posed::drivers::can::validate(mapping, why));
  // The mapping as --print-config and a recording's metadata write it loads back the same.
  // clock_kind too: it decides which counters the mapping may have.
  const std::string again = "imu:\n  clock_kind: " + r.config.imu.clock_kind +
                            "\n  can_mapping: " + posed::config::can_mapping_yaml(mapping) + "\n";
  const posed::config::LoadResult back = posed::config::load_config_text(again, "again.yaml");
  check(back.ok() && back.config.imu.can_mapping.fields.size() == mapping.fields.size());
}

void velodyne_calibration(std::string_view text) {
  posed::drivers::velodyne::Calibration c;
  std::string error;
  if (!posed::drivers::velodyne::parse_calibration_text(text, "fuzz.cal", c, error)) {
    check(!error.empty());
    return;
  }
  check(c.lasers.size() == 16 || c.lasers.size() == 32);
  for (const auto& l : c.lasers) {
    check(std::isfinite(l.rot_correction_rad) && std::isfinite(l.vert_correction_rad) &&
          std::isfinite(l.dist_correction_m));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  posed_config(text);
  velodyne_calibration(text);
  return 0;
}
