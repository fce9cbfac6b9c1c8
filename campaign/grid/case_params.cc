#include "campaign/grid/case_params.h"

#include <map>
#include <mutex>
#include <tuple>
#include <nlohmann/json.hpp>

#include "campaign/common/bad_input.h"
#include "campaign/grid/sha256.h"
#include "capsim/version.h"
#include "solver/config/case_config.h"
#include "solver/dynamics/cost_model.h"
#include "solver/mesh/mesh.h"
#include "solver/solver_version.h"

namespace capsim::campaign {

std::string solver_version() { return kSolverVersion; }

CaseParams CaseParams::defaults() {
  CaseParams p;
  for (const auto& k : case_keys())
    if (k.always_stored) p.values_[k.name] = k.default_value;
  return p;
}

CaseParams CaseParams::from_json(const std::string& json_text) {
  CaseParams p;
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(json_text);
  } catch (const std::exception& e) {
    throw BadInput(std::string("case parameters are not valid JSON: ") + e.what());
  }
  for (auto it = j.begin(); it != j.end(); ++it) {
    const CaseKey* key = find_case_key(it.key());
    if (!key) throw BadInput("case parameters: unknown key '" + it.key() + "'");
    const auto& v = it.value();
    if (v.is_boolean()) p.values_[it.key()] = v.get<bool>();
    else if (v.is_number_integer() && key->type != KeyType::kFloat && key->type != KeyType::kFloatOrAuto)
      p.values_[it.key()] = v.get<std::int64_t>();
    else if (v.is_number()) p.values_[it.key()] = v.get<double>();
    else if (v.is_string()) p.values_[it.key()] = v.get<std::string>();
    else throw BadInput("case parameters: bad value for '" + it.key() + "'");
  }
  return p;
}

namespace {
/// The value of @p key in @p m, or the registry's default when the case does not set it.
const Value& value_or_default(const std::map<std::string, Value>& m, const std::string& key) {
  auto it = m.find(key);
  return it != m.end() ? it->second : find_case_key(key)->default_value;
}
double number(const std::map<std::string, Value>& m, const std::string& key) {
  const Value& v = value_or_default(m, key);
  if (auto* i = std::get_if<std::int64_t>(&v)) return static_cast<double>(*i);
  return std::get<double>(v);
}
}  // namespace

double CaseParams::capillary_number() const { return number(values_, "flow.capillary_number"); }
double CaseParams::aspect_ratio() const { return number(values_, "capsule.aspect_ratio"); }
double CaseParams::skalak_C() const { return number(values_, "capsule.skalak_C"); }
double CaseParams::bending_modulus() const { return number(values_, "capsule.bending_modulus"); }
int CaseParams::mesh_level() const { return static_cast<int>(number(values_, "mesh.level")); }
double CaseParams::t_end() const { return number(values_, "time.t_end"); }
std::string CaseParams::law() const { return std::get<std::string>(value_or_default(values_, "capsule.law")); }

std::string CaseParams::canonical() const {
  // The solver resolves every default, so an explicit default and an unset key give the same identity,
  // and numbers are canonical however they were typed (2 and 2.0).
  const auto resolved = config::parse_case_config(to_toml(), "case " + to_json()).to_map();
  std::string out;
  for (const auto& [k, v] : resolved) {
    const CaseKey* key = find_case_key(k);
    if (!key->in_identity) continue;
    // Keys added after identities were first stored enter only when set otherwise, so that adding a key
    // leaves every existing case its identity.
    if (key->identity_omits_default && v == config::identity_text(key->default_value)) continue;
    // A key the solver ignores for this case (skalak_C of a neo-Hookean capsule) must not split one case in two.
    if (!key->unless_key.empty() && resolved.at(key->unless_key) == config::identity_text(key->unless_value)) continue;
    out += k + "=" + v + "\n";
  }
  return out;
}

std::string CaseParams::identity(const std::string& version) const {
  return sha256_hex(canonical() + "solver=" + version + "\n").substr(0, 16);
}

std::string CaseParams::to_json() const {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [k, v] : values_) std::visit([&](const auto& x) { j[k] = x; }, v);
  return j.dump();
}

std::string CaseParams::to_toml() const {
  std::map<std::string, std::string> sections;
  for (const auto& [k, v] : values_) {
    // dt = "auto" is the solver's default (an unset key); leave it out so the case file stays numeric.
    if (k == "time.dt" && std::holds_alternative<std::string>(v)) continue;
    auto dot = k.find('.');
    sections[k.substr(0, dot)] += k.substr(dot + 1) + " = " + value_to_text(v) + "\n";
  }
  std::string out = "# Written by capsim campaign: one case of a campaign.\n";
  for (const auto& [s, body] : sections) out += "\n[" + s + "]\n" + body;
  return out;
}

namespace {
/// The smallest node spacing of a case's reference mesh: what its stage count starts from. Built once per
/// (level, a/b, map); a level-4 mesh takes milliseconds.
double reference_min_spacing(const config::CaseConfig& c) {
  static std::mutex mutex;
  static std::map<std::tuple<int, double, std::string>, double> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  const auto key = std::make_tuple(c.level, c.aspect_ratio, c.spheroid_map);
  auto it = cache.find(key);
  if (it == cache.end()) {
    const auto m = mesh::make_capsule_mesh(c.level, c.aspect_ratio, mesh::parse_spheroid_map(c.spheroid_map));
    it = cache.emplace(key, mesh::min_node_spacing(m, m.nodes)).first;
  }
  return it->second;
}
}  // namespace

double CaseParams::estimated_cost() const {
  const config::CaseConfig c = config::parse_case_config(to_toml(), "case " + to_json());
  return dynamics::CostModel::case_cost(c, reference_min_spacing(c));
}

double CaseParams::estimated_cost_on_level(int level) const {
  if (level == mesh_level()) return estimated_cost();
  CaseParams moved = *this;
  moved.set("mesh.level", std::int64_t{level});
  try {
    return moved.estimated_cost();
  } catch (const config::ConfigError&) {
    return 0;
  }
}

}  // namespace capsim::campaign
