#pragma once
/// @file
/// @brief The fully resolved parameters of one case and its identity.

#include <map>
#include <string>

#include "campaign/grid/case_keys.h"

namespace capsim::campaign {

/// @brief Solver version that enters case identities: capsim::kSolverVersion (solver/solver_version.h), bumped
/// whenever the solver's numerical results change. Not the git commit: a commit that only touches docs or the
/// campaign layer must not invalidate a finished study. Each result still records its exact code_version.
std::string solver_version();

/// @brief All case keys of one case (defaults filled in), as a sorted map of dotted key -> value.
class CaseParams {
 public:
  /// @brief A case holding every key that has a default.
  static CaseParams defaults();
  /// @brief Rebuilds a case from to_json() text. @throws BadInput on unknown keys or wrong types.
  static CaseParams from_json(const std::string& json_text);

  /// @brief Sets one key (the caller has validated type and range).
  void set(const std::string& key, Value v) { values_[key] = std::move(v); }
  /// @brief Removes one key (back to its default; a kStoredWhenSet key then leaves params_json as if never set).
  void erase(const std::string& key) { values_.erase(key); }
  /// @brief All values, sorted by key.
  const std::map<std::string, Value>& values() const { return values_; }

  /// @brief flow.capillary_number.
  double capillary_number() const;
  /// @brief capsule.aspect_ratio.
  double aspect_ratio() const;
  /// @brief capsule.law.
  std::string law() const;
  /// @brief capsule.skalak_C.
  double skalak_C() const;
  /// @brief capsule.bending_modulus (0 when not set).
  double bending_modulus() const;
  /// @brief mesh.level.
  int mesh_level() const;
  /// @brief time.t_end.
  double t_end() const;

  /// @brief Canonical text of the parameters that change results: the solver's own resolved configuration
  /// (capsim::config::CaseConfig::to_map(), defaults explicit) as sorted "key=value" lines, with what the
  /// key registry (solver/config/case_keys.def) leaves out: output-only keys, keys ignored for this case
  /// (capsule.skalak_C of the neo-Hookean law) and keys added later that are at their default.
  /// @throws capsim::config::ConfigError if the solver rejects the case.
  std::string canonical() const;
  /// @brief Case identity: first 16 hex digits of SHA-256(canonical() + "solver=" + version).
  std::string identity(const std::string& version) const;
  /// @brief JSON object of all values (dotted keys).
  std::string to_json() const;
  /// @brief A case file for `capsim run` (TOML sections).
  std::string to_toml() const;
  /// @brief Relative cost estimate, for the order cases start in and the progress ETA: the one cost model's
  /// dynamics::CostModel::case_cost of the resolved case (solver/dynamics/cost_model.h says what it holds:
  /// the scene's symmetry, the kernel precision, the bending stiffness's stages, the level).
  /// @throws capsim::config::ConfigError if the solver rejects the case.
  double estimated_cost() const;
  /// @brief estimated_cost() of the same case on mesh level @p level (the ETA carries a case's measured cost
  /// from one level to the next by the ratio of the two); 0 if the solver rejects the case on that level.
  double estimated_cost_on_level(int level) const;

 private:
  std::map<std::string, Value> values_;
};

}  // namespace capsim::campaign
