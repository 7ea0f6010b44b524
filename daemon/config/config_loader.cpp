#include "daemon/config/config_loader.hpp"

// yaml-cpp 0.7's node/impl.h trips GCC 12's -Wdangling-pointer (a false positive in its own
// templates); silence it for that header only.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdangling-pointer"
#include <yaml-cpp/yaml.h>
#pragma GCC diagnostic pop

#include <Eigen/Core>
#include <Eigen/LU>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <utility>

#include "daemon/config/config_schema.hpp"

namespace posed::config {
namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

std::string format_number(double v) {
  char buf[64];
  if (v == std::floor(v) && std::fabs(v) < 1e15) {
    std::snprintf(buf, sizeof buf, "%.0f", v);
    return buf;
  }
  std::snprintf(buf, sizeof buf, "%.17g", v);
  // Shortest text that reads back exactly, so --print-config output can be loaded again.
  for (int precision = 1; precision <= 17; ++precision) {
    char shorter[64];
    std::snprintf(shorter, sizeof shorter, "%.*g", precision, v);
    if (std::strtod(shorter, nullptr) == v) return shorter;
  }
  return buf;
}

std::string hex_id(std::uint32_t id) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%X", id);
  return buf;
}

}  // namespace

std::string can_mapping_yaml(const drivers::can::CanImuMapping& m) {
  if (m.fields.empty()) return "{}";
  std::string s = "{complete_on_id: " + hex_id(m.complete_on_id) +
                  ", complete_on_extended: " + (m.complete_on_extended ? "true" : "false") +
                  ", fields: [";
  for (std::size_t i = 0; i < m.fields.size(); ++i) {
    const auto& f = m.fields[i];
    s += std::string(i ? ", " : "") + "{id: " + hex_id(f.can_id) +
         ", extended: " + (f.extended ? "true" : "false") +
         ", field: " + std::string(drivers::can::to_string(f.field)) +
         ", byte: " + std::to_string(f.byte_offset) +
         ", type: " + std::string(drivers::can::to_string(f.type)) +
         ", byte_order: " + (f.big_endian ? "motorola" : "intel") +
         ", scale: " + format_number(f.scale) + ", offset: " + format_number(f.offset) + "}";
  }
  return s + "]}";
}

namespace {

std::string range_text(const Field& f) {
  std::string s = "[" + format_number(f.min) + ", " + format_number(f.max) + "]";
  if (!f.unit.empty()) s += " " + std::string(f.unit);
  return s;
}

class Loader {
 public:
  Loader(std::string_view file, PosedConfig& config, std::vector<ConfigError>& errors)
      : file_(file), config_(config), errors_(errors) {}

  void error(const YAML::Node& node, std::string_view key, std::string reason) {
    const YAML::Mark mark = node.Mark();
    errors_.push_back(ConfigError{file_, mark.line >= 0 ? mark.line + 1 : 0,
                                  mark.column >= 0 ? mark.column + 1 : 0, std::string(key),
                                  std::move(reason)});
  }

  // Walks a mapping; every leaf must be a schema key.
  void walk(const YAML::Node& node, const std::string& prefix) {
    // Copies, not references: yaml-cpp's iterator hands out a temporary pair, so a reference to
    // it->first dangles at the end of the statement (ASan: stack-use-after-scope).
    for (auto it = node.begin(); it != node.end(); ++it) {
      const YAML::Node key_node = it->first;
      const YAML::Node value = it->second;
      if (!key_node.IsScalar()) {
        error(key_node, prefix, "keys must be plain names");
        continue;
      }
      const std::string key = prefix.empty() ? key_node.Scalar() : prefix + "." + key_node.Scalar();
      if (const Field* field = find_field(key)) {
        const YAML::Mark mark = key_node.Mark();
        // yaml-cpp keeps both of a key written twice (in one mapping, or in a section written
        // twice); which one counts would be an accident of order, and an edit to one of them
        // would silently do nothing.
        if (const auto first = places_.find(key); first != places_.end()) {
          error(key_node, key,
                "set twice (first on line " + std::to_string(first->second.first) + "); keep one");
          continue;
        }
        places_[key] = {mark.line + 1, mark.column + 1};
        apply(*field, value);
      } else if (value.IsMap() && is_section(key)) {
        walk(value, key);
      } else {
        error(key_node, key, "unknown key" + suggestion(key));
      }
    }
  }

