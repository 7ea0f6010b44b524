#include "drivers/velodyne/calibration_loader.hpp"

#include <tinyxml2.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>

namespace posed::drivers::velodyne {
namespace {

std::string where(std::string_view name, int line) {
  std::string s = "calibration file ";
  s += name;
  if (line > 0) s += " line " + std::to_string(line);
  return s + ": ";
}

/// Shared checks for every format: laser ids 0..n-1, a count the decoder supports, sane angles.
bool validate(std::string_view name, const std::map<int, std::pair<LaserCorrection, int>>& by_id,
              std::optional<int> declared_count, int count_line, Calibration& out,
              std::string& error) {
  const int n = static_cast<int>(by_id.size());
  if (declared_count && *declared_count != n) {
    error = where(name, count_line) + "num_lasers says " + std::to_string(*declared_count) +
            ", the table has " + std::to_string(n) + " lasers";
    return false;
  }
  if (n != 16 && n != 32) {
    error = where(name, count_line) + "expected 16 or 32 lasers, found " + std::to_string(n);
    return false;
  }
  out.lasers.assign(static_cast<std::size_t>(n), LaserCorrection{});
  int expected = 0;
  for (const auto& [id, entry] : by_id) {
    const auto& [laser, line] = entry;
    if (id != expected) {
      error = where(name, line) + "laser ids must be 0.." + std::to_string(n - 1) + ", found " +
              std::to_string(id) + " where " + std::to_string(expected) + " was expected";
      return false;
    }
    if (!(std::fabs(laser.vert_correction_rad) <= std::numbers::pi / 2) ||
        !(std::fabs(laser.rot_correction_rad) <= std::numbers::pi)) {
      error = where(name, line) + "laser " + std::to_string(id) +
              ": correction angle out of range (vert " + std::to_string(laser.vert_correction_rad) +
              " rad, rot " + std::to_string(laser.rot_correction_rad) + " rad)";
      return false;
    }
    if (!std::isfinite(laser.dist_correction_m) || !std::isfinite(laser.vert_offset_m) ||
        !std::isfinite(laser.horiz_offset_m)) {
      error = where(name, line) + "laser " + std::to_string(id) + ": non-finite correction";
      return false;
    }
    out.lasers[static_cast<std::size_t>(id)] = laser;
    ++expected;
  }
  if (!(out.distance_resolution_m >= 0.0 && out.distance_resolution_m <= 0.1)) {
    error = where(name, 0) + "distance resolution " + std::to_string(out.distance_resolution_m) +
            " m is out of range (0, 0.1]";
    return false;
  }
  out.source = std::string(name);
  return true;
}

// ---- VeloView XML -------------------------------------------------------------------------

bool xml_double(const tinyxml2::XMLElement* parent, const char* tag, double& value) {
  const auto* e = parent->FirstChildElement(tag);
  if (e == nullptr) return true;  // optional: VeloView omits zero corrections in old files
  return e->QueryDoubleText(&value) == tinyxml2::XML_SUCCESS;
}

}  // namespace

bool parse_calibration_xml(std::string_view text, std::string_view name, Calibration& out,
                           std::string& error) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) {
    error = where(name, doc.ErrorLineNum()) + "XML: " + doc.ErrorStr();
    return false;
  }
  const tinyxml2::XMLElement* db = nullptr;
  if (const auto* root = doc.FirstChildElement("boost_serialization")) {
    db = root->FirstChildElement("DB");
  }
  if (db == nullptr) {
    error = where(name, 0) + "not a VeloView calibration (no <boost_serialization><DB>)";
    return false;
  }
  Calibration cal;
  if (const auto* lsb = db->FirstChildElement("distLSB_")) {
    double lsb_cm = 0.0;
    if (lsb->QueryDoubleText(&lsb_cm) != tinyxml2::XML_SUCCESS) {
      error = where(name, lsb->GetLineNum()) + "distLSB_ is not a number";
      return false;
    }
    cal.distance_resolution_m = lsb_cm / 100.0;  // VeloView stores centimetres
  }
  // <enabled_> lists 64 flags (the HDL-64 layout); a 32-laser sensor enables the first 32.
  std::vector<int> enabled;
  if (const auto* en = db->FirstChildElement("enabled_")) {
    for (const auto* it = en->FirstChildElement("item"); it; it = it->NextSiblingElement("item")) {
      int v = 0;
      if (it->QueryIntText(&v) != tinyxml2::XML_SUCCESS) {
        error = where(name, it->GetLineNum()) + "enabled_ item is not an integer";
        return false;
      }
      enabled.push_back(v);
    }
  }
  const auto* points = db->FirstChildElement("points_");
  if (points == nullptr) {
    error = where(name, db->GetLineNum()) + "no <points_> (per-laser table)";
    return false;
  }
  std::map<int, std::pair<LaserCorrection, int>> by_id;
  for (const auto* item = points->FirstChildElement("item"); item;
       item = item->NextSiblingElement("item")) {
    const auto* px = item->FirstChildElement("px");
    if (px == nullptr) continue;
    const int line = px->GetLineNum();
    int id = -1;
    const auto* id_e = px->FirstChildElement("id_");
    if (id_e == nullptr || id_e->QueryIntText(&id) != tinyxml2::XML_SUCCESS || id < 0) {
      error = where(name, line) + "laser entry without a valid <id_>";
      return false;
    }
    if (!enabled.empty() && (static_cast<std::size_t>(id) >= enabled.size() ||
                             enabled[static_cast<std::size_t>(id)] == 0)) {
      continue;
    }
    double rot_deg = 0, vert_deg = 0, dist_cm = 0, voff_cm = 0, hoff_cm = 0;
    if (!xml_double(px, "rotCorrection_", rot_deg) ||
        !xml_double(px, "vertCorrection_", vert_deg) ||
        !xml_double(px, "distCorrection_", dist_cm) ||
        !xml_double(px, "vertOffsetCorrection_", voff_cm) ||
        !xml_double(px, "horizOffsetCorrection_", hoff_cm)) {
      error = where(name, line) + "laser " + std::to_string(id) + ": a correction is not a number";
      return false;
    }
    LaserCorrection l;
    l.rot_correction_rad = rot_deg * kDegToRad;
    l.vert_correction_rad = vert_deg * kDegToRad;
    l.dist_correction_m = dist_cm / 100.0;
    l.vert_offset_m = voff_cm / 100.0;
    l.horiz_offset_m = hoff_cm / 100.0;
    if (!by_id.emplace(id, std::pair{l, line}).second) {
      error = where(name, line) + "laser " + std::to_string(id) + " listed twice";
      return false;
    }
  }
  return validate(name, by_id, std::nullopt, points->GetLineNum(), cal, error) &&
         (out = std::move(cal), true);
}

