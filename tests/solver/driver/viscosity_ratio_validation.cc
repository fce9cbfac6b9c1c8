// Whole cases at a viscosity ratio λ ≠ 1 (label `validation`; seconds to minutes each, level 2): the small-deformation
// limit of a sphere, whose D12 and inclination do not depend on λ at first order in Ca, and the rigid-spheroid
// limit of a large λ as Ca → 0, whose shape turns with Jeffery's period.
#include "solver/driver/case_driver.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "solver/io/case_file.h"

namespace capsim::driver {
namespace {

namespace fs = std::filesystem;

CaseResult run(config::CaseConfig c, const std::string& name) {
  RunOptions o;
  o.out_dir = fs::path(CAPSIM_TEST_TMP) / "validation" / name;
  fs::remove_all(o.out_dir);
  const CaseResult r = run_case(c, o);
  std::printf("%s: status %s, regime %s, mean_D12 %.5f (min %.5f), period %.3f, theta %.2f deg, %ld steps, %ld "
              "evaluations, GMRES mean %.2f max %d, wall %.1f s\n",
              name.c_str(), r.status.c_str(), std::string(diagnostics::to_string(r.analysis.regime)).c_str(),
              r.analysis.mean_D12, r.analysis.min_D12, r.analysis.period,
              r.analysis.theta_mean * 180.0 / std::numbers::pi, r.steps, r.flow_evaluations, r.gmres_iterations_mean,
              r.gmres_iterations_max, r.wall_s);
  return r;
}

// Small deformation of an initially spherical neo-Hookean capsule (Barthès-Biesel & Sgaier 1985): D12 = 25/12 Ca
// and θ = π/4 at first order in Ca, for every λ; the interior viscosity enters at second order and in the time to
// reach the deformed shape, which grows like (1 + λ)/2. As the λ = 1 test (case_driver_test.cc,
// SphereMatchesSmallDeformationTheory): Ca = 0.01, level 2, the plateau of one time unit after the deformed shape
// is reached (γ̇t ≥ 0.5 · max(1, (1 + λ)/2); later the compressed membrane wrinkles slowly) is compared. D12 within 2%
// (the λ = 1 test holds 1%; at λ ≠ 1 a second-order term of relative size O(Ca) is added); θ in (40°, 45°] (its
// first correction is O(Ca) with a λ-dependent coefficient: 44.2° at λ = 0.2, 41.8° at λ = 5).
TEST(ViscosityRatioSphere, SmallDeformationLimitDoesNotDependOnLambda) {
  const double Ca = 0.01;
  const double theory = 25.0 / 12.0 * Ca;
  for (const double lambda : {0.2, 5.0}) {
    config::CaseConfig c;
    c.aspect_ratio = 1.0;
    c.law = config::MembraneLawKind::NeoHookean;
    c.capillary_number = Ca;
    c.level = 2;
    const double t0 = 0.5 * std::max(1.0, (1.0 + lambda) / 2.0);
    c.t_end = t0 + 0.5;
    c.viscosity_ratio = lambda;
    const std::string name = "sphere_lambda_" + std::to_string(lambda);
    const CaseResult r = run(c, name);
    ASSERT_EQ(r.status, "done") << r.reason;
    EXPECT_GT(r.gmres_iterations_mean, 0.0);
    const auto series = io::read_case_file(fs::path(CAPSIM_TEST_TMP) / "validation" / name / "case.h5").series;
    int checked = 0;
    for (std::size_t i = 0; i < series.size(); ++i) {
      if (series.t[i] < t0) continue;
      EXPECT_NEAR(series.D12[i], theory, 0.02 * theory) << "λ " << lambda << " t = " << series.t[i];
      const double theta_deg = series.theta[i] * 180.0 / std::numbers::pi;
      EXPECT_GT(theta_deg, 40.0) << "λ " << lambda;
      EXPECT_LE(theta_deg, 45.0) << "λ " << lambda;
      ++checked;
    }
    EXPECT_GT(checked, 5) << "λ " << lambda;
  }
}

// The rigid-spheroid limit at a large λ. An a/b = 2 prolate capsule (Skalak) with λ = 10 tumbles; its shape (D12)
// repeats every half period, which for a rigid spheroid is Jeffery's π(r + 1/r) = 7.854 (r = 2). The capsule is rigid
// only as Ca → 0: at finite Ca it deforms while it turns (D12 swings between 0.27 and 0.39 at Ca = 0.05, λ = 10 or
// 20: the deformation is set by the balance of the outer flow's strain and the membrane's elasticity, both resisted
// by the interior fluid, so λ cancels from its size while the membrane relaxes faster than the capsule turns), and
// the period is longer. Measured on level 2 (results/validation/README.md, "Viscosity ratio", "Rigid limit"):
// 8.244, 8.059 and 7.955 at Ca = 0.05, 0.025 and 0.0125, an excess over Jeffery's that halves with Ca (0.390,
// 0.205, 0.101): first order in Ca, and its Richardson extrapolation 2 P(Ca/2) − P(Ca) → 7.851, 0.04 % from
// Jeffery's. Asserted: tumbling at Ca = 0.025 and 0.0125, the excess halving (ratio in [1.6, 2.4]), and the
// extrapolated period within 1 % of Jeffery's.
TEST(ViscosityRatioSpheroid, LargeLambdaTumblesWithJefferysPeriodAsCaVanishes) {
  const double jeffery = std::numbers::pi * (2.0 + 1.0 / 2.0);
  double period[2] = {0.0, 0.0};
  const double cas[2] = {0.025, 0.0125};
  for (int k = 0; k < 2; ++k) {
    config::CaseConfig c;
    c.aspect_ratio = 2.0;
    c.law = config::MembraneLawKind::Skalak;
    c.capillary_number = cas[k];
    c.level = 2;
    c.t_end = 30.0;
    c.viscosity_ratio = 10.0;
    const CaseResult r = run(c, "jeffery_lambda10_ca" + std::to_string(cas[k]));
    ASSERT_EQ(r.status, "done") << r.reason;
    EXPECT_EQ(r.analysis.regime, diagnostics::Regime::tumbling) << "Ca " << cas[k];
    period[k] = r.analysis.period;
  }
  const double excess_ratio = (period[0] - jeffery) / (period[1] - jeffery);
  EXPECT_GT(excess_ratio, 1.6) << period[0] << " " << period[1];
  EXPECT_LT(excess_ratio, 2.4) << period[0] << " " << period[1];
  const double extrapolated = 2.0 * period[1] - period[0];
  EXPECT_NEAR(extrapolated / jeffery, 1.0, 0.01) << "periods " << period[0] << ", " << period[1];
}

}  // namespace
}  // namespace capsim::driver