  void apply(const Field& field, const YAML::Node& value) {
    std::visit(Overloaded{
                   [&](bool* out) { parse_bool(field, value, *out); },
                   [&](int* out) { parse_int(field, value, *out); },
                   [&](double* out) { parse_double(field, value, *out); },
                   [&](std::string* out) { parse_string(field, value, *out); },
                   [&](Rotation3* out) { parse_matrix(field, value, *out, 3); },
                   [&](Transform4* out) { parse_matrix(field, value, *out, 4); },
                   [&](drivers::can::CanImuMapping* out) { parse_can_mapping(field, value, *out); },
               },
               field.ref(config_));
  }

  /// Where a key was set in the file (line and column, 1-based), for checks across keys.
  std::pair<int, int> place_of(const std::string& key) const {
    const auto it = places_.find(key);
    return it == places_.end() ? std::pair<int, int>{0, 0} : it->second;
  }

 private:
  static bool is_section(const std::string& key) {
    const std::string prefix = key + ".";
    for (const auto& f : schema()) {
      if (f.key.substr(0, prefix.size()) == prefix) return true;
    }
    return false;
  }

  static std::string suggestion(const std::string& key) {
    // The nearest key by edit distance, when it is close enough to be a typo.
    std::string best;
    std::size_t best_distance = 4;
    for (const auto& f : schema()) {
      const std::string candidate(f.key);
      std::vector<std::size_t> row(candidate.size() + 1);
      for (std::size_t j = 0; j < row.size(); ++j) row[j] = j;
      for (std::size_t i = 1; i <= key.size(); ++i) {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= candidate.size(); ++j) {
          const std::size_t up = row[j];
          row[j] = std::min(
              {row[j] + 1, row[j - 1] + 1, diagonal + (key[i - 1] == candidate[j - 1] ? 0u : 1u)});
          diagonal = up;
        }
      }
      if (row.back() < best_distance) {
        best_distance = row.back();
        best = candidate;
      }
    }
    return best.empty() ? std::string() : " (did you mean '" + best + "'?)";
  }

  bool expect_scalar(const Field& f, const YAML::Node& v, std::string_view what) {
    if (v.IsScalar()) return true;
    error(v, f.key,
          "expected " + std::string(what) + ", found a " +
              (v.IsMap()        ? "mapping"
               : v.IsSequence() ? "list"
                                : "null value"));
    return false;
  }

  void parse_bool(const Field& f, const YAML::Node& v, bool& out) {
    if (!expect_scalar(f, v, "true or false")) return;
    const std::string& s = v.Scalar();
    if (s == "true" || s == "yes" || s == "on") {
      out = true;
    } else if (s == "false" || s == "no" || s == "off") {
      out = false;
    } else {
      error(v, f.key, "expected true or false, found '" + s + "'");
    }
  }

