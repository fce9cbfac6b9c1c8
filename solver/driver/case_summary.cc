#include "solver/driver/case_summary.h"

#include <omp.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "capsim/version.h"
#include "solver/driver/case_driver.h"
#include "solver/solver_version.h"
#include "solver/stokes/stokeslet.h"

namespace capsim::driver {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The serialised fields, each once: JSON and HDF5 names are the same. A new PeriodAnalysis number is one
// line in kAnalysisFields; a new result number one line in kNumberFields.
struct AnalysisField {
  const char* name;
  double diagnostics::PeriodAnalysis::*member;
};
constexpr AnalysisField kAnalysisFields[] = {
    {"min_D12", &diagnostics::PeriodAnalysis::min_D12},
    {"max_tau_min", &diagnostics::PeriodAnalysis::max_tau_min},
    {"mean_D12", &diagnostics::PeriodAnalysis::mean_D12},
    {"period", &diagnostics::PeriodAnalysis::period},
    {"theta_mean", &diagnostics::PeriodAnalysis::theta_mean},
    {"theta_amplitude", &diagnostics::PeriodAnalysis::theta_amplitude},
    {"min_tau_min", &diagnostics::PeriodAnalysis::min_tau_min},
    {"mean_tau_min", &diagnostics::PeriodAnalysis::mean_tau_min},
    {"tau_min_spread", &diagnostics::PeriodAnalysis::tau_min_spread},
    {"min_D12_period_spread", &diagnostics::PeriodAnalysis::min_D12_period_spread},
    {"max_tau_min_period_spread", &diagnostics::PeriodAnalysis::max_tau_min_period_spread},
};

struct NumberField {
  const char* name;
  double (*get)(const CaseSummary&);
  void (*set)(CaseSummary&, double);
};
#define CAPSIM_SUMMARY_NUMBER(name, expr)                                   \
  NumberField {                                                             \
    #name, [](const CaseSummary& s) -> double { return s.expr; },           \
        [](CaseSummary& s, double v) { s.expr = v; }                        \
  }
const NumberField kNumberFields[] = {
    CAPSIM_SUMMARY_NUMBER(volume_drift, volume_drift),
    CAPSIM_SUMMARY_NUMBER(compressed_area_fraction, wrinkle_final.compressed_area_fraction),
    CAPSIM_SUMMARY_NUMBER(load_roughness, wrinkle_final.load_roughness),
    CAPSIM_SUMMARY_NUMBER(max_compressed_area_fraction, wrinkle_max.compressed_area_fraction),
    CAPSIM_SUMMARY_NUMBER(max_load_roughness, wrinkle_max.load_roughness),
    CAPSIM_SUMMARY_NUMBER(wrinkle_wavelength, wrinkle_final.wrinkle_wavelength),
    CAPSIM_SUMMARY_NUMBER(wrinkle_amplitude, wrinkle_final.wrinkle_amplitude),
    CAPSIM_SUMMARY_NUMBER(max_wrinkle_amplitude, wrinkle_max.wrinkle_amplitude),
    CAPSIM_SUMMARY_NUMBER(wrinkle_wavelength_of_max, wrinkle_max.wrinkle_wavelength),
    CAPSIM_SUMMARY_NUMBER(dt, dt),
    CAPSIM_SUMMARY_NUMBER(t_final, t_final),
    CAPSIM_SUMMARY_NUMBER(wall_s, wall_s),
    CAPSIM_SUMMARY_NUMBER(membrane_s, membrane_s),
    CAPSIM_SUMMARY_NUMBER(load_s, load_s),
    CAPSIM_SUMMARY_NUMBER(stokes_s, stokes_s),
    CAPSIM_SUMMARY_NUMBER(gmres_iterations_mean, gmres_iterations_mean),
    CAPSIM_SUMMARY_NUMBER(gmres_iterations_max, gmres_iterations_max),
    CAPSIM_SUMMARY_NUMBER(final_tilt, final_tilt),
    CAPSIM_SUMMARY_NUMBER(tilt_growth_rate, tilt_growth_rate),
    CAPSIM_SUMMARY_NUMBER(tilt_growth_rate_error, tilt_growth_rate_error),
    CAPSIM_SUMMARY_NUMBER(final_spin_rate, final_spin_rate),
};
#undef CAPSIM_SUMMARY_NUMBER

// JSON has no NaN or infinity: undefined numbers are null.
nlohmann::json json_number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

double number_or_nan(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_number() ? it->get<double>() : kNaN;
}

long integer_or_zero(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_number_integer() ? it->get<long>() : 0;
}

std::string string_or_empty(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}

double required_number(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_number()) throw std::invalid_argument(std::string("result: '") + key + "' missing or not a number");
  return it->get<double>();
}