bool parse_calibration_yaml(std::string_view text, std::string_view name, Calibration& out,
                            std::string& error) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    error = where(name, e.mark.line + 1) + "YAML: " + e.msg;
    return false;
  }
  try {
    if (!root.IsMap() || !root["lasers"] || !root["lasers"].IsSequence()) {
      error = where(name, root.Mark().line + 1) + "expected a map with a 'lasers' list";
      return false;
    }
    Calibration cal;
    std::optional<int> declared;
    int count_line = root["lasers"].Mark().line + 1;
    if (const auto n = root["num_lasers"]) {
      declared = n.as<int>();
      count_line = n.Mark().line + 1;
    }
    if (const auto r = root["distance_resolution"]) cal.distance_resolution_m = r.as<double>();
    std::map<int, std::pair<LaserCorrection, int>> by_id;
    for (const auto& entry : root["lasers"]) {
      const int line = entry.Mark().line + 1;
      if (!entry.IsMap() || !entry["laser_id"]) {
        error = where(name, line) + "laser entry without laser_id";
        return false;
      }
      const auto get = [&](const char* key) {
        const auto v = entry[key];
        return v ? v.as<double>() : 0.0;
      };
      const int id = entry["laser_id"].as<int>();
      if (!entry["vert_correction"]) {
        error = where(name, line) + "laser " + std::to_string(id) + " has no vert_correction";
        return false;
      }
      LaserCorrection l;
      l.rot_correction_rad = get("rot_correction");
      l.vert_correction_rad = get("vert_correction");
      l.dist_correction_m = get("dist_correction");
      l.vert_offset_m = get("vert_offset_correction");
      l.horiz_offset_m = get("horiz_offset_correction");
      if (id < 0 || !by_id.emplace(id, std::pair{l, line}).second) {
        error = where(name, line) + "laser id " + std::to_string(id) + " invalid or listed twice";
        return false;
      }
    }
    if (!validate(name, by_id, declared, count_line, cal, error)) return false;
    out = std::move(cal);
    return true;
  } catch (const YAML::Exception& e) {
    error = where(name, e.mark.line + 1) + e.msg;
    return false;
  }
}

bool load_calibration(const std::string& path, Calibration& out, std::string& error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = where(path, 0) + "cannot open";
    return false;
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse_calibration_text(buffer.str(), path, out, error);
}

bool parse_calibration_text(std::string_view text, std::string_view name, Calibration& out,
                            std::string& error) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first != std::string_view::npos && text[first] == '<') {
    return parse_calibration_xml(text, name, out, error);
  }
  return parse_calibration_yaml(text, name, out, error);
}

}  // namespace posed::drivers::velodyne