  bool parse_number(const Field& f, const YAML::Node& v, double& out) {
    if (!expect_scalar(f, v, "a number")) return false;
    const std::string& s = v.Scalar();
    char* end = nullptr;
    out = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(out)) {
      error(v, f.key, "expected a number, found '" + s + "'");
      return false;
    }
    return true;
  }

  void parse_int(const Field& f, const YAML::Node& v, int& out) {
    double d = 0;
    if (!parse_number(f, v, d)) return;
    if (d != std::floor(d)) {
      error(v, f.key, "expected a whole number, found '" + v.Scalar() + "'");
      return;
    }
    if (d < f.min || d > f.max) {
      error(v, f.key, v.Scalar() + " is out of range " + range_text(f));
      return;
    }
    out = static_cast<int>(d);
  }

  void parse_double(const Field& f, const YAML::Node& v, double& out) {
    double d = 0;
    if (!parse_number(f, v, d)) return;
    if (d < f.min || d > f.max) {
      error(v, f.key, v.Scalar() + " is out of range " + range_text(f));
      return;
    }
    out = d;
  }

  void parse_string(const Field& f, const YAML::Node& v, std::string& out) {
    if (v.IsNull()) {
      out.clear();
      return;
    }
    if (!expect_scalar(f, v, "text")) return;
    const std::string& s = v.Scalar();
    if (!f.choices.empty()) {
      bool allowed = false;
      std::string_view rest = f.choices;
      while (!rest.empty()) {
        const auto bar = rest.find('|');
        allowed = allowed || rest.substr(0, bar) == s;
        rest = bar == std::string_view::npos ? std::string_view() : rest.substr(bar + 1);
      }
      if (!allowed) {
        std::string options(f.choices);
        for (auto& c : options) c = c == '|' ? ',' : c;
        error(v, f.key, "'" + s + "' is not one of: " + options);
        return;
      }
    }
    out = s;
  }

  template <std::size_t N>
  void parse_matrix(const Field& f, const YAML::Node& v, std::array<double, N>& out, int dim) {
    if (!v.IsSequence() || v.size() != N) {
      error(v, f.key,
            "expected a list of " + std::to_string(N) + " numbers (row-major " +
                std::to_string(dim) + "x" + std::to_string(dim) + ")" +
                (v.IsSequence() ? ", found " + std::to_string(v.size()) : std::string()));
      return;
    }
    std::array<double, N> m{};
    for (std::size_t i = 0; i < N; ++i) {
      const YAML::Node& e = v[i];
      Field element = f;
      element.min = -1e9;
      element.max = 1e9;
      if (!parse_number(element, e, m[i])) return;
    }
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) R(r, c) = m[static_cast<std::size_t>(r * dim + c)];
    }
    // M2DGR writes rotations to 5 decimals at best; 1e-4 accepts those and catches typos.
    const double orthonormality = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
    if (orthonormality > 1e-4 || R.determinant() < 0) {
      char buf[160];
      std::snprintf(buf, sizeof buf,
                    "the rotation part is not a rotation (|R^T R - I| = %.3g, det = %.3g); is the "
                    "matrix transposed or a reflection?",
                    orthonormality, R.determinant());
      error(v, f.key, buf);
      return;
    }
    if (dim == 4 && (m[12] != 0 || m[13] != 0 || m[14] != 0 || m[15] != 1)) {
      error(v, f.key, "the last row of a 4x4 transform must be 0, 0, 0, 1");
      return;
    }
    out = m;
  }

  // imu.can_mapping (config/imu-can-example.yaml):
  //   can_mapping:
  //     complete_on_id: 0x182        # the frame that completes a sample
  //     complete_on_extended: false  # optional: inferred from the fields with that ID
  //     fields:
  //       - {id: 0x181, field: gyro_x, byte: 0, type: i16, byte_order: intel, scale: 1.0e-3}
  // Each problem is reported at its own node with a key such as imu.can_mapping.fields[2].type;
  // a mapping that parses is then checked by the decoder's own validate().
  void parse_can_mapping(const Field& f, const YAML::Node& v, drivers::can::CanImuMapping& out) {
    namespace can = drivers::can;
    const std::string key(f.key);
    if (v.IsNull() || (v.IsMap() && v.size() == 0)) {
      out = {};
      return;
    }
    if (!v.IsMap()) {
      error(v, key,
            std::string("expected a mapping {complete_on_id, fields: [...]}, found a ") +
                (v.IsSequence() ? "list" : "plain value"));
      return;
    }
    const std::size_t errors_before = errors_.size();
    // optional, not bare Nodes: assigning to a yaml-cpp Node writes into the node it refers to.
    std::optional<YAML::Node> fields, complete_id, complete_extended;
    for (auto it = v.begin(); it != v.end(); ++it) {
      const YAML::Node name = it->first;
      const YAML::Node value = it->second;
      const std::string n = name.IsScalar() ? name.Scalar() : std::string();
      if (n == "fields") {
        fields.emplace(value);
      } else if (n == "complete_on_id") {
        complete_id.emplace(value);
      } else if (n == "complete_on_extended") {
        complete_extended.emplace(value);
      } else {
        error(name, key + "." + n,
              "unknown key (a CAN mapping has fields, complete_on_id, complete_on_extended)");
      }
    }
    can::CanImuMapping m;
    if (!fields) {
      error(v, key + ".fields", "missing: the list of mapped fields");
    } else if (!fields->IsSequence() || fields->size() == 0) {
      error(*fields, key + ".fields", "expected a non-empty list of {id, field, byte, type, ...}");
    } else {
      for (std::size_t i = 0; i < fields->size(); ++i) {
        can::CanFieldMap entry;
        const std::string entry_key = key + ".fields[" + std::to_string(i) + "]";
        const YAML::Mark mark = (*fields)[i].Mark();
        places_[entry_key] = {mark.line + 1, mark.column + 1};
        if (parse_can_field((*fields)[i], entry_key, entry)) {
          m.fields.push_back(entry);
        }
      }
    }
    if (!complete_id) {
      error(v, key + ".complete_on_id", "missing: the ID of the frame that completes a sample");
    } else {
      parse_can_id(*complete_id, key + ".complete_on_id", true, m.complete_on_id);
    }
    if (complete_extended) {
      parse_flag(*complete_extended, key + ".complete_on_extended", m.complete_on_extended);
    } else {
      // Inferred: extended when the mapped frames with that number are all 29-bit ones.
      bool standard = false, extended = false;
      for (const auto& e : m.fields) {
        if (e.can_id != m.complete_on_id) continue;
        (e.extended ? extended : standard) = true;
      }
      m.complete_on_extended = extended && !standard;
    }
    if (errors_.size() != errors_before) return;
    std::string why;
    std::size_t bad = std::string::npos;
    if (!can::validate(m, why, bad)) {
      if (bad < fields->size()) {
        error((*fields)[bad], key + ".fields[" + std::to_string(bad) + "]", why);
      } else if (why.find("complete_on_id") != std::string::npos) {
        error(*complete_id, key + ".complete_on_id", why);
      } else {
        error(*fields, key + ".fields", why);
      }
      return;
    }
    out = std::move(m);
  }

  bool parse_can_field(const YAML::Node& v, const std::string& key,
                       drivers::can::CanFieldMap& out) {
    namespace can = drivers::can;
    if (!v.IsMap()) {
      error(v, key, "expected a mapping {id, field, byte, type, byte_order, scale, offset}");
      return false;
    }
    const std::size_t errors_before = errors_.size();
    std::optional<YAML::Node> id, extended, field, byte, type, order, scale, offset;
    for (auto it = v.begin(); it != v.end(); ++it) {
      const YAML::Node name = it->first;
      const YAML::Node value = it->second;
      const std::string n = name.IsScalar() ? name.Scalar() : std::string();
      std::optional<YAML::Node>* slot = n == "id"           ? &id
                                        : n == "extended"   ? &extended
                                        : n == "field"      ? &field
                                        : n == "byte"       ? &byte
                                        : n == "type"       ? &type
                                        : n == "byte_order" ? &order
                                        : n == "scale"      ? &scale
                                        : n == "offset"     ? &offset
                                                            : nullptr;
      if (slot == nullptr) {
        error(name, key + "." + n,
              "unknown key (a mapped field has id, extended, field, byte, type, byte_order, "
              "scale, offset)");
      } else {
        slot->emplace(value);
      }
    }
    for (const auto& [node, name] : {std::pair{&id, "id"}, std::pair{&field, "field"},
                                     std::pair{&byte, "byte"}, std::pair{&type, "type"}}) {
      if (!*node) error(v, key + "." + name, "missing");
    }
    if (extended) parse_flag(*extended, key + ".extended", out.extended);
    if (id) parse_can_id(*id, key + ".id", out.extended, out.can_id);
    if (field && expect_text(*field, key + ".field")) {
      if (const auto f = can::imu_field_from_string(field->Scalar())) {
        out.field = *f;
      } else {
        error(*field, key + ".field",
              "'" + field->Scalar() +
                  "' is not one of: gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z,counter");
      }
    }
    if (type && expect_text(*type, key + ".type")) {
      if (const auto t = can::field_type_from_string(type->Scalar())) {
        out.type = *t;
      } else {
        error(*type, key + ".type",
              "'" + type->Scalar() + "' is not one of: u8,i8,u16,i16,u32,i32,f32");
      }
    }
    double d = 0;
    if (byte && parse_plain_number(*byte, key + ".byte", d)) {
      if (d != std::floor(d) || d < 0 || d > 63) {
        error(*byte, key + ".byte", "expected a byte offset 0..63, found '" + byte->Scalar() + "'");
      } else {
        out.byte_offset = static_cast<std::uint8_t>(d);
      }
    }
    if (order && expect_text(*order, key + ".byte_order")) {
      if (order->Scalar() == "intel") {
        out.big_endian = false;
      } else if (order->Scalar() == "motorola") {
        out.big_endian = true;
      } else {
        error(*order, key + ".byte_order",
              "'" + order->Scalar() + "' is not one of: intel,motorola (little, big endian)");
      }
    }
    if (scale && parse_plain_number(*scale, key + ".scale", d)) {
      if (d == 0) {
        error(*scale, key + ".scale", "must not be 0");
      } else {
        out.scale = d;
      }
    }
    if (offset && parse_plain_number(*offset, key + ".offset", d)) out.offset = d;
    return errors_.size() == errors_before;
  }

  bool expect_text(const YAML::Node& v, const std::string& key) {
    if (v.IsScalar()) return true;
    error(v, key, "expected a name, found a " + std::string(v.IsMap() ? "mapping" : "list"));
    return false;
  }

  bool parse_plain_number(const YAML::Node& v, const std::string& key, double& out) {
    const std::string s = v.IsScalar() ? v.Scalar() : std::string();
    char* end = nullptr;
    out = std::strtod(s.c_str(), &end);
    if (!v.IsScalar() || s.empty() || end != s.c_str() + s.size() || !std::isfinite(out)) {
      error(v, key, "expected a number, found '" + s + "'");
      return false;
    }
    return true;
  }

  void parse_flag(const YAML::Node& v, const std::string& key, bool& out) {
    const std::string s = v.IsScalar() ? v.Scalar() : std::string();
    if (s == "true" || s == "yes" || s == "on") {
      out = true;
    } else if (s == "false" || s == "no" || s == "off") {
      out = false;
    } else {
      error(v, key, "expected true or false, found '" + s + "'");
    }
  }

  // An arbitration ID, decimal or 0x hex: 11 bits, or 29 bits when `extended`.
  void parse_can_id(const YAML::Node& v, const std::string& key, bool extended,
                    std::uint32_t& out) {
    const std::string s = v.IsScalar() ? v.Scalar() : std::string();
    char* end = nullptr;
    errno = 0;
    const unsigned long long id = std::strtoull(s.c_str(), &end, 0);
    if (!v.IsScalar() || s.empty() || s.front() == '-' || end != s.c_str() + s.size() ||
        errno != 0) {
      error(v, key, "expected a CAN ID (decimal or 0x hex), found '" + s + "'");
      return;
    }
    const unsigned long long max = extended ? 0x1FFFFFFFull : 0x7FFull;
    if (id > max) {
      error(v, key,
            s + " is out of range for " +
                (extended ? std::string("a 29-bit ID (0..0x1FFFFFFF)")
                          : std::string("an 11-bit ID (0..0x7FF; extended: true for 29 bits)")));
      return;
    }
    out = static_cast<std::uint32_t>(id);
  }

  std::string file_;
  PosedConfig& config_;
  std::vector<ConfigError>& errors_;
  std::map<std::string, std::pair<int, int>> places_;
};

