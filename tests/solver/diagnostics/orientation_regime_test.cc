// The regimes in any orientation and the tilt's growth rate (solver/README.md §5, "Regimes in any orientation"), on
// synthetic time series with known answers: the in-plane projection (D12, θ) of a tumbling, swinging or steady shape
// and a prescribed tilt of the material axis.
#include "solver/diagnostics/orientation_regime.h"

#include <cmath>
#include <functional>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

namespace capsim::diagnostics {
namespace {

constexpr double kPi = std::numbers::pi;

double wrap_axis(double a) {
  double w = std::remainder(a, kPi);
  if (w <= -kPi / 2) w += kPi;
  return w;
}

// The in-plane projection's motion.
struct Projection {
  double D12, theta;
};
// Tumbling: a quasi-rigid Jeffery rotation of an r = 2 ellipse (shape period π (r + 1/r) ≈ 7.85), squeezed once per turn.
Projection tumbling(double t) {
  const double r = 2.0, psi = t * r / (r * r + 1.0);
  const double phi = std::atan2(-std::sin(psi), r * std::cos(psi)) - 2 * kPi * std::floor((psi + kPi) / (2 * kPi));
  return {1.0 / 3.0 + 0.05 * std::sin(2 * phi), wrap_axis(phi)};
}
constexpr double kSwingPeriod = 6.5;
Projection swinging(double t) {
  const double w = 2 * kPi / kSwingPeriod;
  return {0.3 + 0.08 * std::cos(w * t + 1.0), 0.3 + 0.15 * std::sin(w * t)};
}
Projection steady(double) { return {0.2, 0.4}; }

TimeSeries series(double t_end, const std::function<Projection(double)>& shape,
                  const std::function<double(double)>& tilt, double dt = 0.01) {
  TimeSeries s;
  for (int i = 0; i * dt <= t_end + 1e-12; ++i) {
    StepRecord r;
    r.t = i * dt;
    const Projection p = shape(r.t);
    r.D12 = p.D12;
    r.theta = p.theta;
    r.tau_min = 0.01;
    r.axis_tilt = tilt(r.t);
    s.push_back(r);
  }
  return s;
}

Regime classify(const TimeSeries& s) { return classify_regime(s, analyse_periods(s)); }

// With the axis in the plane (tilt 0 exactly, every seed case) the answer is the in-plane classifier's own, and so is
// every number of the analysis: the orientation adds nothing there.
TEST(OrientationRegime, InThePlaneTheInPlaneAnswerStands) {
  for (const auto& [shape, expected] : {std::pair{&tumbling, Regime::tumbling}, std::pair{&swinging, Regime::swinging},
                                        std::pair{&steady, Regime::steady}}) {
    const TimeSeries s = series(40.0, shape, [](double) { return 0.0; });
    const PeriodAnalysis a = analyse_periods(s);
    ASSERT_EQ(a.regime, expected);
    EXPECT_EQ(classify_regime(s, a), expected);
    EXPECT_TRUE(orientation_converged(s, a, 1e-9));
    const TiltGrowth g = tilt_growth_rate(s, a);
    EXPECT_TRUE(std::isnan(g.rate));
    EXPECT_EQ(g.periods, 0);
  }
  // A tilt within the in-plane tolerance (1°) is still in the plane; just beyond it is not.
  EXPECT_EQ(classify(series(40.0, tumbling, [](double t) { return 1.0 * std::abs(std::sin(t)); })), Regime::tumbling);
  EXPECT_EQ(classify(series(40.0, tumbling, [](double t) { return 1.05 * std::abs(std::sin(t)); })), Regime::kayaking);
  EXPECT_EQ(classify(series(40.0, swinging, [](double) { return 1.0; })), Regime::swinging);
  EXPECT_EQ(classify(series(40.0, swinging, [](double) { return 1.05; })), Regime::oscillating_swinging);
}

TEST(OrientationRegime, RollingKeepsTheAxisAlongTheVorticity) {
  // A stationary section (the capsule seen end on) with the axis within 2° of x3.
  const Projection round = {1e-5, 0.0};
  EXPECT_EQ(classify(series(20.0, [&](double) { return round; }, [](double) { return 89.0; })), Regime::rolling);
  EXPECT_EQ(classify(series(20.0, [&](double) { return round; }, [](double) { return 88.0; })), Regime::rolling);
  // Beyond 2° from x3 with a stationary shape and tilt: a steady tilted state, not rolling.
  EXPECT_EQ(classify(series(20.0, [&](double) { return round; }, [](double) { return 87.9; })), Regime::steady);
  // Rolling is named from the axis alone: a projection that still oscillates does not change it.
  EXPECT_EQ(classify(series(40.0, swinging, [](double t) { return 89.5 + 0.3 * std::sin(t); })), Regime::rolling);
}

TEST(OrientationRegime, WobblingKayakingAndOscillatingSwinging) {
  // The axis circles the vorticity 20° away from it while the projection turns: wobbling.
  EXPECT_EQ(classify(series(40.0, tumbling, [](double t) { return 70.0 + 10.0 * std::sin(0.8 * t); })),
            Regime::wobbling);
  // The same at an intermediate tilt, reaching within 45° of the plane: kayaking.
  EXPECT_EQ(classify(series(40.0, tumbling, [](double t) { return 30.0 + 10.0 * std::sin(0.8 * t); })),
            Regime::kayaking);
  // The border: a tilt never below 45° is wobbling, one that dips below it is kayaking.
  EXPECT_EQ(classify(series(40.0, tumbling, [](double t) { return 50.0 + 5.0 * std::sin(0.8 * t); })),
            Regime::wobbling);
  EXPECT_EQ(classify(series(40.0, tumbling, [](double t) { return 49.0 + 5.0 * std::sin(0.8 * t); })),
            Regime::kayaking);
  // A swinging projection with the axis oscillating about the plane: oscillating-swinging.
  EXPECT_EQ(classify(series(40.0, swinging,
                            [](double t) { return 15.0 * std::abs(std::sin(kPi * t / kSwingPeriod)); })),
            Regime::oscillating_swinging);
  // A wobbling axis over a swinging projection is still wobbling (the axis names it first).
  EXPECT_EQ(classify(series(40.0, swinging, [](double t) { return 60.0 + 5.0 * std::sin(t); })), Regime::wobbling);
}

TEST(OrientationRegime, UnknownWhereNothingConsistentIsMeasured) {
  // Too short for a period: the in-plane analysis knows nothing, and neither does the orientation.
  const TimeSeries short_run = series(3.0, tumbling, [](double) { return 30.0; });
  ASSERT_EQ(analyse_periods(short_run).regime, Regime::unknown);
  EXPECT_EQ(classify(short_run), Regime::unknown);
  // A stationary shape whose axis still moves by more than 1°: neither steady nor a named motion.
  EXPECT_EQ(classify(series(20.0, steady, [](double t) { return 30.0 + 0.6 * std::sin(3.0 * t); })), Regime::unknown);
  EXPECT_EQ(classify(series(20.0, steady, [](double t) { return 30.0 + 0.4 * std::sin(3.0 * t); })), Regime::steady);
  // No material axis (a mesh without pole nodes: NaN tilt): the in-plane answer, unchanged.
  EXPECT_EQ(classify(series(40.0, swinging, [](double) { return std::nan(""); })), Regime::swinging);
}

TEST(OrientationRegime, NamesSpellThePublishedRegimes) {
  EXPECT_EQ(to_string(Regime::rolling), "rolling");
  EXPECT_EQ(to_string(Regime::wobbling), "wobbling");
  EXPECT_EQ(to_string(Regime::kayaking), "kayaking");
  EXPECT_EQ(to_string(Regime::oscillating_swinging), "oscillating-swinging");
}

TEST(OrientationRegime, RejectsAnInconsistentSeries) {
  TimeSeries s = series(10.0, steady, [](double) { return 5.0; });
  s.axis_tilt.pop_back();
  EXPECT_THROW(classify_regime(s, PeriodAnalysis{}), std::invalid_argument);
  EXPECT_THROW(tilt_growth_rate(s, PeriodAnalysis{}), std::invalid_argument);
}

// The tilt grows (or decays) as exp(σ t) with an oscillation of the shape period on top: the per-period means give σ.
TEST(TiltGrowthRate, RecoversTheExponentOfAGrowingOrDecayingTilt) {
  for (const double sigma : {0.03, -0.05}) {
    for (const auto& [shape, period] : {std::pair{&tumbling, kPi * 2.5}, std::pair{&swinging, kSwingPeriod}}) {
      const double A = sigma > 0 ? 1.0 : 10.0;
      const TimeSeries s = series(60.0, shape, [&](double t) {
        return A * std::exp(sigma * t) * (1.0 + 0.5 * std::cos(2 * kPi * t / period));
      });
      const PeriodAnalysis a = analyse_periods(s);
      const TiltGrowth g = tilt_growth_rate(s, a);
      ASSERT_GE(g.periods, 5) << sigma;
      EXPECT_NEAR(g.rate, sigma, 2e-4) << sigma << " " << to_string(a.regime);
      // Exact exponential periods: the residuals, and with them the error, vanish to the sampling's accuracy.
      EXPECT_LT(g.error, 1e-4) << sigma;
    }
  }
}

TEST(TiltGrowthRate, ErrorCoversTheTruthWithNoiseAndOnlySmallTiltsCount) {
  // A deterministic irregular perturbation of the amplitude: the fit is off, its error says by how much.
  const double sigma = 0.02;
  const TimeSeries s = series(80.0, tumbling, [&](double t) {
    return 2.0 * std::exp(sigma * t) * (1.0 + 0.1 * std::sin(0.37 * t * t / 10.0));
  });
  const TiltGrowth g = tilt_growth_rate(s, analyse_periods(s));
  ASSERT_GE(g.periods, 5);
  EXPECT_GT(g.error, 1e-5);
  EXPECT_LT(std::abs(g.rate - sigma), 3.0 * g.error) << g.rate << " ± " << g.error;
  EXPECT_LT(g.error, 0.01);
  // A tilt that has grown beyond the linear range (20°) is left out: only the early periods count (5° to 55°).
  const TimeSeries big = series(80.0, tumbling, [&](double t) { return 5.0 * std::exp(0.03 * t); });
  const PeriodAnalysis a = analyse_periods(big);
  const TiltGrowth early = tilt_growth_rate(big, a);
  EXPECT_NEAR(early.rate, 0.03, 1e-4);
  EXPECT_LT(early.periods, static_cast<int>(a.periods.size()));
  TiltGrowthOptions all;
  all.linear_tilt_limit = 90.0;
  EXPECT_EQ(tilt_growth_rate(big, a, all).periods, static_cast<int>(a.periods.size()));
  // Two periods give a rate without an error; one gives nothing.
  PeriodAnalysis two = a;
  two.periods.resize(2);
  all.linear_tilt_limit = 90.0;
  const TiltGrowth g2 = tilt_growth_rate(big, two, all);
  EXPECT_NEAR(g2.rate, 0.03, 1e-4);
  EXPECT_TRUE(std::isnan(g2.error));
  two.periods.resize(1);
  EXPECT_TRUE(std::isnan(tilt_growth_rate(big, two, all).rate));
}

// The off-plane part of the stop test: the regime of the last two periods must agree, and so must their mean tilts.
TEST(OrientationConverged, RequiresTheTiltToHaveSettled) {
  const TimeSeries settled = series(40.0, tumbling, [](double t) { return 30.0 + 10.0 * std::sin(0.5 * t); });
  const PeriodAnalysis a = analyse_periods(settled);
  ASSERT_EQ(a.regime, Regime::tumbling);
  // The oscillation of the tilt is not of the shape period: the period means differ by a few degrees.
  const double d = std::abs(final_tilt(settled, a.periods[0].t_begin, a.periods[0].t_end) -
                            final_tilt(settled, a.periods[1].t_begin, a.periods[1].t_end));
  EXPECT_FALSE(orientation_converged(settled, a, 0.5 * d));
  EXPECT_TRUE(orientation_converged(settled, a, 2.0 * d));
  // A tilt still growing: not converged at 0.1°, whatever the shape does.
  const TimeSeries growing = series(40.0, tumbling, [](double t) { return 3.0 * std::exp(0.02 * t); });
  EXPECT_FALSE(orientation_converged(growing, analyse_periods(growing), 0.1));
  // A stationary shape whose axis still drifts (toward x3) within the stationary window.
  const Projection round = {1e-5, 0.0};
  const TimeSeries drifting = series(20.0, [&](double) { return round; }, [](double t) { return 80.0 + 0.1 * t; });
  const PeriodAnalysis b = analyse_periods(drifting);
  ASSERT_EQ(b.regime, Regime::steady);
  EXPECT_FALSE(orientation_converged(drifting, b, 0.1));
  EXPECT_TRUE(orientation_converged(drifting, b, 1.0));
  // The regime changes between the two periods (kayaking, then in the plane): not converged at any tolerance.
  const TimeSeries returning = series(40.0, tumbling, [&](double t) { return t < 32.0 ? 1.5 : 0.5; });
  const PeriodAnalysis c = analyse_periods(returning);
  EXPECT_FALSE(orientation_converged(returning, c, 10.0));
}

}  // namespace
}  // namespace capsim::diagnostics
