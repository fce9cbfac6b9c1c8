#include "campaign/grid/case_keys.h"

#include "campaign/grid/decimal.h"

namespace capsim::campaign {

std::string value_to_text(const Value& v) {
  if (auto* d = std::get_if<double>(&v)) {
    std::string s = canonical_double(*d);
    // Keep TOML floats floats: "2" -> "2.0".
    if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
    return s;
  }
  if (auto* str = std::get_if<std::string>(&v)) {
    std::string out = "\"";
    for (char c : *str) {
      if (c == '"' || c == '\\') out.push_back('\\');
      out.push_back(c);
    }
    return out + "\"";
  }
  return config::shortest_text(v);  // integers and booleans
}

const std::vector<std::pair<std::string, std::string>>& axis_aliases() {
  static const std::vector<std::pair<std::string, std::string>> aliases = {
      {"capillary_number", "flow.capillary_number"},
      {"aspect_ratio", "capsule.aspect_ratio"},
      {"law", "capsule.law"},
      {"skalak_C", "capsule.skalak_C"},
      {"mesh_level", "mesh.level"},
      {"bending_modulus", "capsule.bending_modulus"},
      {"viscosity_ratio", "flow.viscosity_ratio"},
      {"tilt", "capsule.tilt"},
      {"azimuth", "capsule.azimuth"},
  };
  return aliases;
}

std::string resolve_axis_name(const std::string& name) {
  for (const auto& [alias, key] : axis_aliases())
    if (name == alias) return key;
  if (find_case_key(name)) return name;
  return "";
}

}  // namespace capsim::campaign