/// DDS Security is all or nothing: an enclave, or all six files; half a configuration would
/// start posed unprotected or not at all, so it stops start-up naming what is missing.
void check_dds_security(const DdsSecuritySection& s, std::string_view file, const Loader& loader,
                        std::vector<ConfigError>& errors) {
  const std::pair<const char*, const std::string*> files[] = {
      {"dds.security.identity_ca", &s.identity_ca},
      {"dds.security.certificate", &s.certificate},
      {"dds.security.private_key", &s.private_key},
      {"dds.security.permissions_ca", &s.permissions_ca},
      {"dds.security.governance", &s.governance},
      {"dds.security.permissions", &s.permissions}};
  std::string set, missing;
  const char* first_set = nullptr;
  for (const auto& [key, value] : files) {
    std::string& list = value->empty() ? missing : set;
    list += std::string(list.empty() ? "" : ", ") + key;
    if (!value->empty() && first_set == nullptr) first_set = key;
  }
  if (!s.enclave.empty() && !set.empty()) {
    const auto [line, column] = loader.place_of("dds.security.enclave");
    errors.push_back(
        {std::string(file), line, column, "dds.security.enclave",
         "give either an enclave directory or the six files, not both (also set: " + set + ")"});
  } else if (s.enclave.empty() && !set.empty() && !missing.empty()) {
    const auto [line, column] = loader.place_of(first_set);
    errors.push_back({std::string(file), line, column, "dds.security",
                      "half-configured: " + set + " set but " + missing +
                          " missing; DDS Security needs all six (or dds.security.enclave)"});
  }
}

