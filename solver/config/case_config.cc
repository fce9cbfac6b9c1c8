#include "solver/config/case_config.h"

#include <fstream>
#include <sstream>

#include <toml++/toml.h>

#include "solver/config/case_keys.h"
#include "solver/config/toml_value.h"

namespace capsim::config {
namespace {

std::string known_keys() {
  std::string out;
  for (const auto& k : case_keys()) out += (out.empty() ? "" : ", ") + k.name;
  return out;
}

/// The values a case file and its overrides give, by key (a later one replaces an earlier one), each with
/// where it was given. They are range-checked only once all are read, so that an override may correct a
/// bad value of the file, and before they are stored into the (narrower) CaseConfig fields.
struct Given {
  KeyValue value;
  std::string where;
};
using GivenValues = std::map<const CaseKey*, Given>;

void give(const CaseKey& key, const toml::node& node, const std::string& where, GivenValues& given) {
  std::string why;
  auto v = toml_to_key_value(key, node, why);
  if (!v) throw ConfigError(where + ": " + why);
  given[&key] = {std::move(*v), where};
}

void read_table(const toml::table& root, const std::string& origin, GivenValues& given) {
  for (const auto& [section_key, section_node] : root) {
    const std::string section(section_key.str());
    const auto* table = section_node.as_table();
    if (!table) throw ConfigError(origin + ": '" + section + "' must be a [section] (known keys: " + known_keys() + ")");
    for (const auto& [key, node] : *table) {
      const std::string name = section + "." + std::string(key.str());
      const CaseKey* k = find_case_key(name);
      if (!k) throw ConfigError(origin + ": unknown key '" + name + "' (known keys: " + known_keys() + ")");
      give(*k, node, origin + ": " + name, given);
    }
  }
}

void read_override(const std::string& item, GivenValues& given) {
  const auto eq = item.find('=');
  const auto dot = item.find('.');
  if (eq == std::string::npos || dot == std::string::npos || dot > eq)
    throw ConfigError("--set " + item + ": expected section.key=value");
  const std::string name = item.substr(0, eq), value = item.substr(eq + 1);
  const CaseKey* k = find_case_key(name);
  if (!k) throw ConfigError("--set: unknown key '" + name + "' (known keys: " + known_keys() + ")");
  toml::table t;
  try {
    t = toml::parse("v = " + value);
  } catch (const toml::parse_error&) {
    t = toml::table{{"v", value}};  // a bare word is a string: --set capsule.law=skalak
  }
  give(*k, *t.get("v"), "--set " + name, given);
}

}  // namespace

void CaseConfig::validate() const {
  for (const auto& k : case_keys())
    if (auto why = check_case_value(k, k.get(*this)); !why.empty()) throw ConfigError(k.name + ": " + why);
}

std::map<std::string, std::string> CaseConfig::to_map() const {
  std::map<std::string, std::string> out;
  for (const auto& k : case_keys()) out[k.name] = identity_text(k.get(*this));
  return out;
}

std::string CaseConfig::to_toml() const {
  std::string out, current;
  for (const auto& k : case_keys()) {
    if (current != k.section()) {
      current = k.section();
      out += (out.empty() ? "[" : "\n[") + current + "]\n";
    }
    out += k.short_name() + " = " + identity_text(k.get(*this)) + "\n";
  }
  return out;
}

std::vector<std::string> case_key_names() {
  std::vector<std::string> out;
  for (const auto& k : case_keys()) out.push_back(k.name);
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
  GivenValues given;
  read_table(root, origin, given);
  for (const auto& o : overrides) read_override(o, given);
  for (const auto& [key, g] : given) {
    if (auto why = check_case_value(*key, g.value); !why.empty()) throw ConfigError(g.where + ": " + why);
    key->set(c, g.value);
  }
  c.validate();  // the defaults of the keys not given pass their own rules (case_keys_test checks it)
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
