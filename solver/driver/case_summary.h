#pragma once
/// @file
/// @brief The summary of one case: its parameters and every result field, in one struct with one
/// serialisation. It is the worker contract (campaign/README.md, "The worker contract"): `capsim run --json` prints to_json() as its last
/// stdout line, the driver stores it as the root attributes of case.h5 (summary_attributes), and the
/// campaign store and Slurm collect read worker lines back with from_json(). Adding a result field is one
/// member here plus one line in the field list of case_summary.cc; adding a PeriodAnalysis field is one line
/// in its field list there.
///
/// Numbers that are undefined (no period found: min_D12 and the like are NaN) are JSON null and read back as
/// NaN; HDF5 attributes keep them as NaN.

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "solver/config/case_config.h"
#include "solver/diagnostics/period_analysis.h"
#include "solver/diagnostics/wrinkle.h"
#include "solver/io/attribute.h"

namespace capsim::driver {

struct CaseResult;

/// @brief The parameters a result reports, so that a reader can check it belongs to its case.
struct CaseParameters {
  double capillary_number = 0;  ///< Ca = μ γ̇ a / Gs (JSON: both "capillary_number" and "Ca")
  double aspect_ratio = 1;
  config::MembraneLawKind law = config::MembraneLawKind::Skalak;  ///< JSON and attributes: its word
  double skalak_C = 0;  ///< enters the case only for the Skalak law
  int mesh_level = 0;
  double bending_modulus = 0;  ///< κ_b (JSON "bending_modulus"; a result from before the key reads as 0)
  double viscosity_ratio = 1;  ///< λ (JSON "viscosity_ratio"; a result from before the key reads as 1)
  double tilt = 0;             ///< capsule.tilt, degrees (JSON "tilt"; a result from before the key reads as 0)
  double azimuth = 0;          ///< capsule.azimuth, degrees (JSON "azimuth"; a result from before the key reads as 0)

  /// @brief The parameters of a resolved case configuration.
  static CaseParameters of(const config::CaseConfig& config);
};

/// @brief "" if @p reported describes the same case as @p expected, else the first field that differs with
/// its reported value ("skalak_C 2"). Numbers agree to 1e-9 relative (they went through decimal text);
/// skalak_C is compared only for the Skalak law, as the case identity does.
std::string parameter_mismatch(const CaseParameters& reported, const CaseParameters& expected);

/// @brief Everything a case reports.
struct CaseSummary {
  std::string status;  ///< "done" | "unstable" | "interrupted"
  std::string reason;  ///< why unstable or interrupted ("" when done)
  CaseParameters parameters;
  diagnostics::PeriodAnalysis analysis;  ///< regime and the period (or steady-window) metrics; periods list not serialised
  bool converged = false;
  double volume_drift = 0;
  diagnostics::WrinkleIndicators wrinkle_final, wrinkle_max;
  long steps = 0;
  long flow_evaluations = 0;
  double dt = 0, t_final = 0, wall_s = 0;
  double membrane_s = 0, load_s = 0, stokes_s = 0;  ///< wall time of the phases (CaseResult)
  double gmres_iterations_mean = 0, gmres_iterations_max = 0;  ///< viscosity-ratio solve (CaseResult; 0 at λ = 1)
  double final_tilt = 0;  ///< degrees, CaseResult::final_tilt (NaN when read from a result from before it)
  double tilt_growth_rate = 0, tilt_growth_rate_error = 0;  ///< per unit γ̇t, CaseResult (NaN: none, or before them)
  double final_spin_rate = 0;  ///< units of γ̇, CaseResult::final_spin_rate (NaN: no period, or a result from before it)
  int threads = 0;
  std::string case_file;  ///< absolute path of case.h5
  std::string code_version;    ///< git commit of the build
  /// Instruction set of the Stokeslet kernel of the build that ran (the last invocation of a resumed case):
  /// "avx512", "avx2" or "portable". Their 1/r refinements round differently, so two builds of one commit
  /// on different machines agree to round-off, not bit for bit (campaign/README.md, "Resumption guarantees").
  std::string kernel_isa;
  std::string solver_version;  ///< capsim::kSolverVersion (enters case identities)

  /// @brief The summary of a run of @p config: parameters from the configuration, results from @p result,
  /// threads from OpenMP, versions from this build.
  static CaseSummary of(const config::CaseConfig& config, const CaseResult& result);

  /// @brief The JSON object of the contract (non-finite numbers as null).
  [[nodiscard]] nlohmann::json to_json() const;
  /// @brief The summary of a JSON object written by to_json().
  /// @throws std::invalid_argument naming the field if status or a parameter is missing or of the wrong
  /// type. Result fields may be absent or null (NaN / 0 / "").
  static CaseSummary from_json(const nlohmann::json& j);
};

/// @brief The summary as the HDF5 attributes of case.h5 (same names as the JSON, booleans as 0/1, the case
/// file's own path left out).
std::vector<io::Attribute> summary_attributes(const CaseSummary& summary);

}  // namespace capsim::driver