// The regime named @p name; every enumerator is tried (to_string is the one spelling of each), so a regime
// added to diagnostics::Regime is read back without a change here.
diagnostics::Regime regime_of(const std::string& name) {
  for (int i = 0; i < 64; ++i)
    if (diagnostics::to_string(static_cast<diagnostics::Regime>(i)) == name) return static_cast<diagnostics::Regime>(i);
  return diagnostics::Regime::unknown;
}

}  // namespace

CaseParameters CaseParameters::of(const config::CaseConfig& c) {
  return {c.capillary_number, c.aspect_ratio, c.law,           c.skalak_C, c.level, c.bending_modulus,
          c.viscosity_ratio,  c.tilt,         c.azimuth};
}

std::string parameter_mismatch(const CaseParameters& reported, const CaseParameters& expected) {
  auto near = [](double a, double b) { return std::fabs(a - b) <= 1e-9 * std::max(1.0, std::fabs(b)); };
  auto text = [](double v) { return nlohmann::json(v).dump(); };
  if (!near(reported.capillary_number, expected.capillary_number))
    return "capillary_number " + text(reported.capillary_number);
  if (!near(reported.aspect_ratio, expected.aspect_ratio)) return "aspect_ratio " + text(reported.aspect_ratio);
  if (reported.law != expected.law) return "law \"" + std::string(config::word_of(reported.law)) + "\"";
  if (expected.law == config::MembraneLawKind::Skalak && !near(reported.skalak_C, expected.skalak_C))
    return "skalak_C " + text(reported.skalak_C);
  if (reported.mesh_level != expected.mesh_level) return "mesh_level " + std::to_string(reported.mesh_level);
  if (!near(reported.bending_modulus, expected.bending_modulus))
    return "bending_modulus " + text(reported.bending_modulus);
  if (!near(reported.viscosity_ratio, expected.viscosity_ratio))
    return "viscosity_ratio " + text(reported.viscosity_ratio);
  if (!near(reported.tilt, expected.tilt)) return "tilt " + text(reported.tilt);
  if (!near(reported.azimuth, expected.azimuth)) return "azimuth " + text(reported.azimuth);
  return "";
}

CaseSummary CaseSummary::of(const config::CaseConfig& config, const CaseResult& r) {
  CaseSummary s;
  s.status = r.status;
  s.reason = r.reason;
  s.parameters = CaseParameters::of(config);
  s.analysis = r.analysis;
  s.analysis.periods.clear();  // not part of the summary
  s.converged = r.converged;
  s.volume_drift = r.volume_drift;
  s.wrinkle_final = r.wrinkle_final;
  s.wrinkle_max = r.wrinkle_max;
  s.steps = r.steps;
  s.flow_evaluations = r.flow_evaluations;
  s.dt = r.dt;
  s.t_final = r.t_final;
  s.wall_s = r.wall_s;
  s.membrane_s = r.membrane_s;
  s.load_s = r.load_s;
  s.stokes_s = r.stokes_s;
  s.gmres_iterations_mean = r.gmres_iterations_mean;
  s.gmres_iterations_max = r.gmres_iterations_max;
  s.final_tilt = r.final_tilt;
  s.tilt_growth_rate = r.tilt_growth_rate;
  s.tilt_growth_rate_error = r.tilt_growth_rate_error;
  s.final_spin_rate = r.final_spin_rate;
  s.threads = omp_get_max_threads();
  s.case_file = r.case_file.empty() ? std::string() : std::filesystem::absolute(r.case_file).string();
  s.code_version = kGitCommit;
  s.kernel_isa = stokes::kernel::kernel_isa();
  s.solver_version = kSolverVersion;
  return s;
}

nlohmann::json CaseSummary::to_json() const {
  nlohmann::json j = {
      {"status", status},
      {"reason", reason},
      {"capillary_number", parameters.capillary_number},
      {"Ca", parameters.capillary_number},  // the name campaign/README.md, "The worker contract" promises; capillary_number is the long one
      {"aspect_ratio", parameters.aspect_ratio},
      {"law", std::string(config::word_of(parameters.law))},
      {"skalak_C", parameters.skalak_C},
      {"mesh_level", parameters.mesh_level},
      {"bending_modulus", parameters.bending_modulus},
      {"viscosity_ratio", parameters.viscosity_ratio},
      {"tilt", parameters.tilt},
      {"azimuth", parameters.azimuth},
      {"regime", std::string(diagnostics::to_string(analysis.regime))},
      {"converged", converged},
      {"steps", steps},
      {"flow_evaluations", flow_evaluations},
      {"threads", threads},
      {"case_file", case_file},
      {"code_version", code_version},
      {"kernel_isa", kernel_isa},
      {"solver_version", solver_version},
  };
  for (const auto& f : kAnalysisFields) j[f.name] = json_number(analysis.*f.member);
  for (const auto& f : kNumberFields) j[f.name] = json_number(f.get(*this));
  return j;
}