/// A DDS topic posed reads must be a ROS 2 topic's DDS name, "rt/" then ROS name tokens
/// (letters, digits, _; not starting with a digit) joined by single slashes: a ROS name such as
/// /initialpose would otherwise give a reader no ROS 2 publisher ever matches, silently.
void check_dds_topic(const std::string& topic, const std::string& key, std::string_view file,
                     const Loader& loader, std::vector<ConfigError>& errors) {
  if (topic.empty()) return;
  const auto [line, column] = loader.place_of(key);
  if (topic.front() == '/') {
    errors.push_back({std::string(file), line, column, key,
                      "'" + topic + "' is a ROS name; its DDS name is rt" + topic +
                          " (ROS 2 prefixes topics with rt/)"});
    return;
  }
  bool ok = topic.size() > 3 && topic.compare(0, 3, "rt/") == 0;
  std::size_t token_start = 3;
  for (std::size_t i = 3; ok && i <= topic.size(); ++i) {
    if (i == topic.size() || topic[i] == '/') {
      ok = i > token_start && !std::isdigit(static_cast<unsigned char>(topic[token_start]));
      token_start = i + 1;
    } else {
      ok = std::isalnum(static_cast<unsigned char>(topic[i])) || topic[i] == '_';
    }
  }
  if (!ok) {
    errors.push_back({std::string(file), line, column, key,
                      "'" + topic +
                          "' is not a ROS 2 topic's DDS name (rt/ then names of letters, digits "
                          "and _ joined by /, e.g. rt/initialpose)"});
  }
}

