// Long physics checks of whole cases (label `validation`; minutes each): the seed's figure-2 regimes and
// the volume drift bound, on the level-2 mesh.
#include "solver/driver/case_driver.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>

#include "solver/io/case_file.h"

namespace capsim::driver {
namespace {

namespace fs = std::filesystem;

CaseResult run_figure2(double Ca, const std::string& law, const std::string& name) {
  config::CaseConfig c;
  c.aspect_ratio = 2.0;
  c.law = config::from_word<config::MembraneLawKind>(law).value();
  c.skalak_C = 1.0;
  c.capillary_number = Ca;
  c.level = 2;
  c.t_end = 40.0;
  RunOptions o;
  o.out_dir = fs::path(CAPSIM_TEST_TMP) / "validation" / name;
  fs::remove_all(o.out_dir);
  const CaseResult r = run_case(c, o);
  std::printf("%s: status %s, regime %s, period %.3f, min_D12 %.4f, max_tau_min %+.4f, volume drift %.2e, %ld steps\n",
              name.c_str(), r.status.c_str(), std::string(diagnostics::to_string(r.analysis.regime)).c_str(),
              r.analysis.period, r.analysis.min_D12, r.analysis.max_tau_min, r.volume_drift, r.steps);
  return r;
}

// Seed figure 2(a): a/b = 2, Skalak C = 1. Ca = 0.1 tumbles, Ca = 0.9 swings; both start at D12 = 1/3.
TEST(Figure2, ProlateSkalakTumblesAtCa01AndSwingsAtCa09) {
  const CaseResult tumbling = run_figure2(0.1, "skalak", "fig2_ca0.1");
  ASSERT_EQ(tumbling.status, "done") << tumbling.reason;
  EXPECT_EQ(tumbling.analysis.regime, diagnostics::Regime::tumbling);
  // A quasi-rigid tumbling ellipsoid turns its shape by π in π(r + 1/r) = 7.85 (Jeffery); a deformable one
  // is slower but of that order.
  EXPECT_GT(tumbling.analysis.period, 7.0);
  EXPECT_LT(tumbling.analysis.period, 12.0);

  const CaseResult swinging = run_figure2(0.9, "skalak", "fig2_ca0.9");
  ASSERT_EQ(swinging.status, "done") << swinging.reason;
  EXPECT_EQ(swinging.analysis.regime, diagnostics::Regime::swinging);
  EXPECT_GT(swinging.analysis.mean_D12, tumbling.analysis.mean_D12) << "swinging capsules are more elongated";
  for (const char* name : {"fig2_ca0.1", "fig2_ca0.9"}) {
    const auto s = io::read_case_file(fs::path(CAPSIM_TEST_TMP) / "validation" / name / "case.h5").series;
    EXPECT_NEAR(s.D12.front(), 1.0 / 3.0, 1e-3);
  }
}

// Volume is conserved by the continuous problem. Without the flux correction the level-2 mesh loses
// 3.6–3.8% over γ̇t = 60 (Skalak, a/b = 2, Ca = 0.1 and 0.9); with it (the default) the stated bound is
// 1e-3 over γ̇t = 40 for both laws (measured: ≤ 4e-5 in the quick Table 1 campaign).
TEST(VolumeDrift, BoundedForBothLaws) {
  for (const char* law : {"neo-hookean", "skalak"}) {
    const CaseResult r = run_figure2(0.3, law, std::string("drift_") + law);
    ASSERT_NE(r.status, "unstable") << r.reason;
    EXPECT_LT(std::abs(r.volume_drift), 1e-3) << law;
  }
}

}  // namespace
}  // namespace capsim::driver
