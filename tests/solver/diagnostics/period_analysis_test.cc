// Period, extrema and regime detection on synthetic signals with known answers.
#include "solver/diagnostics/period_analysis.h"

#include <string>
#include <variant>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "solver/config/case_keys.h"

namespace capsim::diagnostics {
namespace {

constexpr double kPi = std::numbers::pi;

// Bring an axis angle into (−π/2, π/2], as ellipsoid_of_inertia reports it.
double wrap_axis(double a) {
  double w = std::remainder(a, kPi);
  if (w <= -kPi / 2) w += kPi;
  return w;
}

// Jeffery orbit of a rigid ellipse of aspect ratio r in v = (x2, 0, 0): tan φ = −(1/r) tan(t r/(r²+1)),
// φ continuous and decreasing (clockwise with the vorticity). Revolution period 2π (r + 1/r).
double jeffery_angle(double t, double r) {
  const double psi = t * r / (r * r + 1.0);
  // atan2 gives the angle mod 2π; add back the completed turns so the angle is continuous.
  const double base = std::atan2(-std::sin(psi), r * std::cos(psi));
  const double turns = std::floor((psi + kPi) / (2 * kPi));
  return base - 2 * kPi * turns;
}

struct Signal {
  std::vector<double> t, D12, theta, tau_min;
};

Signal sample(double t_end, double dt, const std::function<void(double, double&, double&, double&)>& f,
              double jitter = 0.0) {
  Signal s;
  for (int i = 0; i * dt <= t_end; ++i) {
    // Deterministic jitter of the sampling times: the analysis must not assume a constant step.
    const double t = i * dt + (i > 0 ? jitter * dt * std::sin(12.9898 * i) : 0.0);
    double d, th, tau;
    f(t, d, th, tau);
    s.t.push_back(t);
    s.D12.push_back(d);
    s.theta.push_back(th);
    s.tau_min.push_back(tau);
  }
  return s;
}

PeriodAnalysis analyse(const Signal& s, const PeriodOptions& o = {}) {
  return analyse_periods(s.t, s.D12, s.theta, s.tau_min, o);
}

TEST(UnwrapAxisAngle, RemovesWrapsOfPi) {
  // A steadily decreasing axis, reported in (−π/2, π/2].
  std::vector<double> raw, truth;
  for (int i = 0; i < 400; ++i) {
    truth.push_back(0.3 - 0.05 * i);
    raw.push_back(wrap_axis(truth.back()));
  }
  const auto u = unwrap_axis_angle(raw);
  for (std::size_t i = 0; i < u.size(); ++i) EXPECT_NEAR(u[i], truth[i], 1e-12) << i;
}

TEST(SignificantMinima, IgnoresWigglesBelowTheProminence) {
  std::vector<double> y;
  for (int i = 0; i < 2000; ++i) {
    const double t = 0.01 * i;
    y.push_back(std::cos(2 * kPi * t / 4.0) + 0.01 * std::sin(2 * kPi * t / 0.05));  // period 4, 5 periods
  }
  const auto m = significant_minima(y, 0.2);
  ASSERT_EQ(m.size(), 5u);  // minima at t = 2, 6, 10, 14, 18
  for (std::size_t k = 0; k < m.size(); ++k) EXPECT_NEAR(0.01 * m[k], 2.0 + 4.0 * k, 0.05);
  // With a prominence below the wiggles, the wiggles count: many more minima.
  EXPECT_GT(significant_minima(y, 0.001).size(), 50u);
}

TEST(PeriodAnalysis, RigidJefferyOrbitTumblesWithHalfTheRevolutionPeriod) {
  const double r = 2.0, D0 = 1.0 / 3.0;
  const Signal s = sample(40.0, 0.01, [&](double t, double& d, double& th, double& tau) {
    d = D0;  // a rigid ellipse keeps its shape
    th = wrap_axis(jeffery_angle(t, r));
    tau = 0.0;
  });
  const auto a = analyse(s);
  EXPECT_EQ(a.regime, Regime::tumbling);
  EXPECT_NEAR(a.period, kPi * (r + 1 / r), 1e-3);
  EXPECT_NEAR(a.revolution_period, 2 * kPi * (r + 1 / r), 2e-3);
  EXPECT_NEAR(a.min_D12, D0, 1e-15);
  ASSERT_GE(a.periods.size(), 4u);  // 40 / 7.85
  for (const auto& w : a.periods) EXPECT_NEAR(w.theta_sweep, -kPi, 0.02);
  EXPECT_TRUE(periodic_regime_converged(a));
}

TEST(PeriodAnalysis, DeformableTumblingGivesMinD12AndMaxTauMinOverOnePeriod) {
  // A quasi-rigid Jeffery rotation with the shape squeezed in the compression quadrant (φ = −π/4):
  // D12 = 1/3 + 0.05 sin 2φ has its minimum 1/3 − 0.05 there, once per turn of the axis by π.
  const double r = 2.0;
  const Signal s = sample(
      50.0, 0.01,
      [&](double t, double& d, double& th, double& tau) {
        const double phi = jeffery_angle(t, r);
        d = 1.0 / 3.0 + 0.05 * std::sin(2 * phi);
        th = wrap_axis(phi);
        tau = -0.02 + 0.03 * std::cos(2 * phi + 0.3);
      },
      0.3);
  const auto a = analyse(s);
  EXPECT_EQ(a.regime, Regime::tumbling);
  EXPECT_NEAR(a.period, kPi * (r + 1 / r), 1e-3);
  EXPECT_NEAR(a.min_D12, 1.0 / 3.0 - 0.05, 1e-5);
  EXPECT_NEAR(a.max_tau_min, 0.01, 1e-5);
  // The time mean of sin 2φ over a Jeffery period is not zero (the axis lingers near the flow direction),
  // so only bound it.
  EXPECT_GT(a.mean_D12, 1.0 / 3.0 - 0.05);
  EXPECT_LT(a.mean_D12, 1.0 / 3.0 + 0.05);
  EXPECT_TRUE(periodic_regime_converged(a));
}

TEST(PeriodAnalysis, SwingingOscillatesAboutAMeanInclination) {
  const double T = 6.5, w = 2 * kPi / T;
  const Signal s = sample(
      40.0, 0.01,
      [&](double t, double& d, double& th, double& tau) {
        th = 0.3 + 0.15 * std::sin(w * t);
        d = 0.3 + 0.08 * std::cos(w * t + 1.0);
        tau = 0.05 + 0.02 * std::sin(w * t);
      },
      0.3);
  const auto a = analyse(s);
  EXPECT_EQ(a.regime, Regime::swinging);
  EXPECT_NEAR(a.period, T, 1e-3);
  EXPECT_NEAR(a.revolution_period, 2 * T, 2e-3);
  EXPECT_NEAR(a.min_D12, 0.22, 1e-5);
  EXPECT_NEAR(a.max_tau_min, 0.07, 1e-5);
  EXPECT_NEAR(a.mean_D12, 0.3, 1e-4);
  EXPECT_NEAR(a.theta_mean, 0.3, 1e-3);
  EXPECT_NEAR(a.theta_amplitude, 0.15, 1e-4);
  EXPECT_GE(a.periods.size(), 5u);
  EXPECT_TRUE(periodic_regime_converged(a));
}

// The period-to-period spread of the answers (the "periods" error of Table 1): zero for an exactly periodic
// signal, the growth over one period for a signal whose swing grows linearly in time.
TEST(PeriodAnalysis, PeriodSpreadIsTheChangeOfTheAnswersOverTheLastPeriods) {
  const double T = 6.5, w = 2 * kPi / T, growth = 1e-4;  // amplitude of D12 and τmin grows by growth per unit time
  auto signal = [&](double g) {
    return sample(40.0, 0.005, [&, g](double t, double& d, double& th, double& tau) {
      th = 0.3 + 0.15 * std::sin(w * t);
      d = 0.3 - (0.08 + g * t) * std::cos(w * t);
      tau = 0.05 + (0.02 + g * t) * std::sin(w * t);
    });
  };
  const auto periodic = analyse(signal(0.0));
  ASSERT_EQ(periodic.regime, Regime::swinging);
  EXPECT_LT(periodic.min_D12_period_spread, 1e-6);
  EXPECT_LT(periodic.max_tau_min_period_spread, 1e-6);
  const auto growing = analyse(signal(growth));
  ASSERT_EQ(growing.regime, Regime::swinging);
  ASSERT_GE(growing.periods.size(), 3u);
  // Minima and maxima one period apart differ by growth · T (the last two periods are compared).
  EXPECT_NEAR(growing.min_D12_period_spread, growth * T, 0.05 * growth * T);
  EXPECT_NEAR(growing.max_tau_min_period_spread, growth * T, 0.05 * growth * T);
}

TEST(PeriodAnalysis, SwingingNearTheTransitionWithAKinkedMinimumStaysSwinging) {
  // Near Ca*, D12 dips to ~0 with a V-shaped minimum and θ jumps quickly there; still no net rotation.
  const double T = 8.0, w = 2 * kPi / T;
  const Signal s = sample(40.0, 0.005, [&](double t, double& d, double& th, double& tau) {
    d = 0.02 + 0.3 * std::abs(std::sin(0.5 * w * t));
    th = 0.2 + 0.9 * std::sin(w * t + 0.5);
    tau = std::cos(w * t);
  });
  const auto a = analyse(s);
  EXPECT_EQ(a.regime, Regime::swinging);
  EXPECT_NEAR(a.period, T, 0.01);
  EXPECT_NEAR(a.min_D12, 0.02, 1e-4);
  EXPECT_NEAR(a.max_tau_min, 1.0, 1e-4);
}

TEST(PeriodAnalysis, SphereReachesASteadyShape) {
  auto f = [](double t, double& d, double& th, double& tau) {
    d = 0.1 * (1 - std::exp(-t / 2));
    th = kPi / 4 + 0.2 * std::exp(-t / 2);
    tau = 0.3 * (1 - std::exp(-t / 2));
  };
  const auto a = analyse(sample(60.0, 0.01, f));
  EXPECT_EQ(a.regime, Regime::steady);
  EXPECT_EQ(a.period, 0.0);
  EXPECT_NEAR(a.min_D12, 0.1, 1e-9);
  EXPECT_NEAR(a.max_tau_min, 0.3, 1e-9);
  EXPECT_NEAR(a.theta_mean, kPi / 4, 1e-9);
  EXPECT_TRUE(periodic_regime_converged(a));
  // Still relaxing at t = 8: neither steady nor periodic yet.
  const auto early = analyse(sample(8.0, 0.01, f));
  EXPECT_EQ(early.regime, Regime::unknown);
  EXPECT_TRUE(std::isnan(early.period));
  EXPECT_TRUE(std::isnan(early.min_D12));
  EXPECT_FALSE(periodic_regime_converged(early));
}

TEST(PeriodAnalysis, UndeformedSphereIsSteadyWhateverItsNoisyInclination) {
  // A circular section has no long axis: θ is round-off noise and must not prevent "steady".
  const auto a = analyse(sample(10.0, 0.01, [](double t, double& d, double& th, double& tau) {
    d = 1e-13 * (1 + std::sin(7 * t));
    th = 1.5 * std::sin(1000 * t);
    tau = 0;
  }));
  EXPECT_EQ(a.regime, Regime::steady);
}

// The final analysis of a run (what the driver passes once the run has ended): stationary to the default
// time.period_tolerance.
PeriodOptions final_analysis() {
  PeriodOptions o;
  o.stationary_tolerance = 2e-3;
  return o;
}

// A tank-treading sphere whose shape is stationary to ~1e-3 while τmin, a pointwise minimum
// over a wrinkling membrane, flickers by a few 1e-2. The settled rule (spread of D12 ≤ 1e-4) never calls
// it steady; the final analysis must report it steady, with D12, θ and the statistics of τmin over the
// window — and the march's analysis must not (a stop needs a settled shape).
TEST(PeriodAnalysis, StationaryShapeWithFlickeringTauMinIsSteady) {
  const double D = 0.39, th0 = 0.45;
  // Flicker: a sum of incommensurate fast modes (a deterministic stand-in for mesh-scale wrinkles).
  auto flicker = [](double t) { return std::sin(41.3 * t) * std::cos(17.1 * t + 0.4) + 0.5 * std::sin(97.0 * t); };
  auto f = [&](double t, double& d, double& th, double& tau) {
    d = D * (1 - std::exp(-2 * t)) + 3e-4 * flicker(t);
    th = th0 + 0.3 * std::exp(-2 * t) + 2e-4 * flicker(1.7 * t);
    tau = -0.004 + 0.02 * flicker(2.3 * t);
  };
  const auto a = analyse(sample(12.0, 0.01, f, 0.3), final_analysis());
  ASSERT_EQ(a.regime, Regime::steady);
  EXPECT_EQ(a.period, 0.0);
  EXPECT_EQ(a.revolution_period, 0.0);
  // The steady D12 and θ: time means over the window, to within the flicker's amplitude.
  EXPECT_NEAR(a.mean_D12, D, 1e-4);
  EXPECT_NEAR(a.theta_mean, th0, 1e-4);
  EXPECT_NEAR(a.min_D12, D, 1e-3);
  EXPECT_LE(a.min_D12, a.mean_D12);
  // τmin statistics over the same window, against the samples themselves.
  const Signal s = sample(12.0, 0.01, f, 0.3);
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t i = 0; i < s.t.size(); ++i)
    if (s.t[i] >= s.t.back() - PeriodOptions{}.steady_window) lo = std::min(lo, s.tau_min[i]), hi = std::max(hi, s.tau_min[i]);
  EXPECT_EQ(a.max_tau_min, hi);
  EXPECT_EQ(a.min_tau_min, lo);
  EXPECT_NEAR(a.tau_min_spread, hi - lo, 1e-15);
  EXPECT_GT(a.tau_min_spread, 0.03);  // the flicker is there and is not taken for unsteadiness
  EXPECT_NEAR(a.mean_tau_min, -0.004, 2e-3);
  ASSERT_EQ(a.periods.size(), 1u);
  EXPECT_NEAR(a.periods[0].period(), PeriodOptions{}.steady_window, 0.02);
  // During the march only the settled rule may call it steady, and the flickering shape is not settled.
  EXPECT_NE(analyse(s).regime, Regime::steady);
  // A tighter tolerance than the flicker of the shape refuses it.
  PeriodOptions tight;
  tight.stationary_tolerance = 1e-4;
  EXPECT_NE(analyse(s, tight).regime, Regime::steady);
}

// A sphere at small Ca wrinkles more: D12 flickers with a spread (≈ 4e-3) above the tolerance while its
// mean does not move. Stationary (no drift between the half-window means) is what counts, not the spread;
// an oscillation of the shape by 2e-2 (a swinging's order) is refused even without drift.
TEST(PeriodAnalysis, FlickerAboveTheToleranceWithoutDriftIsSteady) {
  auto flicker = [](double t) { return std::sin(41.3 * t) * std::cos(17.1 * t + 0.4) + 0.5 * std::sin(97.0 * t); };
  auto f = [&](double t, double& d, double& th, double& tau) {
    d = 0.27 + 1.3e-3 * flicker(t);
    th = 0.53 + 1e-3 * flicker(1.3 * t);
    tau = -0.15 + 0.02 * flicker(2.1 * t);
  };
  const Signal s = sample(10.0, 0.01, f);
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t i = 0; i < s.t.size(); ++i)
    if (s.t[i] >= s.t.back() - PeriodOptions{}.steady_window) lo = std::min(lo, s.D12[i]), hi = std::max(hi, s.D12[i]);
  ASSERT_GT(hi - lo, 2e-3) << "the flicker must exceed the tolerance for this test to mean something";
  const auto a = analyse(s, final_analysis());
  EXPECT_EQ(a.regime, Regime::steady);
  EXPECT_NEAR(a.mean_D12, 0.27, 2e-4);
  auto g = [&](double t, double& d, double& th, double& tau) {
    d = 0.27 + 1e-2 * std::sin(2 * kPi * t / 2.5);  // D12 oscillating by 2e-2, period 2.5: no drift
    th = 0.53;
    tau = -0.15;
  };
  EXPECT_NE(analyse(sample(10.0, 0.01, g), final_analysis()).regime, Regime::steady);
}

