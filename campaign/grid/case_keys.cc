#include "campaign/grid/case_keys.h"

#include <cmath>

#include "campaign/grid/decimal.h"

namespace capsim::campaign {

const std::vector<CaseKey>& case_keys() {
  static const std::vector<CaseKey> keys = {
      {"capsule.aspect_ratio", KeyType::kFloat, Value{2.0}, true, "a/b of the initial spheroid, > 0"},
      {"capsule.law", KeyType::kString, Value{std::string("skalak")}, true, "\"neo-hookean\" | \"skalak\""},
      {"capsule.skalak_C", KeyType::kFloat, Value{1.0}, true,
       "Skalak area-dilation constant C > -0.5 (ignored, and left out of the identity, for neo-hookean)"},
      {"flow.capillary_number", KeyType::kFloat, Value{0.3}, true, "Ca = mu gamma_dot l / Gs, > 0"},
      {"mesh.level", KeyType::kInt, Value{std::int64_t{3}}, true, "icosahedron subdivision level, 0..6"},
      {"mesh.spheroid_map", KeyType::kString, std::nullopt, true, "sphere-to-spheroid map (solver default when unset)"},
      {"time.t_end", KeyType::kFloat, Value{60.0}, true, "hard cap on simulated time (1/shear rate), > 0"},
      {"time.dt", KeyType::kFloatOrAuto, Value{std::string("auto")}, true, "\"auto\" or a time step > 0"},
      {"time.scheme", KeyType::kString, std::nullopt, true, "time integrator: \"rkc\" | \"rk2\" (solver default when unset)"},
      {"time.dt_factor", KeyType::kFloat, std::nullopt, true, "safety factor on the automatic rk2 time step, > 0"},
      {"time.dt_accuracy", KeyType::kFloat, std::nullopt, true, "automatic rkc time step (accuracy-limited), > 0"},
      {"time.period_tolerance", KeyType::kFloat, std::nullopt, true, "periodic-regime stop tolerance, > 0"},
      {"time.check_interval", KeyType::kFloat, std::nullopt, true, "time between periodic-regime checks, > 0"},
      {"time.volume_tolerance", KeyType::kFloat, std::nullopt, true, "relative volume change counted as blow-up"},
      {"numerics.regular_degree", KeyType::kInt, std::nullopt, true, "boundary-integral triangle rule: 4, 5, 6"},
      {"numerics.duffy_order", KeyType::kInt, std::nullopt, true, "Gauss points per direction, singular integrals"},
      {"numerics.membrane_degree", KeyType::kInt, std::nullopt, true, "membrane/mass-matrix triangle rule: 4, 5, 6"},
      {"numerics.volume_correction", KeyType::kBool, std::nullopt, true, "remove the discrete volume flux (true/false)"},
      {"numerics.far_degree", KeyType::kInt, std::nullopt, true, "boundary-integral far-field rule: 0 (off), 1, 2"},
      {"numerics.far_radius", KeyType::kFloat, std::nullopt, true, "far-field threshold in element radii, > 1"},
      {"output.snapshot_interval", KeyType::kFloat, Value{0.0}, false, "time between snapshots, 0 = none"},
      {"output.checkpoint_interval", KeyType::kFloat, std::nullopt, false, "time between checkpoints"},
      {"output.sample_interval", KeyType::kFloat, std::nullopt, true, "time-series sampling (0 = every step)"},
  };
  return keys;
}

const CaseKey* find_case_key(const std::string& name) {
  for (const auto& k : case_keys())
    if (k.name == name) return &k;
  return nullptr;
}

std::string value_to_text(const Value& v) {
  if (auto* i = std::get_if<std::int64_t>(&v)) return std::to_string(*i);
  if (auto* d = std::get_if<double>(&v)) {
    std::string s = canonical_double(*d);
    // Keep TOML floats floats: "2" -> "2.0".
    if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
    return s;
  }
  if (auto* b = std::get_if<bool>(&v)) return *b ? "true" : "false";
  std::string out = "\"";
  for (char c : std::get<std::string>(v)) {
    if (c == '"' || c == '\\') out.push_back('\\');
    out.push_back(c);
  }
  return out + "\"";
}

std::string check_case_value(const CaseKey& key, const Value& value) {
  const std::string& n = key.name;
  auto num = [&]() -> std::optional<double> {
    if (auto* d = std::get_if<double>(&value)) return *d;
    if (auto* i = std::get_if<std::int64_t>(&value)) return static_cast<double>(*i);
    return std::nullopt;
  };
  if (auto x = num(); x && !std::isfinite(*x)) return "must be a finite number";
  if (n == "capsule.aspect_ratio" || n == "flow.capillary_number" || n == "time.t_end" || n == "time.dt_factor") {
    if (auto x = num(); x && !(*x > 0)) return "must be > 0 (got " + value_to_text(value) + ")";
  } else if (n == "capsule.skalak_C") {
    if (auto x = num(); x && !(*x > -0.5)) return "must be > -0.5 (got " + value_to_text(value) + ")";
  } else if (n == "capsule.law") {
    const auto& s = std::get<std::string>(value);
    if (s != "neo-hookean" && s != "skalak") return "unknown law '" + s + "' (expected \"neo-hookean\" or \"skalak\")";
  } else if (n == "mesh.level") {
    auto l = std::get<std::int64_t>(value);
    if (l < 0 || l > 6) return "must be in 0..6 (got " + std::to_string(l) + ")";
  } else if (n == "time.dt") {
    if (auto* s = std::get_if<std::string>(&value); s && *s != "auto") return "must be \"auto\" or a number > 0";
    if (auto x = num(); x && !(*x > 0)) return "must be > 0 (got " + value_to_text(value) + ")";
  } else if (n == "time.period_tolerance" || n == "time.check_interval") {
    if (auto x = num(); x && !(*x > 0)) return "must be > 0 (got " + value_to_text(value) + ")";
  } else if (n == "numerics.far_degree") {
    if (auto* d = std::get_if<std::int64_t>(&value); d && (*d < 0 || *d > 2))
      return "must be 0, 1 or 2 (got " + std::to_string(*d) + ")";
  } else if (n == "numerics.far_radius") {
    if (auto x = num(); x && !(*x > 1)) return "must be > 1 (got " + value_to_text(value) + ")";
  } else if (n == "time.volume_tolerance") {
    if (auto x = num(); x && !(*x > 0 && *x < 1)) return "must be in (0, 1) (got " + value_to_text(value) + ")";
  } else if (n == "output.snapshot_interval" || n == "output.checkpoint_interval" || n == "output.sample_interval") {
    if (auto x = num(); x && *x < 0) return "must be >= 0 (got " + value_to_text(value) + ")";
  }
  return "";
}

std::string resolve_axis_name(const std::string& name) {
  if (name == "capillary_number") return "flow.capillary_number";
  if (name == "aspect_ratio") return "capsule.aspect_ratio";
  if (name == "law") return "capsule.law";
  if (name == "skalak_C") return "capsule.skalak_C";
  if (name == "mesh_level") return "mesh.level";
  if (find_case_key(name)) return name;
  return "";
}

}  // namespace capsim::campaign
