#include "solver/config/case_config.h"

#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>

#include <toml++/toml.h>

#include "solver/membrane/membrane_law.h"
#include "solver/mesh/mesh.h"

namespace capsim::config {
namespace {

std::string fmt_double(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  std::string s = os.str();
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

// One accepted key: how to read it from a TOML node into the config.
struct KeySpec {
  const char* section;
  const char* name;
  std::function<void(const toml::node&, CaseConfig&, const std::string& where)> read;
};

double as_number(const toml::node& n, const std::string& where) {
  if (auto v = n.value_exact<double>()) return *v;
  if (auto v = n.value_exact<int64_t>()) return static_cast<double>(*v);
  throw ConfigError(where + ": expected a number");
}
int as_int(const toml::node& n, const std::string& where) {
  if (auto v = n.value_exact<int64_t>()) return static_cast<int>(*v);
  throw ConfigError(where + ": expected an integer");
}
bool as_bool(const toml::node& n, const std::string& where) {
  if (auto v = n.value_exact<bool>()) return *v;
  throw ConfigError(where + ": expected true or false");
}
std::string as_string(const toml::node& n, const std::string& where) {
  if (auto v = n.value_exact<std::string>()) return *v;
  throw ConfigError(where + ": expected a string");
}

const std::vector<KeySpec>& key_specs() {
  static const std::vector<KeySpec> specs = {
      {"capsule", "aspect_ratio", [](auto& n, auto& c, auto& w) { c.aspect_ratio = as_number(n, w); }},
      {"capsule", "law", [](auto& n, auto& c, auto& w) { c.law = as_string(n, w); }},
      {"capsule", "skalak_C", [](auto& n, auto& c, auto& w) { c.skalak_C = as_number(n, w); }},
      {"flow", "capillary_number", [](auto& n, auto& c, auto& w) { c.capillary_number = as_number(n, w); }},
      {"mesh", "level", [](auto& n, auto& c, auto& w) { c.level = as_int(n, w); }},
      {"mesh", "spheroid_map", [](auto& n, auto& c, auto& w) { c.spheroid_map = as_string(n, w); }},
      {"time", "t_end", [](auto& n, auto& c, auto& w) { c.t_end = as_number(n, w); }},
      {"time", "scheme", [](auto& n, auto& c, auto& w) { c.scheme = as_string(n, w); }},
      {"time", "dt",
       [](auto& n, auto& c, auto& w) {
         if (auto s = n.template value_exact<std::string>()) {
           if (*s != "auto") throw ConfigError(w + ": expected \"auto\" or a number");
           c.dt.reset();
         } else {
           c.dt = as_number(n, w);
         }
       }},
      {"time", "dt_factor", [](auto& n, auto& c, auto& w) { c.dt_factor = as_number(n, w); }},
      {"time", "dt_accuracy", [](auto& n, auto& c, auto& w) { c.dt_accuracy = as_number(n, w); }},
      {"time", "period_tolerance", [](auto& n, auto& c, auto& w) { c.period_tolerance = as_number(n, w); }},
      {"time", "check_interval", [](auto& n, auto& c, auto& w) { c.check_interval = as_number(n, w); }},
      {"time", "volume_tolerance", [](auto& n, auto& c, auto& w) { c.volume_tolerance = as_number(n, w); }},
      {"numerics", "regular_degree", [](auto& n, auto& c, auto& w) { c.regular_degree = as_int(n, w); }},
      {"numerics", "duffy_order", [](auto& n, auto& c, auto& w) { c.duffy_order = as_int(n, w); }},
      {"numerics", "membrane_degree", [](auto& n, auto& c, auto& w) { c.membrane_degree = as_int(n, w); }},
      {"numerics", "volume_correction", [](auto& n, auto& c, auto& w) { c.volume_correction = as_bool(n, w); }},
      {"numerics", "far_degree", [](auto& n, auto& c, auto& w) { c.far_degree = as_int(n, w); }},
      {"numerics", "far_radius", [](auto& n, auto& c, auto& w) { c.far_radius = as_number(n, w); }},
      {"output", "snapshot_interval", [](auto& n, auto& c, auto& w) { c.snapshot_interval = as_number(n, w); }},
      {"output", "checkpoint_interval", [](auto& n, auto& c, auto& w) { c.checkpoint_interval = as_number(n, w); }},
      {"output", "sample_interval", [](auto& n, auto& c, auto& w) { c.sample_interval = as_number(n, w); }},
  };
  return specs;
}

const KeySpec* find_spec(const std::string& section, const std::string& name) {
  for (const auto& s : key_specs())
    if (section == s.section && name == s.name) return &s;
  return nullptr;
}

std::string known_keys() {
  std::string out;
  for (const auto& s : key_specs()) out += std::string(out.empty() ? "" : ", ") + s.section + "." + s.name;
  return out;
}

void apply_table(const toml::table& root, CaseConfig& c, const std::string& origin) {
  for (const auto& [section_key, section_node] : root) {
    const std::string section(section_key.str());
    const auto* table = section_node.as_table();
    if (!table) throw ConfigError(origin + ": '" + section + "' must be a [section] (known keys: " + known_keys() + ")");
    for (const auto& [key, node] : *table) {
      const std::string name(key.str());
      const KeySpec* spec = find_spec(section, name);
      if (!spec) throw ConfigError(origin + ": unknown key '" + section + "." + name + "' (known keys: " + known_keys() + ")");
      spec->read(node, c, origin + ": " + section + "." + name);
    }
  }
}

void apply_override(const std::string& item, CaseConfig& c) {
  const auto eq = item.find('=');
  const auto dot = item.find('.');
  if (eq == std::string::npos || dot == std::string::npos || dot > eq)
    throw ConfigError("--set " + item + ": expected section.key=value");
  const std::string section = item.substr(0, dot), name = item.substr(dot + 1, eq - dot - 1);
  const std::string value = item.substr(eq + 1);
  const KeySpec* spec = find_spec(section, name);
  if (!spec) throw ConfigError("--set: unknown key '" + section + "." + name + "' (known keys: " + known_keys() + ")");
  toml::table t;
  try {
    t = toml::parse("v = " + value);
  } catch (const toml::parse_error&) {
    t = toml::table{{"v", value}};  // a bare word is a string: --set capsule.law=skalak
  }
  spec->read(*t.get("v"), c, "--set " + section + "." + name);
}

void require(bool ok, const std::string& key, double value, const std::string& rule) {
  if (!ok) throw ConfigError(key + " = " + fmt_double(value) + " is out of range (" + rule + ")");
}

}  // namespace

void CaseConfig::validate() const {
  require(std::isfinite(aspect_ratio) && aspect_ratio > 0.0, "capsule.aspect_ratio", aspect_ratio, "must be > 0");
  if (law != "neo-hookean" && law != "skalak")
    throw ConfigError("capsule.law = \"" + law + "\" is not known (choose \"neo-hookean\" or \"skalak\")");
  require(std::isfinite(skalak_C) && skalak_C > -0.5, "capsule.skalak_C", skalak_C, "must be > -0.5");
  require(std::isfinite(capillary_number) && capillary_number > 0.0, "flow.capillary_number", capillary_number,
          "must be > 0");
  require(level >= 0 && level <= 6, "mesh.level", level, "0..6");
  try {
    (void)mesh::parse_spheroid_map(spheroid_map);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(e.what());
  }
  require(std::isfinite(t_end) && t_end > 0.0, "time.t_end", t_end, "must be > 0");
  if (dt) require(std::isfinite(*dt) && *dt > 0.0, "time.dt", *dt, "must be > 0 or \"auto\"");
  if (scheme != "rk2" && scheme != "rkc")
    throw ConfigError("time.scheme = \"" + scheme + "\" is not known (choose \"rk2\" or \"rkc\")");
  require(std::isfinite(dt_factor) && dt_factor > 0.0, "time.dt_factor", dt_factor, "must be > 0");
  require(std::isfinite(dt_accuracy) && dt_accuracy > 0.0, "time.dt_accuracy", dt_accuracy, "must be > 0");
  require(period_tolerance > 0.0, "time.period_tolerance", period_tolerance, "must be > 0");
  require(check_interval > 0.0, "time.check_interval", check_interval, "must be > 0");
  require(volume_tolerance > 0.0 && volume_tolerance < 1.0, "time.volume_tolerance", volume_tolerance, "0 < v < 1");
  for (auto [key, v] : {std::pair{"numerics.regular_degree", regular_degree}, {"numerics.membrane_degree", membrane_degree}})
    require(v >= 4 && v <= 6, key, v, "4, 5 or 6");
  require(duffy_order >= 2 && duffy_order <= 64, "numerics.duffy_order", duffy_order, "2..64");
  require(far_degree >= 0 && far_degree <= 2, "numerics.far_degree", far_degree, "0 (off), 1 or 2");
  require(std::isfinite(far_radius) && far_radius > 1.0, "numerics.far_radius", far_radius, "must be > 1");
  require(snapshot_interval >= 0.0, "output.snapshot_interval", snapshot_interval, "must be >= 0");
  require(checkpoint_interval >= 0.0, "output.checkpoint_interval", checkpoint_interval, "must be >= 0");
  require(sample_interval >= 0.0, "output.sample_interval", sample_interval, "must be >= 0");
}

std::map<std::string, std::string> CaseConfig::to_map() const {
  return {
      {"capsule.aspect_ratio", fmt_double(aspect_ratio)},
      {"capsule.law", "\"" + law + "\""},
      {"capsule.skalak_C", fmt_double(skalak_C)},
      {"flow.capillary_number", fmt_double(capillary_number)},
      {"mesh.level", std::to_string(level)},
      {"mesh.spheroid_map", "\"" + spheroid_map + "\""},
      {"time.t_end", fmt_double(t_end)},
      {"time.scheme", "\"" + scheme + "\""},
      {"time.dt", dt ? fmt_double(*dt) : "\"auto\""},
      {"time.dt_factor", fmt_double(dt_factor)},
      {"time.dt_accuracy", fmt_double(dt_accuracy)},
      {"time.period_tolerance", fmt_double(period_tolerance)},
      {"time.check_interval", fmt_double(check_interval)},
      {"time.volume_tolerance", fmt_double(volume_tolerance)},
      {"numerics.regular_degree", std::to_string(regular_degree)},
      {"numerics.duffy_order", std::to_string(duffy_order)},
      {"numerics.membrane_degree", std::to_string(membrane_degree)},
      {"numerics.volume_correction", volume_correction ? "true" : "false"},
      {"numerics.far_degree", std::to_string(far_degree)},
      {"numerics.far_radius", fmt_double(far_radius)},
      {"output.snapshot_interval", fmt_double(snapshot_interval)},
      {"output.checkpoint_interval", fmt_double(checkpoint_interval)},
      {"output.sample_interval", fmt_double(sample_interval)},
  };
}

std::string CaseConfig::to_toml() const {
  std::string out, current;
  for (const auto& s : key_specs()) {
    if (current != s.section) {
      out += std::string(out.empty() ? "" : "\n") + "[" + s.section + "]\n";
      current = s.section;
    }
    out += std::string(s.name) + " = " + to_map().at(std::string(s.section) + "." + s.name) + "\n";
  }
  return out;
}

std::vector<std::string> case_key_names() {
  std::vector<std::string> out;
  for (const auto& s : key_specs()) out.push_back(std::string(s.section) + "." + s.name);
  return out;
}

CaseConfig parse_case_config(const std::string& text, const std::string& origin,
                             const std::vector<std::string>& overrides) {
  CaseConfig c;
  toml::table root;
  try {
    root = toml::parse(text, origin);
  } catch (const toml::parse_error& e) {
    std::ostringstream os;
    os << origin << ":" << e.source().begin.line << ": " << e.description();
    throw ConfigError(os.str());
  }
  apply_table(root, c, origin);
  for (const auto& o : overrides) apply_override(o, c);
  c.validate();
  return c;
}

CaseConfig load_case_config(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ": cannot open the case file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_case_config(ss.str(), path, overrides);
}

}  // namespace capsim::config
