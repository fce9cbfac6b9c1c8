// Whole cases started off the shear plane (label `validation`; about a minute each, level 2): the symmetry of a
// capsule started along the vorticity axis, and the rigid-spheroid limit of a stiff capsule started off the plane,
// whose axis must follow a Jeffery orbit (solver/README.md, Orientation; results/validation/README.md,
// "Orientation").
#include "solver/driver/case_driver.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "solver/diagnostics/period_analysis.h"
#include "solver/io/case_file.h"

namespace capsim::driver {
namespace {

namespace fs = std::filesystem;
constexpr double kDeg = std::numbers::pi / 180.0;

diagnostics::TimeSeries run(const config::CaseConfig& c, const std::string& name, CaseResult& r) {
  RunOptions o;
  o.out_dir = fs::path(CAPSIM_TEST_TMP) / "validation" / name;
  fs::remove_all(o.out_dir);
  r = run_case(c, o);
  std::printf("%s: status %s, regime %s, final_tilt %.6f deg, %ld steps, %ld evaluations, wall %.1f s\n",
              name.c_str(), r.status.c_str(), std::string(diagnostics::to_string(r.analysis.regime)).c_str(),
              r.final_tilt, r.steps, r.flow_evaluations, r.wall_s);
  return io::read_case_file(o.out_dir / "case.h5").series;
}

// A capsule whose axis starts along the vorticity x3 (tilt 90) keeps it there: the scene is invariant under the
// half-turn about x3 (the product of x → −x and x3 → −x3, both symmetries of the flow and of the spheroid), which
// fixes the two poles' positions on the x3 axis. Neither symmetry is imposed here (numerics.central_symmetry off,
// and the tilted mesh has no mirror map), and the discrete scene keeps the half-turn bitwise (it is the half-turn
// about the unrotated axis x1, a symmetry of the construction), so the axis may leave x3 only by round-off of the
// sums. Ca = 0.1 deforms the capsule (it rolls, tank-treading about x3, and D12 in the plane moves), so the test is
// not one of a rigid body. Measured (level 2, to γ̇t = 4, 200 steps): the tilt stays within 4.3e-14° of 90 while D12 moves
// by 0.25 (results/validation/README.md, "Orientation"); asserted: 1e-9°, far above that round-off, far below any
// dynamics (a drift driven by a broken symmetry would be O(1°) per time unit at this Ca).
TEST(Orientation, AxisAlongTheVorticityStaysThere) {
  config::CaseConfig c;
  c.aspect_ratio = 2.0;
  c.capillary_number = 0.1;
  c.level = 2;
  c.t_end = 4.0;
  c.tilt = 90.0;
  CaseResult r;
  const auto s = run(c, "tilt90_ca0.1", r);
  ASSERT_EQ(r.status, "done") << r.reason;
  ASSERT_GT(s.size(), 10u);
  double worst = 0.0, worst_d12 = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    worst = std::max(worst, 90.0 - s.axis_tilt[i]);
    worst_d12 = std::max(worst_d12, std::abs(s.D12[i] - s.D12[0]));
  }
  std::printf("tilt 90: largest departure of the axis from x3 %.3e deg over %zu samples; D12 moved by %.4f\n", worst,
              s.size(), worst_d12);
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(worst_d12, 0.01) << "the capsule deforms (not a rigid-body test)";
  EXPECT_NEAR(r.final_tilt, 90.0, 1e-9);
}

// Jeffery (1922): a rigid spheroid of aspect ratio r in the shear v = (x2, 0, 0), axis p = (sin θ cos φ, sin θ sin φ,
// cos θ) with θ its angle from the vorticity axis x3 and φ the angle of its projection from the flow direction x1,
// turns as dφ/dt = −(r² sin²φ + cos²φ)/(r² + 1) and dθ/dt = (r² − 1)/(r² + 1) · sinθ cosθ sinφ cosφ
// (from dp/dt = W p + B (E p − (p·E p) p), B = (r² − 1)/(r² + 1)). Dividing one by the other and integrating:
//     tan θ · sqrt(r² sin²φ + cos²φ) = C r
// (the orbit constant C; with φ measured from the gradient direction x2 instead, the familiar
// tan θ = C r / sqrt(r² cos²φ + sin²φ)), and the axis returns after φ has turned by 2π, T = 2π (r + 1/r) (the line
// and the shape after T/2). In the diagnostics θ = 90° − axis_tilt and φ = axis_azimuth (squared sines and cosines
// do not see its folding), so C = sqrt(r² sin²φ + cos²φ) / (r tan(axis_tilt)).
// A capsule is a rigid spheroid only as Ca → 0. At finite Ca it drifts across the orbits: C falls steadily, the
// axis moving toward the vorticity axis (Dupont et al. 2013 find prolate capsules end rolling at low Ca), by a
// change d(Ca) over the first period that is first order in Ca, as the period's excess over Jeffery's is
// (viscosity_ratio_validation.cc). Measured (λ = 1, Skalak, a/b = 2, level 2, started at tilt 30° in the flow
// direction, numerics.central_symmetry; results/validation/README.md, "Orientation"): d = −23.6 %, −13.9 %,
// −7.35 %, −3.77 % at Ca = 0.01, 0.005, 0.0025, 0.00125 (ratios 1.69, 1.89, 1.95 → 2), and the Richardson
// extrapolants 2 d(Ca/2) − d(Ca), −4.3 %, −0.78 %, −0.19 %, fall about fourfold per halving: the drift is
// d = c1 Ca + c2 Ca² with no Ca⁰ term (a least-squares fit gives c0 = +0.2 %), so the level-2 spheroid keeps
// Jeffery's orbit constant as Ca → 0 (the −4.3 % of the first pair is the Ca² term, not a residual of the mesh).
// The periods, 15.7919, 15.7323, 15.7116, 15.70797 against Jeffery's 15.70796, converge to his as well (the last
// is within 3e-7: the level-2 mesh's own error of the period is below the O(Ca²) excess of Ca = 0.0025).
// Asserted: each ratio in [1.5, 2.5] (first order), each extrapolant at most half the previous one and the last
// within 1 % (a drift that does not vanish with Ca would leave the extrapolants at a constant), each period within
// 1 % of Jeffery's, decreasing with Ca, the largest above his (a deformable capsule turns more slowly) and the
// smallest within 0.1 % of it. A stiffer
// interior does not remove the drift: at λ = 10 and Ca = 0.01 C changes by about −15 % over the period (measured
// once, not asserted: GMRES makes it twice as slow).
struct OrbitMeasure {
  double period = 0, c0 = 0, drift = 0, worst = 0;
};

OrbitMeasure jeffery_run(double Ca, double r_ax) {
  config::CaseConfig c;
  c.aspect_ratio = r_ax;
  c.capillary_number = Ca;
  c.level = 2;
  c.t_end = 17.0;
  c.tilt = 30.0;
  c.central_symmetry = true;  // holds for any orientation: half the cost, the same answer to round-off
  CaseResult r;
  const auto s = run(c, "jeffery_tilt30_ca" + std::to_string(Ca), r);
  EXPECT_EQ(r.status, "done") << r.reason;
  const auto orbit_constant = [&](std::size_t i) {
    const double phi = s.axis_azimuth[i] * kDeg, tau = s.axis_tilt[i] * kDeg;
    return std::sqrt(r_ax * r_ax * std::sin(phi) * std::sin(phi) + std::cos(phi) * std::cos(phi)) /
           (r_ax * std::tan(tau));
  };
  OrbitMeasure m;
  m.c0 = orbit_constant(0);
  // The period: the unwrapped azimuth turning by 360° (it decreases: the vorticity is −e3).
  std::vector<double> phi(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) phi[i] = s.axis_azimuth[i] * kDeg;
  const std::vector<double> phi_u = diagnostics::unwrap_axis_angle(phi);
  std::size_t end = 0;
  m.period = std::nan("");
  for (std::size_t i = 1; i < s.size(); ++i)
    if (phi_u[i] <= phi_u[0] - 2.0 * std::numbers::pi) {
      const double w = (phi_u[0] - 2.0 * std::numbers::pi - phi_u[i - 1]) / (phi_u[i] - phi_u[i - 1]);
      m.period = s.t[i - 1] + w * (s.t[i] - s.t[i - 1]);
      m.drift = (orbit_constant(i - 1) + w * (orbit_constant(i) - orbit_constant(i - 1))) / m.c0 - 1.0;
      end = i;
      break;
    }
  for (std::size_t i = 0; i < end; ++i) m.worst = std::max(m.worst, std::abs(orbit_constant(i) / m.c0 - 1.0));
  std::printf("Ca %.4f: C0 %.6f, C(T)/C0 - 1 = %+.4f, largest |C/C0 - 1| over the period %.4f; period %.4f\n", Ca,
              m.c0, m.drift, m.worst, m.period);
  return m;
}

TEST(Orientation, StiffCapsuleOffThePlaneFollowsAJefferyOrbitAsCaVanishes) {
  const double r_ax = 2.0;
  const double jeffery = 2.0 * std::numbers::pi * (r_ax + 1.0 / r_ax);
  const std::vector<double> cas = {0.01, 0.005, 0.0025, 0.00125};
  std::vector<OrbitMeasure> m;
  for (const double ca : cas) m.push_back(jeffery_run(ca, r_ax));
  EXPECT_NEAR(m[0].c0, 1.0 / (2.0 * std::tan(30.0 * kDeg)), 1e-12) << "C of the start, tilt 30° at azimuth 0";
  for (const auto& x : m)
    ASSERT_TRUE(std::isfinite(x.period)) << "the axis did not turn by 360° before t_end";
  double previous_extrapolant = 0;
  for (std::size_t k = 0; k + 1 < m.size(); ++k) {
    const double ratio = m[k].drift / m[k + 1].drift, extrapolant = 2.0 * m[k + 1].drift - m[k].drift;
    std::printf("Jeffery: Ca %.5f / %.5f: drift ratio %.3f, extrapolated change of C over a period %+.4f\n", cas[k],
                cas[k + 1], ratio, extrapolant);
    EXPECT_GT(ratio, 1.5);
    EXPECT_LT(ratio, 2.5);
    if (k > 0) EXPECT_LT(std::abs(extrapolant), 0.5 * std::abs(previous_extrapolant)) << "the drift has a Ca⁰ part";
    previous_extrapolant = extrapolant;
  }
  EXPECT_LT(std::abs(previous_extrapolant), 0.01);
  EXPECT_GT(m.front().period, jeffery) << "a deformable capsule turns more slowly than the rigid spheroid";
  EXPECT_NEAR(m.back().period / jeffery, 1.0, 1e-3) << "as Ca → 0 the period tends to Jeffery's";
  for (std::size_t k = 0; k < m.size(); ++k) {
    std::printf("Jeffery: Ca %.5f: period %.4f (Jeffery %.4f)\n", cas[k], m[k].period, jeffery);
    EXPECT_NEAR(m[k].period / jeffery, 1.0, 0.01);
    if (k > 0) EXPECT_LT(m[k].period, m[k - 1].period) << "the period's excess over Jeffery's must shrink with Ca";
  }
}

}  // namespace
}  // namespace capsim::driver
