#pragma once
// Reads posed's YAML configuration through the schema table. Every problem found is reported,
// each with file, line, key and reason, so a user fixes a config in one round instead of many.

#include <string>
#include <string_view>
#include <vector>

#include "daemon/config/posed_config.hpp"

namespace posed::config {

struct ConfigError {
  std::string file;
  int line = 0;    ///< 1-based; 0 when the problem has no place in the file
  int column = 0;  ///< 1-based
  std::string key;
  std::string reason;
  /// "posed.yaml:12:3: imu.rate_hz: 5000 is out of range [1, 2000] Hz"
  std::string to_string() const;
};

struct LoadResult {
  PosedConfig config;
  std::vector<ConfigError> errors;
  bool ok() const { return errors.empty(); }
  /// All errors, one per line.
  std::string error_text() const;
};

/// Every field at its schema default.
PosedConfig default_config();

/// Loads a file; unknown keys, wrong types, out-of-range values and invalid transforms are errors.
LoadResult load_config_file(const std::string& path);
/// Same, from text; `name` stands for the file name in errors.
LoadResult load_config_text(std::string_view yaml_text, std::string_view name);

/// imu.can_mapping as one line of flow YAML that the loader reads back ("{}" for none), as
/// --print-config and a recording's metadata show it.
std::string can_mapping_yaml(const drivers::can::CanImuMapping& mapping);

/// The effective configuration as YAML, every key with its unit, range and description.
std::string print_config(const PosedConfig& config);

}  // namespace posed::config