TEST(PeriodAnalysis, SlowlyDriftingShapeIsNotSteady) {
  // D12 creeping up by 1e-3 per time unit (5e-3 over the window), θ fixed: not stationary.
  auto f = [](double t, double& d, double& th, double& tau) {
    d = 0.3 + 1e-3 * t;
    th = 0.5;
    tau = 0.01;
  };
  const auto a = analyse(sample(20.0, 0.01, f), final_analysis());
  EXPECT_NE(a.regime, Regime::steady);
  EXPECT_FALSE(periodic_regime_converged(a));
  // θ drifting at a fixed shape is a slow rotation, not a steady state either.
  auto g = [](double t, double& d, double& th, double& tau) {
    d = 0.3;
    th = 0.5 - 2e-3 * t;
    tau = 0.01;
  };
  const auto b = analyse(sample(20.0, 0.01, g), final_analysis());
  EXPECT_NE(b.regime, Regime::steady);
  EXPECT_FALSE(periodic_regime_converged(b));
}

TEST(PeriodAnalysis, SlowTumblingIsNotSteady) {
  // A long rigid ellipse (r = 10) lingers near the flow direction: its axis turns by only ≈ 0.05 rad over
  // the 5-unit window there, while D12 is exactly constant. That is tumbling, never a steady state.
  const double r = 10.0, D0 = (r - 1) / (r + 1);
  auto f = [&](double t, double& d, double& th, double& tau) {
    d = D0;
    th = wrap_axis(jeffery_angle(t, r));
    tau = 0.0;
  };
  for (double t_end : {6.0, 12.0, 20.0, 28.0})
    EXPECT_NE(analyse(sample(t_end, 0.01, f), final_analysis()).regime, Regime::steady) << t_end;
  const auto a = analyse(sample(40.0, 0.01, f));
  EXPECT_EQ(a.regime, Regime::tumbling);
  EXPECT_NEAR(a.period, kPi * (r + 1 / r), 1e-2);
}

