// A real run of an initially spherical capsule: it reaches a steady, tank-treading shape and
// the analysis must say so (regime `steady`, finite D12, θ and τmin statistics) when the run ends, even
// where the wrinkles keep the shape from settling enough to stop it early.
#include <cmath>
#include <filesystem>
#include <numbers>

#include <gtest/gtest.h>

#include "solver/driver/case_driver.h"

namespace capsim::driver {
namespace {

namespace fs = std::filesystem;

// Neo-Hookean sphere, Ca = 0.3 (Ca = μγ̇ℓ/Gs), level 2, to at most γ̇t = 12 (about ten seconds on one core).
//
// Reference D12. Small-deformation theory (Barthès-Biesel & Rallison 1981) gives D12 = 25/4 · μγ̇a/Es with
// Es = 3 Gs, i.e. 25/12 Ca = 0.625 here: it holds for Ca ≲ 0.05 only and over-predicts at Ca = 0.3, where
// the deformation saturates, so it is an upper bound and not the reference. The reference is the published
// boundary-integral value for this case, D12 ≈ 0.40 (Lac et al. 2004, neo-Hookean sphere in simple shear,
// λ = 1; Walter et al. 2010 reproduce it), read from their curves D12(Ca): ±0.01 reading accuracy. The
// tolerance 0.03 adds the level-2 mesh error (a few 1e-4 on a sphere, results/benchmarks.md) and the
// wrinkle-induced creep of a membrane without bending stiffness on a coarse mesh (≈ 1e-3 per few time
// units), with a factor of two to spare; it is far tighter than the distance to the linear theory (0.2).
// The inclination of a tank-treading sphere lies between 45° (Ca → 0) and the flow direction, and
// decreases with Ca: at Ca = 0.3 it is ≈ 20–30° in the same studies; we bound it to (10°, 45°).
TEST(SteadySphere, NeoHookeanAtCa03IsReportedSteadyWithThePublishedD12) {
  config::CaseConfig c;
  c.aspect_ratio = 1.0;
  c.law = config::MembraneLawKind::NeoHookean;
  c.capillary_number = 0.3;
  c.level = 2;
  c.t_end = 12.0;
  const fs::path dir = fs::path(CAPSIM_TEST_TMP) / "diagnostics" / "steady_sphere";
  fs::remove_all(dir);
  fs::create_directories(dir);
  RunOptions o;
  o.out_dir = dir;
  const CaseResult r = run_case(c, o);
  ASSERT_EQ(r.status, "done") << r.reason;
  const auto& a = r.analysis;
  ASSERT_EQ(a.regime, diagnostics::Regime::steady) << "t_final = " << r.t_final;
  EXPECT_EQ(a.period, 0.0);
  EXPECT_LT(a.mean_D12, 25.0 / 12.0 * c.capillary_number);
  EXPECT_NEAR(a.mean_D12, 0.40, 0.03);
  EXPECT_NEAR(a.min_D12, a.mean_D12, c.period_tolerance);
  const double theta_deg = a.theta_mean * 180.0 / std::numbers::pi;
  EXPECT_GT(theta_deg, 10.0);
  EXPECT_LT(theta_deg, 45.0);
  // τmin statistics over the steady window are reported, never NaN, and ordered.
  ASSERT_TRUE(std::isfinite(a.max_tau_min) && std::isfinite(a.min_tau_min) && std::isfinite(a.mean_tau_min));
  EXPECT_LE(a.min_tau_min, a.mean_tau_min);
  EXPECT_LE(a.mean_tau_min, a.max_tau_min);
  EXPECT_DOUBLE_EQ(a.tau_min_spread, a.max_tau_min - a.min_tau_min);
  std::printf("steady sphere NH Ca 0.3 L2: t_final %.2f D12 %.5f (min %.5f) theta %.2f deg tau_min mean %.4f "
              "[%.4f, %.4f]\n",
              r.t_final, a.mean_D12, a.min_D12, theta_deg, a.mean_tau_min, a.min_tau_min, a.max_tau_min);
}

}  // namespace
}  // namespace capsim::driver
