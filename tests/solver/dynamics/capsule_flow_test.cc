#include "solver/dynamics/capsule_flow.h"

#include <omp.h>

#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "solver/dynamics/time_stepper.h"
#include "solver/membrane/membrane_mechanics.h"

namespace capsim::dynamics {
namespace {

config::CaseConfig sphere_case(int level, double Ca) {
  config::CaseConfig c;
  c.aspect_ratio = 1.0;
  c.level = level;
  c.capillary_number = Ca;
  c.law = "neo-hookean";
  return c;
}

// The reference stretched by 15 % along x1 at constant volume (x2, x3 shrunk by 1/√1.15): a loaded membrane
// that keeps the mirror symmetry.
Eigen::Matrix3Xd stretched(Eigen::Matrix3Xd x) {
  x.row(0) *= 1.15;
  x.row(1) /= std::sqrt(1.15);
  x.row(2) /= std::sqrt(1.15);
  return x;
}

// Sign of the coupling (solver/README.md §3): a capsule stretched away from its reference shape in fluid at rest
// must relax back, its elastic energy decreasing monotonically towards zero.
TEST(CapsuleFlow, StretchedCapsuleRelaxesInFluidAtRest) {
  CapsuleFlow flow(sphere_case(2, 0.1));
  flow.set_background_flow(false);
  Eigen::Matrix3Xd x = stretched(flow.reference());
  const double dt = automatic_time_step(flow.mesh(), 0.1, 0.2);
  Rk2Integrator rk;
  double energy = flow.mechanics().energy(x);
  const double e0 = energy;
  for (int step = 0; step < 200; ++step) {
    rk.step(flow, x, dt);
    const double e = flow.mechanics().energy(x);
    ASSERT_LE(e, energy * (1.0 + 1e-9)) << "energy must not grow, step " << step;
    energy = e;
  }
  EXPECT_LT(energy, 0.05 * e0) << "the capsule must relax towards its reference shape";
  // Elongation along x1 shrinks back towards the sphere.
  EXPECT_LT(x.row(0).maxCoeff(), 1.15);
}

// Rigid body motion in the shear flow: the reference sphere has no load, so it moves with v∞.
TEST(CapsuleFlow, UnloadedCapsuleMovesWithTheUndisturbedFlow) {
  CapsuleFlow flow(sphere_case(2, 0.3));
  Eigen::Matrix3Xd v;
  const auto ev = flow.velocity(flow.reference(), v);
  for (int i = 0; i < v.cols(); ++i) {
    EXPECT_NEAR(v(0, i), flow.reference()(1, i), 1e-12);
    EXPECT_NEAR(v(1, i), 0.0, 1e-12);
    EXPECT_NEAR(v(2, i), 0.0, 1e-12);
  }
  EXPECT_LT(ev.max_speed, 1e-12);
}

// numerics.far_degree / far_radius reach the single layer: the velocity of a loaded capsule changes, by
// about the far-field error of the boundary integral (~1e-4 relative at level 2, degree 2, radius 4).
TEST(CapsuleFlow, FarFieldKeysReachTheBoundaryIntegral) {
  config::CaseConfig c = sphere_case(2, 0.1);
  CapsuleFlow off(c);
  c.far_degree = 2;
  CapsuleFlow on(c);
  off.set_background_flow(false);
  on.set_background_flow(false);
  const Eigen::Matrix3Xd x = stretched(off.reference());
  Eigen::Matrix3Xd v_off, v_on;
  off.velocity(x, v_off);
  on.velocity(x, v_on);
  const double rel = (v_on - v_off).cwiseAbs().maxCoeff() / v_off.cwiseAbs().maxCoeff();
  std::printf("  far_degree 2 vs 0: max |dv| / max |v| = %.2e\n", rel);
  EXPECT_GT(rel, 0.0);
  EXPECT_LT(rel, 1e-3);
}

// numerics.kernel_precision = "mixed" reaches the boundary integral (the velocity moves by ~1e-7 relative, far
// below the level's discretisation error) and a capsule that starts in the shear plane keeps the mirror
// symmetry step after step, so every evaluation stays the half-target one (without the on-plane fix of
// SingleLayer::mirror it was lost after the first few steps).
TEST(CapsuleFlow, MixedPrecisionKeepsTheSymmetricEvaluation) {
  config::CaseConfig c;
  c.level = 2;
  c.aspect_ratio = 2.0;
  c.capillary_number = 0.3;
  CapsuleFlow dbl(c);
  c.kernel_precision = "mixed";
  CapsuleFlow mix(c);
  Eigen::Matrix3Xd x = stretched(mix.reference()), v, vd;  // still mirror-symmetric, the membrane loaded
  mix.velocity(x, v);
  dbl.velocity(x, vd);
  const double rel = (v - vd).cwiseAbs().maxCoeff() / vd.cwiseAbs().maxCoeff();
  std::printf("  mixed vs double, stretched capsule: max |dv| / max |v| = %.2e\n", rel);
  EXPECT_GT(rel, 0.0);
  EXPECT_LT(rel, 1e-5);
  for (int step = 0; step < 40; ++step) {  // forward Euler, dt = 0.01: the shear flow deforms the capsule
    const FlowEvaluation e = mix.velocity(x, v);
    ASSERT_TRUE(e.used_symmetry) << "step " << step;
    x += 0.01 * v;
  }
}

// numerics.central_symmetry: a capsule that starts in the shear plane keeps the mirror and the point symmetry
// x → −x step after step when each step ends with the driver's symmetrisation (mesh::symmetrise), so every
// evaluation is the quarter-target one, in mixed precision too; and the velocity is the mirror-only flow's
// to the kernel's accuracy (double: round-off; mixed: its 3e-7).
TEST(CapsuleFlow, CentralSymmetryIsKeptStepAfterStep) {
  for (const std::string precision : {"double", "mixed"}) {
    config::CaseConfig c;
    c.level = 2;
    c.aspect_ratio = 2.0;
    c.capillary_number = 0.3;  // forward Euler at dt = 0.01 is stable here (MixedPrecisionKeepsTheSymmetricEvaluation)
    c.kernel_precision = precision;
    CapsuleFlow mirror(c);
    c.central_symmetry = true;
    CapsuleFlow central(c);
    Eigen::Matrix3Xd x = stretched(central.reference()), v, vm;
    for (int step = 0; step < 40; ++step) {  // forward Euler, dt = 0.01: sheared and stretched
      const FlowEvaluation e = central.velocity(x, v);
      ASSERT_TRUE(e.used_central) << precision << ", step " << step;
      ASSERT_TRUE(e.used_symmetry) << precision << ", step " << step;
      if (step % 13 == 0) {
        mirror.velocity(x, vm);
        const double rel = (v - vm).cwiseAbs().maxCoeff() / vm.cwiseAbs().maxCoeff();
        EXPECT_LT(rel, precision == "double" ? 1e-12 : 1e-5) << precision << ", step " << step;
      }
      x += 0.01 * v;
      mesh::symmetrise(central.mesh(), x, true, true);
    }
  }
}

}  // namespace
}  // namespace capsim::dynamics

