// The ros2msg text recordings and Foxglove carry for posed_msgs/msg/Status against the IDL the
// DDS wire is generated from: CDR is positional, so a field missing, added or out of order in
// either one makes Foxglove, PlotJuggler and ROS 2 tools decode every later field wrongly.

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "drivers/recording/ros2_schemas.hpp"

namespace posed::dds {
namespace {

std::string idl_text() {
  const char* source_dir = std::getenv("POSED_SOURCE_DIR");
  std::ifstream in(std::string(source_dir != nullptr ? source_dir : POSED_TEST_SOURCE_DIR) +
                   "/daemon/dds/idl/posed_msgs.idl");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// An IDL type as ros2msg spells it: "double" -> "float64", "Foo_" -> "Foo".
std::string msg_type(const std::string& idl) {
  static const std::map<std::string, std::string> kNames = {
      {"double", "float64"},
      {"boolean", "bool"},
      {"std_msgs::msg::dds_::Header_", "std_msgs/Header"}};
  if (const auto it = kNames.find(idl); it != kNames.end()) return it->second;
  if (!idl.empty() && idl.back() == '_') return idl.substr(0, idl.size() - 1);
  return idl;
}

/// posed_msgs.idl's structs, each as its ros2msg lines ("float64[3] gyro_bias_radps").
std::map<std::string, std::vector<std::string>> idl_structs() {
  const std::string text =
      std::regex_replace(idl_text(), std::regex("//[^\n]*"), "");  // doc comments
  const std::regex strukt(R"(struct\s+(\w+)_\s*\{([^}]*)\})");
  const std::regex member(
      R"(^\s*(?:sequence<\s*([\w:]+)\s*>|([\w:]+))\s+(\w+)\s*(?:\[\s*(\d+)\s*\])?\s*$)");
  std::map<std::string, std::vector<std::string>> structs;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), strukt);
       it != std::sregex_iterator(); ++it) {
    std::vector<std::string>& lines = structs[(*it)[1].str()];
    std::stringstream body((*it)[2].str());
    std::string declaration;
    while (std::getline(body, declaration, ';')) {
      if (declaration.find_first_not_of(" \n\t") == std::string::npos) continue;
      std::smatch m;
      EXPECT_TRUE(std::regex_match(declaration, m, member)) << declaration;
      if (m.empty()) continue;
      const std::string suffix = m[1].matched ? "[]" : m[4].matched ? "[" + m[4].str() + "]" : "";
      lines.push_back(msg_type(m[1].matched ? m[1].str() : m[2].str()) + suffix + " " + m[3].str());
    }
  }
  return structs;
}

/// A schema's definitions: "" for the top-level type, else "pkg/Type" -> its field lines.
std::map<std::string, std::vector<std::string>> schema_definitions(std::string_view schema) {
  std::map<std::string, std::vector<std::string>> definitions;
  std::vector<std::string>* current = &definitions[""];
  std::stringstream text{std::string(schema)};
  std::string line;
  while (std::getline(text, line)) {
    if (line.rfind("====", 0) == 0) continue;
    if (line.rfind("MSG: ", 0) == 0) {
      current = &definitions[line.substr(5)];
    } else if (!line.empty()) {
      current->push_back(line);
    }
  }
  return definitions;
}

TEST(Ros2Schema, StatusMatchesTheIdlFieldForField) {
  const auto structs = idl_structs();
  ASSERT_EQ(structs.count("Status"), 1u) << "posed_msgs.idl not found or not parsed";
  const auto definitions = schema_definitions(drivers::recording::ros2::posed_status_schema());
  EXPECT_EQ(definitions.at(""), structs.at("Status"));
  for (const auto& [name, fields] : structs) {
    if (name == "Status") continue;
    const auto it = definitions.find("posed_msgs/" + name);
    ASSERT_NE(it, definitions.end()) << "posed_msgs/" << name << " is not in the schema";
    EXPECT_EQ(it->second, fields) << "posed_msgs/" << name;
  }
  // The mapping stage's member is the last one, so older readers' layout is a prefix of it.
  EXPECT_EQ(structs.at("Status").back(), "MappingStatus mapping");
}

}  // namespace
}  // namespace posed::dds