CaseSummary CaseSummary::from_json(const nlohmann::json& j) {
  if (!j.is_object()) throw std::invalid_argument("result: not a JSON object");
  CaseSummary s;
  const auto status = j.find("status");
  if (status == j.end() || !status->is_string()) throw std::invalid_argument("result: 'status' missing or not a string");
  s.status = status->get<std::string>();
  s.reason = string_or_empty(j, "reason");
  s.parameters.capillary_number = required_number(j, "capillary_number");
  s.parameters.aspect_ratio = required_number(j, "aspect_ratio");
  const auto law = config::from_word<config::MembraneLawKind>(string_or_empty(j, "law"));
  if (!law) throw std::invalid_argument("result: 'law' missing or not a capsule.law word");
  s.parameters.law = *law;
  s.parameters.skalak_C = required_number(j, "skalak_C");
  const auto level = j.find("mesh_level");
  if (level == j.end() || !level->is_number_integer())
    throw std::invalid_argument("result: 'mesh_level' missing or not an integer");
  s.parameters.mesh_level = level->get<int>();
  if (const auto kb = j.find("bending_modulus"); kb != j.end()) {  // absent in results from before the key: 0
    if (!kb->is_number()) throw std::invalid_argument("result: 'bending_modulus' is not a number");
    s.parameters.bending_modulus = kb->get<double>();
  }
  if (const auto vr = j.find("viscosity_ratio"); vr != j.end()) {  // absent in results from before the key: 1
    if (!vr->is_number()) throw std::invalid_argument("result: 'viscosity_ratio' is not a number");
    s.parameters.viscosity_ratio = vr->get<double>();
  }
  for (auto [key, member] : {std::pair{"tilt", &CaseParameters::tilt}, std::pair{"azimuth", &CaseParameters::azimuth}})
    if (const auto v = j.find(key); v != j.end()) {  // absent in results from before the orientation keys: 0
      if (!v->is_number()) throw std::invalid_argument(std::string("result: '") + key + "' is not a number");
      s.parameters.*member = v->get<double>();
    }
  s.analysis.regime = regime_of(string_or_empty(j, "regime"));
  const auto converged = j.find("converged");
  s.converged = converged != j.end() && converged->is_boolean() && converged->get<bool>();
  s.steps = integer_or_zero(j, "steps");
  s.flow_evaluations = integer_or_zero(j, "flow_evaluations");
  s.threads = static_cast<int>(integer_or_zero(j, "threads"));
  s.case_file = string_or_empty(j, "case_file");
  s.code_version = string_or_empty(j, "code_version");
  s.kernel_isa = string_or_empty(j, "kernel_isa");  // absent in results from before it: ""
  s.solver_version = string_or_empty(j, "solver_version");
  for (const auto& f : kAnalysisFields) s.analysis.*f.member = number_or_nan(j, f.name);
  for (const auto& f : kNumberFields) f.set(s, number_or_nan(j, f.name));
  return s;
}

std::vector<io::Attribute> summary_attributes(const CaseSummary& s) {
  std::vector<io::Attribute> a;
  a.emplace_back("status", s.status);
  a.emplace_back("reason", s.reason);
  a.emplace_back("capillary_number", s.parameters.capillary_number);
  a.emplace_back("aspect_ratio", s.parameters.aspect_ratio);
  a.emplace_back("law", std::string(config::word_of(s.parameters.law)));
  a.emplace_back("skalak_C", s.parameters.skalak_C);
  a.emplace_back("mesh_level", s.parameters.mesh_level);
  a.emplace_back("bending_modulus", s.parameters.bending_modulus);
  a.emplace_back("viscosity_ratio", s.parameters.viscosity_ratio);
  a.emplace_back("tilt", s.parameters.tilt);
  a.emplace_back("azimuth", s.parameters.azimuth);
  a.emplace_back("regime", std::string(diagnostics::to_string(s.analysis.regime)));
  a.emplace_back("converged", s.converged ? 1 : 0);
  a.emplace_back("steps", s.steps);
  a.emplace_back("flow_evaluations", s.flow_evaluations);
  a.emplace_back("threads", s.threads);
  a.emplace_back("solver_version", s.solver_version);
  a.emplace_back("kernel_isa", s.kernel_isa);
  // code_version is the case file's own reserved attribute (written by io::CaseWriter, same value).
  for (const auto& f : kAnalysisFields) a.emplace_back(f.name, s.analysis.*f.member);
  for (const auto& f : kNumberFields) a.emplace_back(f.name, f.get(s));
  return a;
}

}  // namespace capsim::driver