TEST(PeriodAnalysis, TooLittleDataIsUnknown) {
  const std::vector<double> t{0, 0.1}, d{0.3, 0.31}, th{0, -0.01}, tau{0, 0};
  EXPECT_EQ(analyse_periods(t, d, th, tau).regime, Regime::unknown);
  const std::vector<double> shorter{0.0};
  EXPECT_THROW(analyse_periods(t, d, th, shorter), std::invalid_argument);
}

TEST(PeriodicConvergence, WaitsForTheTransientToDecay) {
  // Tumbling with a decaying extra deformation: min D12 per period drifts, then settles.
  const double r = 2.0;
  auto f = [&](double t, double& d, double& th, double& tau) {
    const double phi = jeffery_angle(t, r);
    const double amp = 0.05 + 0.05 * std::exp(-t / 5);
    d = 1.0 / 3.0 + amp * std::sin(2 * phi);
    th = wrap_axis(phi);
    tau = -0.02 + amp * std::cos(2 * phi);
  };
  const auto early = analyse(sample(20.0, 0.01, f));
  ASSERT_EQ(early.regime, Regime::tumbling);
  ASSERT_GE(early.periods.size(), 2u);
  EXPECT_FALSE(periodic_regime_converged(early));
  const auto late = analyse(sample(90.0, 0.01, f));
  EXPECT_TRUE(periodic_regime_converged(late));
  EXPECT_NEAR(late.min_D12, 1.0 / 3.0 - 0.05, 1e-4);
  // A stricter tolerance or more agreeing periods are harder to meet.
  ConvergenceOptions strict;
  strict.tol_D12 = 1e-9;
  EXPECT_FALSE(periodic_regime_converged(late, strict));
  ConvergenceOptions many;
  many.periods = 30;  // more periods than recorded
  EXPECT_FALSE(periodic_regime_converged(late, many));
}