void check_cross_field(const PosedConfig& c, std::string_view file, const Loader& loader,
                       std::vector<ConfigError>& errors) {
  check_dds_security(c.dds.security, file, loader, errors);
  check_dds_topic(c.dds.initialpose_topic, "dds.initialpose_topic", file, loader, errors);
  if (c.lidar.min_range_m >= c.lidar.max_range_m) {
    errors.push_back(
        {std::string(file), 0, 0, "lidar.min_range_m", "must be below lidar.max_range_m"});
  }
  if (c.imu.source == "can") {
    const auto [line, column] = loader.place_of("imu.source");
    if (c.imu.can_mapping.fields.empty()) {
      errors.push_back({std::string(file), line, column, "imu.can_mapping",
                        "imu.source is can but no imu.can_mapping says which frames carry the "
                        "IMU's fields (config/imu-can-example.yaml)"});
    }
    if (c.imu.can_interface.empty()) {
      errors.push_back({std::string(file), line, column, "imu.can_interface",
                        "imu.source is can but imu.can_interface is empty"});
    }
  }
  // ClockSync unwraps a counter_us_32bit stamp at 2^32 µs; a narrower or scaled counter wraps
  // elsewhere and would be read as clock jumps.
  const auto& fields = c.imu.can_mapping.fields;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const drivers::can::CanFieldMap& f = fields[i];
    if (f.field != drivers::can::ImuField::kCounter || c.imu.clock_kind != "counter_us_32bit") {
      continue;
    }
    if (f.type != drivers::can::FieldType::kU32 || f.scale != 1.0 || f.offset != 0.0) {
      const std::string key = "imu.can_mapping.fields[" + std::to_string(i) + "]";
      const auto [line, column] = loader.place_of(key);
      errors.push_back({std::string(file), line, column, key,
                        "imu.clock_kind counter_us_32bit needs a microsecond counter that wraps "
                        "at 2^32 (type u32, scale 1, offset 0); for another counter set "
                        "imu.clock_kind: none (samples stamped at arrival) or leave it unmapped"});
    }
  }
}

}  // namespace

std::string ConfigError::to_string() const {
  std::string s = file;
  if (line > 0) s += ":" + std::to_string(line) + ":" + std::to_string(column);
  s += ": ";
  if (!key.empty()) s += key + ": ";
  return s + reason;
}

std::string LoadResult::error_text() const {
  std::string s;
  for (const auto& e : errors) s += e.to_string() + "\n";
  return s;
}

