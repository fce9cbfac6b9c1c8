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
  /// @brief Relative cost estimate, for the order cases start in and the ETA's per-level fit:
  ///   t_end · (flow evaluations per unit time) · kEvaluationCostPerLevel^level,
  /// the evaluations per unit time from the solver's own step rule on the reference mesh
  /// (dynamics::evaluations_per_unit_time: the RKC stages grow as (Ca h)^−1/2, with bending as
  /// sqrt(1 + ρ_b/ρ_el)). Not a prediction of seconds: prestress adds stages along a run and periodic cases
  /// stop before t_end (the EtaModel fits wall ∝ est^β per level). With numerics.kernel_precision = "mixed"
  /// the estimate is multiplied by mixed_precision_cost_factor(level).
  /// @throws capsim::config::ConfigError if the solver rejects the case.
  double estimated_cost() const;
  /// @brief What a flow evaluation costs in mixed precision relative to double on mesh level @p level:
  ///   (S 16^(L−3) / kMixedSumSpeedup + R 4^(L−3)) / (S 16^(L−3) + R 4^(L−3)),
  /// an evaluation being the all-pairs regular sum S (∝ N², the only part mixed precision speeds up) plus the
  /// O(N) rest R (singular and near-singular corrections, membrane, load). S : R = kRegularShareLevel3 at
  /// level 3; the factor is ≈ 0.85, 0.65, 0.49 on levels 2, 3, 4 (the evaluations measured 0.61 and 0.45 on
  /// levels 3 and 4, `capsim bench flow --precision mixed`).
  static double mixed_precision_cost_factor(int level);
  /// @brief S / R of a double-precision level-3 evaluation: the bare regular sum 18.5 ms of 32.0 ms (1 thread,
  /// symmetric scene; results/benchmarks.md, "Flow evaluation by phase").
  static constexpr double kRegularShareLevel3 = 18.5 / (32.0 - 18.5);
  /// @brief How much faster the regular sum is in mixed precision inside an evaluation: 18.5 ms against 7.4 ms
  /// at level 3 (results/benchmarks.md, "Mixed precision").
  static constexpr double kMixedSumSpeedup = 2.5;
  /// @brief What one flow evaluation costs per mesh level finer (×4 nodes): the all-pairs sum alone would be
  /// 16, the near and singular parts 4; `capsim bench flow` measured 8.2 (mixed) and 10.3 (double) from level 3
  /// to 4 (results/speed/bench_flow_L{3,4}_T1*.json).
  static constexpr double kEvaluationCostPerLevel = 9.0;

 private:
  std::map<std::string, Value> values_;
};

}  // namespace capsim::campaign