namespace capsim {
namespace {

// The evaluation's parallel phases (membrane, assembly, CG, layout, corrections, flux) keep every sum in an
// order that does not depend on the thread count, so that a case gives bitwise the same answer on any
// number of threads (and a campaign's results do not depend on its layout). A parallel reduction in any
// of them would break this test.
TEST(CapsuleFlow, VelocityIsBitwiseTheSameOnOneAndTwoThreads) {
  for (const char* precision : {"double", "mixed"}) {  // sum_mixed too: each target's sum is one thread's
    SCOPED_TRACE(precision);
    config::CaseConfig c;
    c.level = 2;
    c.aspect_ratio = 2.0;
    c.capillary_number = 0.3;
    c.kernel_precision = precision;
    dynamics::CapsuleFlow flow(c);
    Eigen::Matrix3Xd x = flow.reference();
    for (int i = 0; i < x.cols(); ++i) {  // smooth and asymmetric: all targets, non-trivial loads
      const double x1 = x(0, i), x2 = x(1, i), x3 = x(2, i);
      x(0, i) = x1 * (1.0 + 0.08 * std::sin(1.3 * x2 + 0.4 * x3));
      x(1, i) = x2 + 0.05 * std::cos(x1) + 0.03 * x3;
    }
    const int before = omp_get_max_threads();
    Eigen::Matrix3Xd v1, v2, q1, q2;
    omp_set_num_threads(1);
    const dynamics::FlowEvaluation e1 = flow.velocity(x, v1, &q1);
    omp_set_num_threads(2);
    const dynamics::FlowEvaluation e2 = flow.velocity(x, v2, &q2);
    omp_set_num_threads(before);
    EXPECT_EQ((q1 - q2).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ((v1 - v2).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(e1.tau_min, e2.tau_min);
    EXPECT_EQ(e1.volume_flux, e2.volume_flux);
  }
}

}  // namespace
}  // namespace capsim
