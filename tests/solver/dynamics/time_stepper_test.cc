#include "solver/dynamics/time_stepper.h"

#include <cmath>
#include <complex>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "solver/membrane/membrane_mechanics.h"
#include "solver/mesh/mesh.h"
#include "tests/solver/dynamics/stability_probe.h"

namespace capsim::dynamics {
namespace {

// The automatic dt is stable with a real but not wasteful margin: RK2 in shear flow at the automatic dt
// survives 200 steps with the stiffest modes excited; at twice that dt it blows up within them.
TEST(Rk2Stability, AutomaticTimeStepIsStableAndTwiceItIsNot) {
  EXPECT_EQ(config::CaseConfig{}.dt_factor, kDefaultFactor);
  for (double Ca : {0.05, 1.0}) {
    CapsuleFlow flow(make_case(2, Ca, 1.0));
    const Eigen::Matrix3Xd x0 = perturbed_reference(flow);
    const double dt = automatic_time_step(flow.mesh(), Ca, kDefaultFactor);
    Rk2Integrator rk;
    EXPECT_EQ(steps_until_blow_up(rk, flow, x0, dt, 200), 200) << "Ca = " << Ca;
    EXPECT_LT(steps_until_blow_up(rk, flow, x0, 2.0 * dt, 200), 200) << "Ca = " << Ca;
  }
}

// Stability polynomial of the RKC coefficients, from the stage recurrence applied to y' = z y:
// second order (R = 1 + z + z²/2 + O(z³)), |R| ≤ 1 on [−β(s), 0], and β(s) ≈ 0.653 s² for ε = 2/13 (SSV 1998).
std::complex<double> rkc_amplification(const RkcCoefficients& k, std::complex<double> z) {
  std::complex<double> r2 = 1.0, r1 = 1.0 + k.mu_tilde[1] * z;
  for (int j = 2; j <= k.stages; ++j) {
    const std::complex<double> r = (1.0 - k.mu[j] - k.nu[j]) + k.mu[j] * r1 + k.nu[j] * r2 +
                                   k.mu_tilde[j] * z * r1 + k.gamma_tilde[j] * z;
    r2 = r1;
    r1 = r;
  }
  return r1;
}

TEST(Rkc, StabilityPolynomialIsSecondOrderAndBoundedOnItsInterval) {
  const double eps = 2.0 / 13.0;
  for (int s : {2, 3, 5, 10, 20, 40}) {
    const RkcCoefficients k = rkc_coefficients(s, eps);
    const double beta = k.stability_boundary();
    EXPECT_NEAR(beta, RkcIntegrator::stability_boundary(s, eps), 1e-12 * beta);
    EXPECT_NEAR(beta, 2.0 / 3.0 * (s * s - 1) * (1.0 - 2.0 * eps / 15.0), 0.02 * beta) << s;
    for (double z : {1e-3, -1e-3}) {
      const double err = std::abs(rkc_amplification(k, z) - (1.0 + z + 0.5 * z * z));
      EXPECT_LT(err, 2.0 * s * s * s * std::abs(z * z * z)) << "s = " << s;  // O(z³)
    }
    double worst = 0.0;
    for (int i = 0; i <= 2000; ++i) worst = std::max(worst, std::abs(rkc_amplification(k, -beta * i / 2000.0)));
    EXPECT_LE(worst, 1.0 + 1e-10) << "s = " << s;
    // Damping: strictly inside the interval |R| stays below 1 − ε-ish away from z = 0.
    EXPECT_LT(std::abs(rkc_amplification(k, -0.5 * beta)), 0.96) << "s = " << s;
    // Well beyond β the Chebyshev polynomial takes over: unstable.
    EXPECT_GT(std::abs(rkc_amplification(k, -1.5 * beta)), 1.0) << "s = " << s;
    const double b = RkcIntegrator::stability_boundary(s, eps);
    EXPECT_EQ(RkcIntegrator::stages_for(b, eps), s);
    EXPECT_EQ(RkcIntegrator::stages_for(b * 1.0001, eps), s + 1);
  }
}

// The stiffness estimate that sets the stages bounds the power-iteration spectral radius of dv/dx from above,
// and not by much (else the stages are wasted).
TEST(Rkc, MembraneSpectralRadiusBoundsThePowerIteration) {
  for (double ar : {0.5, 2.0}) {
    const double Ca = 0.05;
    CapsuleFlow flow(make_case(2, Ca, ar));
    const Eigen::Matrix3Xd x = perturbed_reference(flow);
    Eigen::Matrix3Xd v;
    const auto ev = flow.velocity(x, v);
    const double measured = estimate_spectral_radius(flow, x, 40);
    const double bound = membrane_spectral_radius(flow.mesh(), x, Ca, ev.tau_max);
    EXPECT_GT(bound, measured) << "a/b = " << ar;
    EXPECT_LT(bound, 1.5 * measured) << "a/b = " << ar;
  }
}

// Relaxation of a stretched capsule in fluid at rest, level 1: the error against a tiny-dt reference falls
// by ~4 when dt halves (second order), in the stiff regime (dt ρ ≫ 2, several stages per step).
TEST(Rkc, ConvergesAtSecondOrder) {
  const double Ca = 0.1;
  CapsuleFlow flow(make_case(1, Ca, 1.0));
  flow.set_background_flow(false);
  Eigen::Matrix3Xd x0 = flow.reference();
  x0.row(0) *= 1.2;
  x0.row(1) /= std::sqrt(1.2);
  x0.row(2) /= std::sqrt(1.2);
  const double T = 0.4;
  auto solve = [&](double dt) {
    RkcIntegrator rkc;
    Eigen::Matrix3Xd x = x0;
    const int n = static_cast<int>(std::lround(T / dt));
    int max_stages = 0;
    for (int i = 0; i < n; ++i) max_stages = std::max(max_stages, rkc.step(flow, x, dt).stages);
    return std::pair{x, max_stages};
  };
  const Eigen::Matrix3Xd reference = solve(T / 640).first;
  double previous = 0.0;
  for (int level = 0; level < 3; ++level) {
    const double dt = 0.05 / (1 << level);
    const auto [x, stages] = solve(dt);
    EXPECT_GE(stages, 4) << "the test must exercise the stabilised regime (dt ρ beyond RK2's interval 2)";
    const double err = (x - reference).colwise().norm().maxCoeff();
    std::printf("RKC relaxation: dt %g, up to %d stages, max error %.3g\n", dt, stages, err);
    if (level > 0) {
      const double order = std::log2(previous / err);
      EXPECT_GT(order, 1.7) << "dt = " << dt << " err = " << err << " previous = " << previous;
      EXPECT_LT(order, 2.5) << "dt = " << dt;
    }
    previous = err;
  }
}

// Where RK2 blows up, RKC at the same dt is stable (shear flow, stiffest modes excited), and after one
// shear time its shape agrees with RK2 at its stable dt.
TEST(Rkc, StableWhereRk2BlowsUpAndAgreesWithIt) {
  const double Ca = 0.02;
  CapsuleFlow flow(make_case(1, Ca, 1.0));
  const Eigen::Matrix3Xd x0 = perturbed_reference(flow);
  const double dt_rk2 = automatic_time_step(flow.mesh(), Ca, kDefaultFactor);
  const double dt = 0.02;
  ASSERT_GT(dt, 4.0 * dt_rk2);
  Rk2Integrator rk;
  RkcIntegrator rkc;
  EXPECT_LT(steps_until_blow_up(rk, flow, x0, dt, 50), 50);
  EXPECT_EQ(steps_until_blow_up(rkc, flow, x0, dt, 50), 50);

  Eigen::Matrix3Xd a = x0, b = x0;
  long evaluations_rkc = 0, evaluations_rk2 = 0;
  for (int i = 0; i < 50; ++i) evaluations_rkc += rkc.step(flow, a, dt).evaluations;
  const int n = static_cast<int>(std::ceil(1.0 / dt_rk2));
  for (int i = 0; i < n; ++i) evaluations_rk2 += rk.step(flow, b, 1.0 / n).evaluations;
  const double extent = flow.reference().colwise().norm().maxCoeff();
  const double difference = (a - b).colwise().norm().maxCoeff();
  std::printf("RKC dt %g vs RK2 dt %g after t = 1: max |x_rkc - x_rk2| = %.3g (extent %.3g), evaluations %ld vs %ld\n",
              dt, 1.0 / n, difference, extent, evaluations_rkc, evaluations_rk2);
  EXPECT_LT(difference, 5e-4 * extent);
  EXPECT_LT(3 * evaluations_rkc, evaluations_rk2) << "RKC must need far fewer flow evaluations";
}

// The first stage's v and q are those of a plain evaluation on x_n (snapshots use them instead of one of
// their own), for both schemes.
TEST(Integrators, StartFieldsAreTheFieldsOfTheInitialState) {
  CapsuleFlow flow(make_case(1, 0.3, 2.0));
  const Eigen::Matrix3Xd x0 = perturbed_reference(flow);
  Eigen::Matrix3Xd v, q;
  flow.velocity(x0, v, &q);
  for (const config::TimeScheme scheme : {config::TimeScheme::Rk2, config::TimeScheme::Rkc}) {
    SCOPED_TRACE(config::word_of(scheme));
    auto integrator = make_integrator(scheme);
    Eigen::Matrix3Xd x = x0;
    StartFields start;
    integrator->step(flow, x, 0.01, &start);
    EXPECT_TRUE(start.velocity == v);
    EXPECT_TRUE(start.load == q);
    EXPECT_FALSE(x == x0);
  }
}

// The stage count is the smallest s with β(s) ≥ dt · safety · membrane_spectral_radius(x_n), with the safety
// of time.rkc_safety (make_integrator passes it on): a larger safety takes more stages, never fewer.
TEST(Rkc, StagesFollowSafetyTimesTheStiffnessEstimate) {
  EXPECT_EQ(RkcIntegrator::Options{}.safety, kRkcSafety);
  EXPECT_EQ(config::CaseConfig{}.rkc_safety, kRkcSafety);
  const double Ca = 0.05;
  CapsuleFlow flow(make_case(1, Ca, 2.0));
  const Eigen::Matrix3Xd x0 = perturbed_reference(flow);
  Eigen::Matrix3Xd v;
  const FlowEvaluation ev = flow.velocity(x0, v);
  const double rho = membrane_spectral_radius(flow.mesh(), x0, Ca, ev.tau_max);
  const double dt = 0.05;
  int previous = 0, first = 0;
  for (double safety : {1.0, kRkcSafety, 2.0, 4.0}) {
    auto integrator = make_integrator(config::TimeScheme::Rkc, safety);
    Eigen::Matrix3Xd x = x0;
    const StepInfo info = integrator->step(flow, x, dt);
    const int expected = RkcIntegrator::stages_for(dt * safety * rho, RkcIntegrator::Options{}.damping);
    EXPECT_EQ(info.stages, expected) << "safety " << safety;
    EXPECT_EQ(info.evaluations, expected) << "safety " << safety;
    EXPECT_DOUBLE_EQ(dynamic_cast<RkcIntegrator&>(*integrator).last_spectral_radius(), safety * rho);
    EXPECT_GE(info.stages, previous) << "safety " << safety;
    previous = info.stages;
    if (first == 0) first = info.stages;
  }
  EXPECT_GT(previous, first) << "the dt here must make the safety count";
}

// At the automatic dt of a stiff case the stages the default safety chooses cover the power-iteration
// spectral radius of the state with a margin: dt · ρ(power iteration) · 1.1 ≤ β(s). (Shear flow, Ca = 0.02,
// level 1, every mode excited; the level-2/3 states along runs are in spectral_radius_validation.)
TEST(Rkc, DefaultStagesCoverThePowerIterationSpectralRadius) {
  for (double ar : {0.5, 2.0}) {
    config::CaseConfig c = make_case(1, 0.02, ar);
    CapsuleFlow flow(c);
    const Eigen::Matrix3Xd x = perturbed_reference(flow);
    const double dt = automatic_time_step(c, flow.mesh());
    EXPECT_EQ(dt, c.dt_accuracy) << "the stiff regime: dt set by accuracy";
    auto rkc = make_integrator(config::TimeScheme::Rkc, c.rkc_safety);
    Eigen::Matrix3Xd y = x;
    const int s = rkc->step(flow, y, dt).stages;
    const double truth = estimate_spectral_radius(flow, x, 60);
    const double beta = RkcIntegrator::stability_boundary(s, RkcIntegrator::Options{}.damping);
    std::printf("a/b %g: dt %g, %d stages, beta %.1f, dt rho(power iteration) %.1f\n", ar, dt, s, beta, dt * truth);
    EXPECT_GE(beta, 1.1 * dt * truth) << "a/b = " << ar;
  }
}

// A dt RKC cannot take is a StepRejected (the driver reports it as unstable), and x is left as it was.
TEST(Rkc, RefusesTooManyStagesWithStepRejected) {
  CapsuleFlow flow(make_case(1, 0.05, 2.0));
  RkcIntegrator::Options o;
  o.max_stages = 10;
  RkcIntegrator rkc(o);
  Eigen::Matrix3Xd x = flow.reference();
  const Eigen::Matrix3Xd x0 = x;
  try {
    rkc.step(flow, x, 10.0);
    FAIL() << "no exception";
  } catch (const StepRejected& e) {
    EXPECT_NE(std::string(e.what()).find("stages"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(x == x0);
}

// With bending the automatic rkc step stays the accuracy step while the stages allow it, and is capped so
// that the reference state needs at most half of max_stages where they would not (level 4, κ_b = 0.1);
// without bending it is what it always was.
TEST(Rkc, AutomaticStepKeepsTheStagesWithinReachUnderBending) {
  config::CaseConfig c;
  c.aspect_ratio = 0.5;
  c.capillary_number = 0.05;
  const RkcIntegrator::Options rkc;
  for (int level : {2, 4}) {
    c.level = level;
    const auto mesh = mesh::make_capsule_mesh(level, c.aspect_ratio);
    c.bending_modulus = 0.0;
    EXPECT_EQ(automatic_time_step(c, mesh),
              std::max(c.dt_accuracy, automatic_time_step(mesh, c.capillary_number, c.dt_factor)));
    for (double kb : {1e-3, 1e-1}) {
      c.bending_modulus = kb;
      const double dt = automatic_time_step(c, mesh);
      const double rho = c.rkc_safety * membrane_spectral_radius(mesh, mesh.nodes, c.capillary_number, 0.0, kb);
      const int stages = RkcIntegrator::stages_for(dt * rho, rkc.damping);
      std::printf("level %d κ_b %g: dt %.4g, %d stages at the reference\n", level, kb, dt, stages);
      EXPECT_LE(stages, rkc.max_stages / 2 + 1);
      EXPECT_LE(dt, c.dt_accuracy);
      if (level == 2) {
        EXPECT_EQ(dt, c.dt_accuracy) << "no cap needed on level 2";
      }
    }
  }
  c.level = 4;
  c.bending_modulus = 0.1;
  EXPECT_LT(automatic_time_step(c, mesh::make_capsule_mesh(4, c.aspect_ratio)), c.dt_accuracy) << "capped";
}

// The campaign's cost estimate takes its evaluations per unit time from evaluations_per_unit_time: on the
// reference shape they are exactly what the first step takes (rkc: the stages for the stiffness at rest;
// rk2: two per step), at the automatic dt or a set time.dt, with and without bending.
TEST(Rkc, EvaluationsPerUnitTimeAreWhatTheFirstStepAtRestTakes) {
  for (const config::TimeScheme scheme : {config::TimeScheme::Rkc, config::TimeScheme::Rk2})
    for (double Ca : {0.02, 0.5, 3.0})
      for (double kb : {0.0, 1e-3})
        for (double set_dt : {0.0, 0.004}) {
          config::CaseConfig c = make_case(1, Ca, 0.5);
          c.scheme = scheme;
          c.bending_modulus = kb;
          if (set_dt > 0) c.dt = set_dt;
          CapsuleFlow flow(c);
          const double h = mesh::min_node_spacing(flow.mesh(), flow.reference());
          const double dt = c.dt ? *c.dt : automatic_time_step(c, flow.mesh());
          EXPECT_EQ(dt, c.dt ? *c.dt : automatic_time_step(c, h));
          auto integrator = make_integrator(scheme, c.rkc_safety);
          Eigen::Matrix3Xd x = flow.reference();
          const StepInfo info = integrator->step(flow, x, dt);
          EXPECT_NEAR(evaluations_per_unit_time(c, h) * dt, info.evaluations, 1e-9)
              << config::word_of(scheme) << " Ca " << Ca << " κ_b " << kb << " dt " << dt;
        }
}

}  // namespace
}  // namespace capsim::dynamics
