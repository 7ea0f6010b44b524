#pragma once
// The one schema table: every configuration key with its default, unit, range and description.
// Loading, validation, defaults and `posed --print-config` all read this table, so a key cannot
// exist in one of them and not the others.

#include <array>
#include <span>
#include <string>
#include <string_view>
#include <variant>

#include "daemon/config/posed_config.hpp"

namespace posed::config {

/// Where a field lives in PosedConfig; the alternative also says the field's type.
using FieldRef = std::variant<bool*, int*, double*, std::string*, Rotation3*, Transform4*,
                              drivers::can::CanImuMapping*>;

struct Field {
  /// dotted path in the YAML file, e.g. "imu.rate_hz"
  std::string_view key;
  FieldRef (*ref)(PosedConfig&);
  /// default as YAML text, parsed and validated like a value from the file
  std::string_view default_yaml;
  /// unit shown by --print-config ("" for unitless)
  std::string_view unit;
  /// inclusive range for numbers; ignored for other types
  double min = 0;
  double max = 0;
  /// for strings with a closed set of values: "a|b|c"; empty = free text
  std::string_view choices;
  std::string_view description;
  /// a file path: relative values are resolved against the config file's directory
  bool is_path = false;
};

std::span<const Field> schema();

/// The field at a dotted key, or nullptr.
const Field* find_field(std::string_view key);

}  // namespace posed::config
