// The automatic rk2 time step with a viscosity ratio (label `validation`; minutes: every evaluation solves the
// second-kind equation): the stiffness scales as viscosity_stiffness_factor(λ) = 2/(1 + λ), and the automatic dt
// inversely (5.5 times larger at λ = 10, 1.8 times smaller at λ = 0.1). As for λ = 1 (time_stepper_test.cc): rk2 in
// shear flow at the automatic dt survives 200 steps with the stiffest modes excited; at twice that dt it blows up.
#include <gtest/gtest.h>

#include "tests/solver/dynamics/stability_probe.h"

namespace capsim::dynamics {
namespace {

TEST(Rk2Stability, AutomaticTimeStepFollowsTheViscosityRatio) {
  const double Ca = 0.05;
  for (double lambda : {0.1, 10.0}) {
    config::CaseConfig c = make_case(2, Ca, 1.0);
    c.scheme = config::TimeScheme::Rk2;
    c.viscosity_ratio = lambda;
    CapsuleFlow flow(c);
    const Eigen::Matrix3Xd x0 = perturbed_reference(flow);
    const double dt = automatic_time_step(c, flow.mesh());
    EXPECT_DOUBLE_EQ(dt, automatic_time_step(flow.mesh(), Ca, kDefaultFactor) / viscosity_stiffness_factor(lambda));
    Rk2Integrator rk;
    EXPECT_EQ(steps_until_blow_up(rk, flow, x0, dt, 200), 200) << "λ = " << lambda;
    EXPECT_LT(steps_until_blow_up(rk, flow, x0, 2.0 * dt, 200), 200) << "λ = " << lambda;
  }
}

}  // namespace
}  // namespace capsim::dynamics