PosedConfig default_config() {
  // Parsed once: ~150 YAML documents per load otherwise, which made every config load (and the
  // config fuzzer's every input) pay for the schema rather than for the file.
  static const PosedConfig defaults = [] {
    PosedConfig config;
    std::vector<ConfigError> errors;
    Loader loader("<schema defaults>", config, errors);
    for (const auto& field : schema())
      loader.apply(field, YAML::Load(std::string(field.default_yaml)));
    // A default that fails its own validation is a programming error; the unit test checks it.
    return config;
  }();
  return defaults;
}

LoadResult load_config_text(std::string_view yaml_text, std::string_view name) {
  LoadResult result;
  result.config = default_config();
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml_text));
  } catch (const YAML::ParserException& e) {
    result.errors.push_back(
        {std::string(name), e.mark.line + 1, e.mark.column + 1, "", "not valid YAML: " + e.msg});
    return result;
  }
  if (root.IsNull()) return result;  // an empty file means all defaults
  if (!root.IsMap()) {
    result.errors.push_back({std::string(name), root.Mark().line + 1, root.Mark().column + 1, "",
                             "expected a mapping of sections at the top level"});
    return result;
  }
  Loader loader(name, result.config, result.errors);
  loader.walk(root, "");
  if (result.errors.empty()) check_cross_field(result.config, name, loader, result.errors);
  return result;
}

LoadResult load_config_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    LoadResult result;
    result.config = default_config();
    result.errors.push_back({path, 0, 0, "", "cannot open: " + std::string(std::strerror(errno))});
    return result;
  }
  std::stringstream text;
  text << in.rdbuf();
  LoadResult result = load_config_text(text.str(), path);
  // Paths in a config file are relative to that file, wherever posed is started from.
  const auto slash = path.rfind('/');
  const std::string dir = slash == std::string::npos ? std::string(".") : path.substr(0, slash);
  for (const auto& f : schema()) {
    if (!f.is_path) continue;
    std::string& value = *std::get<std::string*>(f.ref(result.config));
    if (!value.empty() && value.front() != '/') value = dir + "/" + value;
  }
  return result;
}

std::string print_config(const PosedConfig& config_in) {
  PosedConfig config = config_in;  // FieldRef needs a mutable object; nothing is written
  std::string out = "# posed effective configuration (value  # [unit] range: description)\n";
  std::vector<std::string_view> open_sections;
  for (const auto& f : schema()) {
    // Split "a.b.c" into sections [a, b] and leaf c; close/open sections as the path changes.
    std::vector<std::string_view> parts;
    std::string_view rest = f.key;
    for (auto dot = rest.find('.'); dot != std::string_view::npos; dot = rest.find('.')) {
      parts.push_back(rest.substr(0, dot));
      rest = rest.substr(dot + 1);
    }
    std::size_t common = 0;
    while (common < parts.size() && common < open_sections.size() &&
           parts[common] == open_sections[common]) {
      ++common;
    }
    open_sections.resize(common);
    for (std::size_t i = common; i < parts.size(); ++i) {
      out += std::string(2 * i, ' ') + std::string(parts[i]) + ":\n";
      open_sections.push_back(parts[i]);
    }
    std::string value = std::visit(
        Overloaded{
            [](bool* v) { return std::string(*v ? "true" : "false"); },
            [](int* v) { return std::to_string(*v); },
            [](double* v) { return format_number(*v); },
            [](std::string* v) { return v->empty() ? std::string("\"\"") : "\"" + *v + "\""; },
            [](Rotation3* m) {
              std::string s = "[";
              for (std::size_t i = 0; i < m->size(); ++i)
                s += (i ? ", " : "") + format_number((*m)[i]);
              return s + "]";
            },
            [](Transform4* m) {
              std::string s = "[";
              for (std::size_t i = 0; i < m->size(); ++i)
                s += (i ? ", " : "") + format_number((*m)[i]);
              return s + "]";
            },
            [](drivers::can::CanImuMapping* m) { return can_mapping_yaml(*m); },
        },
        f.ref(config));
    std::string comment;
    if (!f.unit.empty()) comment += "[" + std::string(f.unit) + "] ";
    if (f.max > f.min)
      comment += "range " + range_text(f).substr(0, range_text(f).find(']') + 1) + " ";
    if (!f.choices.empty()) comment += "one of " + std::string(f.choices) + " ";
    comment += std::string(f.description);
    out += std::string(2 * parts.size(), ' ') + std::string(rest) + ": " + value + "  # " +
           comment + "\n";
  }
  return out;
}

}  // namespace posed::config