TEST(PeriodicConvergence, DetectsAChangingPeriod) {
  // Same amplitude every cycle but a period still lengthening: not converged.
  auto f = [](double t, double& d, double& th, double& tau) {
    // Instantaneous period 6 / (1 + 0.8 e^(−t/15)): successive periods near t = 30 differ by ≈ 4 %.
    const double phase = 2 * kPi * (t / 6.0 - 2.0 * std::exp(-t / 15));
    d = 0.3 + 0.1 * std::cos(phase);
    th = 0.2 + 0.1 * std::sin(phase);
    tau = 0.0;
  };
  const auto a = analyse(sample(30.0, 0.01, f));
  ASSERT_EQ(a.regime, Regime::swinging);
  ASSERT_GE(a.periods.size(), 2u);
  const double change = std::abs(a.periods[0].period() / a.periods[1].period() - 1);
  EXPECT_GT(change, 0.02);
  EXPECT_FALSE(periodic_regime_converged(a));
  // Amplitude and τmin are the same every cycle: only the period criterion refuses, as a looser one shows.
  ConvergenceOptions loose;
  loose.tol_period = 2 * change;
  EXPECT_TRUE(periodic_regime_converged(a, loose));
}

TEST(PeriodicConvergence, StopTestComparesOnlyTheAnswersItNames) {
  // Swinging with a constant period; one answer settled from the start, the other's amplitude still decaying
  // (successive maxima differ by ≈ 1e-2 near t = 30, far above the tolerance 1e-3).
  auto swinging = [](bool d12_settles) {
    return [d12_settles](double t, double& d, double& th, double& tau) {
      const double phase = 2 * kPi * t / 6.0, decay = 0.1 * std::exp(-t / 15);
      d = 0.3 + (d12_settles ? 0.1 : 0.1 + decay) * std::cos(phase);
      th = 0.2 + 0.1 * std::sin(phase);
      tau = 0.01 + (d12_settles ? decay : 0.0) * std::cos(phase);
    };
  };
  const double tol = 1e-3;
  const auto tau_drifts = analyse(sample(30.0, 0.01, swinging(true)));
  ASSERT_EQ(tau_drifts.regime, Regime::swinging);
  ASSERT_GE(tau_drifts.periods.size(), 2u);
  EXPECT_GT(std::abs(tau_drifts.periods[0].max_tau_min - tau_drifts.periods[1].max_tau_min), 5 * tol);
  EXPECT_FALSE(periodic_regime_converged(tau_drifts, stop_test_options("both", tol)));
  EXPECT_TRUE(periodic_regime_converged(tau_drifts, stop_test_options("min_D12", tol)));
  EXPECT_FALSE(periodic_regime_converged(tau_drifts, stop_test_options("max_tau_min", tol)));
  const auto d12_drifts = analyse(sample(30.0, 0.01, swinging(false)));
  ASSERT_EQ(d12_drifts.regime, Regime::swinging);
  EXPECT_FALSE(periodic_regime_converged(d12_drifts, stop_test_options("both", tol)));
  EXPECT_FALSE(periodic_regime_converged(d12_drifts, stop_test_options("min_D12", tol)));
  EXPECT_TRUE(periodic_regime_converged(d12_drifts, stop_test_options("max_tau_min", tol)));
  // "both" is the default test; the tolerance applies; the period is compared by every test.
  const ConvergenceOptions both = stop_test_options("both", tol), plain;
  EXPECT_EQ(both.tol_D12, tol);
  EXPECT_EQ(both.tol_tau_min, tol);
  EXPECT_EQ(both.tol_period, plain.tol_period);
  EXPECT_EQ(stop_test_options("min_D12", tol).tol_period, plain.tol_period);
  EXPECT_THROW(stop_test_options("D12", tol), std::invalid_argument);
}

// The names the solver and the campaign use are the values the key registry accepts, no more, no fewer.
TEST(PeriodicConvergence, StopTestNamesAreTheRegistrysValues) {
  const config::CaseKey* key = config::find_case_key("time.stop_test");
  ASSERT_NE(key, nullptr);
  EXPECT_EQ(key->rule.words, (std::vector<std::string>{std::string(kStopTestBoth), std::string(kStopTestMinD12),
                                                       std::string(kStopTestMaxTauMin)}));
  EXPECT_EQ(std::get<std::string>(key->default_value), kStopTestBoth);
  for (const auto& name : key->rule.words) EXPECT_NO_THROW(stop_test_options(name, 1e-3)) << name;
}

TEST(Regime, Names) {
  EXPECT_EQ(to_string(Regime::tumbling), "tumbling");
  EXPECT_EQ(to_string(Regime::swinging), "swinging");
  EXPECT_EQ(to_string(Regime::steady), "steady");
  EXPECT_EQ(to_string(Regime::unknown), "unknown");
}

}  // namespace
}  // namespace capsim::diagnostics
