// The case summary: one serialisation for the JSON line, the case file's attributes and the readers.
#include "solver/driver/case_summary.h"

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "solver/driver/case_driver.h"
#include "solver/io/case_file.h"
#include "solver/stokes/stokeslet.h"

namespace capsim::driver {
namespace {

CaseSummary example() {
  CaseSummary s;
  s.status = "unstable";
  s.reason = "volume changed by 5% at t = 3";
  s.parameters = {0.3, 2.0, config::MembraneLawKind::Skalak, 1.5, 2};
  s.analysis.regime = diagnostics::Regime::swinging;
  s.analysis.min_D12 = 0.21;
  s.analysis.max_tau_min = -0.04;
  s.analysis.mean_D12 = 0.3;  // period stays NaN: no complete period
  s.converged = false;
  s.volume_drift = -1e-4;
  s.wrinkle_final = {0.1, 0.2, 0.5, 1e-3};
  s.wrinkle_max = {0.3, 0.4, 0.7, 2e-3};
  s.steps = 1234;
  s.flow_evaluations = 5678;
  s.dt = 0.02;
  s.t_final = 24.68;
  s.wall_s = 9.5;
  s.threads = 2;
  s.case_file = "/tmp/x/case.h5";
  s.code_version = "abc";
  s.solver_version = "2";
  s.kernel_isa = "avx2";
  s.final_tilt = 12.5;
  s.tilt_growth_rate = -0.02;
  s.tilt_growth_rate_error = 0.003;
  s.final_spin_rate = -0.46;
  s.parameters.tilt = 3.0;
  s.parameters.azimuth = -30.0;
  return s;
}

TEST(CaseSummary, JsonRoundTripKeepsEveryField) {
  const CaseSummary s = example();
  const nlohmann::json j = s.to_json();
  EXPECT_TRUE(j["period"].is_null()) << "NaN is null in JSON";
  EXPECT_EQ(j["Ca"], j["capillary_number"]);
  const CaseSummary t = CaseSummary::from_json(nlohmann::json::parse(j.dump()));
  EXPECT_EQ(t.to_json(), j);
  EXPECT_TRUE(std::isnan(t.analysis.period));
  EXPECT_EQ(t.analysis.regime, diagnostics::Regime::swinging);
  EXPECT_EQ(t.steps, 1234);
  EXPECT_EQ(t.wrinkle_max.load_roughness, 0.4);
  EXPECT_EQ(t.wrinkle_final.wrinkle_wavelength, 0.5);
  EXPECT_EQ(t.wrinkle_final.wrinkle_amplitude, 1e-3);
  EXPECT_EQ(t.wrinkle_max.wrinkle_wavelength, 0.7);
  EXPECT_EQ(t.wrinkle_max.wrinkle_amplitude, 2e-3);
  EXPECT_EQ(t.kernel_isa, "avx2");
  EXPECT_EQ(t.final_tilt, 12.5);
  EXPECT_EQ(t.tilt_growth_rate, -0.02);
  EXPECT_EQ(t.tilt_growth_rate_error, 0.003);
  EXPECT_EQ(t.final_spin_rate, -0.46);
  EXPECT_EQ(t.parameters.tilt, 3.0);
  EXPECT_EQ(t.parameters.azimuth, -30.0);
}

// A result from before the orientation keys reads as the in-plane start (tilt 0, azimuth 0), with no growth rate; the
// regimes off the plane read back by their names.
TEST(CaseSummary, OrientationFieldsReadBackAndDefault) {
  nlohmann::json j = example().to_json();
  for (const char* key : {"tilt", "azimuth", "tilt_growth_rate", "tilt_growth_rate_error"}) j.erase(key);
  const CaseSummary t = CaseSummary::from_json(j);
  EXPECT_EQ(t.parameters.tilt, 0.0);
  EXPECT_EQ(t.parameters.azimuth, 0.0);
  EXPECT_TRUE(std::isnan(t.tilt_growth_rate));
  j["tilt"] = "five";
  EXPECT_THROW(CaseSummary::from_json(j), std::invalid_argument);
  for (const auto regime : {diagnostics::Regime::rolling, diagnostics::Regime::wobbling, diagnostics::Regime::kayaking,
                            diagnostics::Regime::oscillating_swinging}) {
    CaseSummary s = example();
    s.analysis.regime = regime;
    EXPECT_EQ(CaseSummary::from_json(s.to_json()).analysis.regime, regime) << diagnostics::to_string(regime);
  }
}

// A result line from before kernel_isa existed still reads (the committed databases hold thousands).
TEST(CaseSummary, FromJsonReadsAResultWithoutTheKernelIsa) {
  nlohmann::json j = example().to_json();
  j.erase("kernel_isa");
  EXPECT_EQ(CaseSummary::from_json(j).kernel_isa, "");
}

// The summary of a run names the instruction set of the kernel that computed it, the one the build reports.
TEST(CaseSummary, OfARunNamesTheKernelsInstructionSet) {
  config::CaseConfig c;
  CaseResult r;
  const CaseSummary s = CaseSummary::of(c, r);
  EXPECT_EQ(s.kernel_isa, stokes::kernel::kernel_isa());
  EXPECT_FALSE(s.kernel_isa.empty());  // the names themselves belong to solver/stokes/stokeslet.cc
}

// The keys campaign/README.md, "The worker contract" and the scripts rely on.
TEST(CaseSummary, JsonHasTheContractKeys) {
  const nlohmann::json j = example().to_json();
  for (const char* key : {"status", "reason", "Ca", "capillary_number", "aspect_ratio", "law", "skalak_C",
                          "mesh_level", "min_D12", "max_tau_min", "mean_D12", "period", "regime", "converged",
                          "volume_drift", "compressed_area_fraction", "load_roughness", "max_compressed_area_fraction",
                          "max_load_roughness", "wrinkle_wavelength", "wrinkle_amplitude", "max_wrinkle_amplitude",
                          "wrinkle_wavelength_of_max", "steps", "flow_evaluations", "dt", "t_final",
                          "wall_s", "threads",
                          "case_file", "code_version", "kernel_isa", "solver_version", "tilt", "azimuth",
                          "final_tilt", "tilt_growth_rate", "tilt_growth_rate_error", "final_spin_rate"})
    EXPECT_TRUE(j.contains(key)) << key;
}

TEST(CaseSummary, FromJsonRejectsAResultWithoutItsParameters) {
  nlohmann::json j = example().to_json();
  j.erase("skalak_C");
  EXPECT_THROW(CaseSummary::from_json(j), std::invalid_argument);
  EXPECT_THROW(CaseSummary::from_json(nlohmann::json::array()), std::invalid_argument);
}

// Defect 7: every parameter is compared, skalak_C too (only for the Skalak law, as the case identity).
TEST(CaseSummary, ParameterMismatchComparesEveryParameter) {
  const CaseParameters p{0.3, 2.0, config::MembraneLawKind::Skalak, 1.0, 2};
  EXPECT_EQ(parameter_mismatch(p, p), "");
  CaseParameters q = p;
  q.skalak_C = 2.0;
  EXPECT_EQ(parameter_mismatch(q, p), "skalak_C 2.0");
  q = p;
  q.capillary_number = 0.3 * (1 + 1e-12);  // decimal round trip noise
  EXPECT_EQ(parameter_mismatch(q, p), "");
  q.mesh_level = 3;
  EXPECT_EQ(parameter_mismatch(q, p), "mesh_level 3");
  CaseParameters nh{0.3, 2.0, config::MembraneLawKind::NeoHookean, 1.0, 2}, nh2 = nh;
  nh2.skalak_C = 7.0;
  EXPECT_EQ(parameter_mismatch(nh2, nh), "") << "skalak_C does not enter a neo-Hookean case";
  nh2.law = config::MembraneLawKind::Skalak;
  EXPECT_NE(parameter_mismatch(nh2, nh), "");
  // The initial orientation is a parameter of the case like the others.
  q = p;
  q.tilt = 5.0;
  EXPECT_EQ(parameter_mismatch(p, q), "tilt 0.0");
  q = p;
  q.azimuth = 30.0;
  EXPECT_EQ(parameter_mismatch(q, p), "azimuth 30.0");
}

// What run_case stores as case.h5's attributes is the summary (with the case file's own code_version).
TEST(CaseSummary, CaseFileAttributesAreTheSummary) {
  config::CaseConfig c;
  c.level = 1;
  c.t_end = 0.1;
  const auto dir = std::filesystem::path(CAPSIM_TEST_TMP) / "driver" / "summary_attributes";
  std::filesystem::remove_all(dir);
  RunOptions o;
  o.out_dir = dir;
  const CaseResult r = run_case(c, o);
  const CaseSummary s = CaseSummary::of(c, r);
  const auto contents = io::read_case_file(r.case_file);
  auto find = [&](const std::string& key) -> const io::Attribute* {
    for (const auto& a : contents.attributes)
      if (a.key == key) return &a;
    return nullptr;
  };
  for (const auto& expected : summary_attributes(s)) {
    const io::Attribute* a = find(expected.key);
    ASSERT_NE(a, nullptr) << expected.key;
    if (expected.key == "wall_s") continue;  // stored just before the file is closed
    if (const double* v = std::get_if<double>(&expected.value); v && std::isnan(*v))
      EXPECT_TRUE(std::isnan(std::get<double>(a->value))) << expected.key;
    else
      EXPECT_EQ(a->value, expected.value) << expected.key;
  }
  EXPECT_NE(find("code_version"), nullptr);
  EXPECT_EQ(std::get<std::int64_t>(find("flow_evaluations")->value), r.flow_evaluations);
}

}  // namespace
}  // namespace capsim::driver
