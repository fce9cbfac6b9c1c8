#include "solver/dynamics/capsule_flow.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
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
  c.law = config::MembraneLawKind::NeoHookean;
  return c;
}

// The prolate level-2 scene of most tests here: a/b = 2, Ca = 0.3 (forward Euler at dt = 0.01 is stable).
config::CaseConfig prolate_case() {
  config::CaseConfig c;
  c.level = 2;
  c.aspect_ratio = 2.0;
  c.capillary_number = 0.3;
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
  config::CaseConfig c = prolate_case();
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
    config::CaseConfig c = prolate_case();
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

// A smooth asymmetric deformation of the reference: every target is evaluated, every load component non-zero.
Eigen::Matrix3Xd sheared_asymmetric(Eigen::Matrix3Xd x) {
  for (int i = 0; i < x.cols(); ++i) {
    const double x1 = x(0, i), x2 = x(1, i), x3 = x(2, i);
    x(0, i) = x1 * (1.0 + 0.08 * std::sin(1.3 * x2 + 0.4 * x3));
    x(1, i) = x2 + 0.05 * std::cos(x1) + 0.03 * x3;
  }
  return x;
}

void expect_same_evaluation(const FlowEvaluation& a, const FlowEvaluation& b) {
  EXPECT_EQ(a.max_speed, b.max_speed);
  EXPECT_EQ(a.volume_flux, b.volume_flux);
  EXPECT_EQ(a.used_symmetry, b.used_symmetry);
  EXPECT_EQ(a.used_central, b.used_central);
}

// The seam: a flow evaluation is boundary_velocity(x, membrane_load(x)), bitwise, on every path of the load solve
// (full, centrally symmetric, with bending), so an integrator composing the phases itself computes what velocity
// computes.
TEST(CapsuleFlow, VelocityIsTheCompositionOfItsPublicPhases) {
  struct Variant {
    const char* name;
    double bending_modulus;
    bool central;
  };
  for (const Variant& variant : {Variant{"elastic", 0.0, false}, Variant{"central", 0.0, true},
                                 Variant{"bending", 1e-2, true}}) {
    SCOPED_TRACE(variant.name);
    config::CaseConfig c = prolate_case();
    c.bending_modulus = variant.bending_modulus;
    c.central_symmetry = variant.central;
    CapsuleFlow flow(c);
    const Eigen::Matrix3Xd x = stretched(flow.reference());  // mirror and centrally symmetric, loaded
    Eigen::Matrix3Xd v, q, v_phases, q_phases;
    const FlowEvaluation whole = flow.velocity(x, v, &q);
    EXPECT_EQ(whole.used_central, variant.central);
    const membrane::MembraneState s = flow.membrane_load(x, q_phases);
    const FlowEvaluation phases = flow.boundary_velocity(x, q_phases, v_phases);
    EXPECT_EQ((q - q_phases).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ((v - v_phases).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(whole.tau_min, s.tau_min);
    EXPECT_EQ(whole.bending_energy, flow.last_bending().energy);
    expect_same_evaluation(whole, phases);
    EXPECT_EQ(flow.timings().evaluations, 1) << "only velocity counts as a flow evaluation";
  }
}

// The elastic and bending loads are the two parts of the membrane load: M⁻¹ is linear, so they sum to it to the
// load solve's relative tolerance (1e-12 per component, times the mass matrix's bounded condition number), and the
// bending part is a real part of it (κ_b = 1e-2 on a level-2 mesh); without bending the elastic load is the
// membrane load, bitwise (the same solve), and the bending load is zero.
TEST(CapsuleFlow, ElasticAndBendingLoadsSumToTheMembraneLoad) {
  config::CaseConfig c = prolate_case();
  {
    CapsuleFlow flow(c);
    const Eigen::Matrix3Xd x = sheared_asymmetric(flow.reference());
    Eigen::Matrix3Xd q, q_el, q_b;
    flow.membrane_load(x, q);
    flow.elastic_load(x, q_el);
    EXPECT_EQ(flow.bending_load(x, q_b).energy, 0.0);
    EXPECT_EQ((q - q_el).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(q_b.cols(), x.cols());
    EXPECT_EQ(q_b.cwiseAbs().maxCoeff(), 0.0);
  }
  c.bending_modulus = 1e-2;
  CapsuleFlow flow(c);
  const Eigen::Matrix3Xd x = sheared_asymmetric(flow.reference());
  Eigen::Matrix3Xd q, q_el, q_b;
  const membrane::MembraneState s = flow.membrane_load(x, q);
  const double energy = flow.last_bending().energy;
  const membrane::MembraneState s_el = flow.elastic_load(x, q_el);
  const membrane::BendingState& b = flow.bending_load(x, q_b);
  EXPECT_EQ(b.energy, energy);
  EXPECT_GT(b.energy, 0.0);
  EXPECT_EQ(s_el.tau_min, s.tau_min);
  const double scale = q.cwiseAbs().maxCoeff();
  const double split = (q_el + q_b - q).cwiseAbs().maxCoeff() / scale;
  std::printf("  |q_el + q_b - q| / max |q| = %.2e, max |q_b| / max |q| = %.2e\n", split,
              q_b.cwiseAbs().maxCoeff() / scale);
  EXPECT_LT(split, 1e-10);
  EXPECT_GT(q_b.cwiseAbs().maxCoeff(), 1e-3 * scale);
}

// With the background flow off, boundary_velocity is linear in q at fixed x (single layer and volume projection
// are): the property a linearly implicit step splitting the load relies on. Checked to round-off on an asymmetric
// scene (so that both loads take the same full evaluation).
TEST(CapsuleFlow, BoundaryVelocityIsLinearInTheLoadWithoutTheBackgroundFlow) {
  config::CaseConfig c = prolate_case();
  c.bending_modulus = 1e-2;
  CapsuleFlow flow(c);
  flow.set_background_flow(false);
  const Eigen::Matrix3Xd x = sheared_asymmetric(flow.reference());
  Eigen::Matrix3Xd q_el, q_b, v_el, v_b, v_sum;
  flow.elastic_load(x, q_el);
  flow.bending_load(x, q_b);
  const double a = 0.7, b = -1.9;
  EXPECT_FALSE(flow.boundary_velocity(x, q_el, v_el).used_symmetry);
  flow.boundary_velocity(x, q_b, v_b);
  flow.boundary_velocity(x, a * q_el + b * q_b, v_sum);
  const double rel = (a * v_el + b * v_b - v_sum).cwiseAbs().maxCoeff() / v_sum.cwiseAbs().maxCoeff();
  std::printf("  linearity defect of boundary_velocity: %.2e\n", rel);
  EXPECT_LT(rel, 1e-13);
}

// A SecondKindSolve (the viscosity contrast's place in the evaluation) sits between the single layer and the volume
// correction: it receives f = v∞ − S[q]/(8πCa), the volume correction acts on its result (whose flux is reported),
// and begin_step reaches it. A solve that returns f leaves the evaluation bitwise the λ = 1 one.
class ScaledSolve final : public SecondKindSolve {
 public:
  explicit ScaledSolve(double factor) : factor_(factor) {}
  void solve(const Eigen::Matrix3Xd&, const Eigen::Matrix3Xd& f, Eigen::Matrix3Xd& v) override {
    last_f = f;
    v = factor_ * f;
  }
  void begin_step() override { ++steps; }
  Eigen::Matrix3Xd last_f;
  int steps = 0;

 private:
  double factor_;
};

TEST(CapsuleFlow, SecondKindSolveSitsBetweenTheSingleLayerAndTheVolumeCorrection) {
  config::CaseConfig c = prolate_case();
  CapsuleFlow plain(c), identity(c), halved(c);
  identity.set_second_kind_solve(std::make_unique<ScaledSolve>(1.0));
  auto solve = std::make_unique<ScaledSolve>(0.5);
  ScaledSolve& seen = *solve;
  halved.set_second_kind_solve(std::move(solve));
  const Eigen::Matrix3Xd x = sheared_asymmetric(plain.reference());
  Eigen::Matrix3Xd v, v_identity, v_halved;
  const FlowEvaluation e = plain.velocity(x, v);
  const FlowEvaluation e_identity = identity.velocity(x, v_identity);
  EXPECT_EQ((v - v_identity).cwiseAbs().maxCoeff(), 0.0);
  expect_same_evaluation(e, e_identity);

  const FlowEvaluation e_halved = halved.velocity(x, v_halved);
  c.volume_correction = false;
  CapsuleFlow uncorrected(c);
  Eigen::Matrix3Xd f;
  uncorrected.velocity(x, f);
  EXPECT_EQ((seen.last_f - f).cwiseAbs().maxCoeff(), 0.0) << "the solve's right-hand side is the λ = 1 velocity";
  EXPECT_NEAR(e_halved.volume_flux, 0.5 * e.volume_flux, 1e-15 * std::abs(e.volume_flux));
  EXPECT_NE(e.volume_flux, 0.0);
  // v = P[f/2] = P[f]/2: the volume correction is linear, applied once, after the solve.
  EXPECT_LT((v_halved - 0.5 * v).cwiseAbs().maxCoeff(), 1e-15 * v.cwiseAbs().maxCoeff());
  halved.begin_step();
  EXPECT_EQ(seen.steps, 1);
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
    config::CaseConfig c = dynamics::prolate_case();
    c.kernel_precision = precision;
    dynamics::CapsuleFlow flow(c);
    const Eigen::Matrix3Xd x = dynamics::sheared_asymmetric(flow.reference());  // all targets, non-trivial loads
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

// Any orientation rotated by a symmetry of the flow gives the rotated answer (solver/README.md, Orientation). The shear
// v∞ = (x2, 0, 0) is invariant under the half-turn about the vorticity axis, R = diag(−1, −1, 1): R v∞(x) = v∞(R x).
// (The mirror x3 → −x3 and the point symmetry x → −x are its other symmetries, but they are reflections: applied to
// node positions alone they turn the surface inside out, so the half-turn, their product, is the one a mesh can
// carry.) A capsule whose stress-free shape is tilted out of the plane (capsule.tilt, capsule.azimuth), deformed
// with no symmetry left, evaluated at x and at R x on the general path, must give velocities v(R x) = R v(x) and the
// same membrane tension; at λ = 1 and at λ = 5 (the double layer and its GMRES solve), in double and mixed precision.
// The half-turn only flips signs, which every kernel, quadrature and inner product carries exactly, so the
// difference is round-off at most (measured: 0, bitwise, in all three variants; asserted to 1e-12).
TEST(CapsuleFlow, AnyOrientationTurnedByTheFlowsHalfTurnGivesTheTurnedVelocity) {
  struct Variant {
    const char* precision;
    double viscosity_ratio;
  };
  for (const Variant variant : {Variant{"double", 1.0}, Variant{"mixed", 1.0}, Variant{"double", 5.0}}) {
    SCOPED_TRACE(std::string(variant.precision) + ", λ = " + std::to_string(variant.viscosity_ratio));
    config::CaseConfig c = dynamics::prolate_case();
    c.kernel_precision = variant.precision;
    c.viscosity_ratio = variant.viscosity_ratio;
    c.tilt = 30.0;
    c.azimuth = 20.0;
    // Two flows, so that each solve starts cold: at λ ≠ 1 a flow warm-starts GMRES from its previous velocity,
    // which for the turned scene would be the unturned answer (a different start, the same answer only to the
    // GMRES tolerance: 3e-9 measured).
    dynamics::CapsuleFlow flow(c), turned_flow(c);
    const Eigen::Matrix3Xd x = dynamics::sheared_asymmetric(flow.reference());
    const Eigen::Matrix3d R = Eigen::Vector3d(-1.0, -1.0, 1.0).asDiagonal();
    const Eigen::Matrix3Xd xr = R * x;
    Eigen::Matrix3Xd v, vr;
    const dynamics::FlowEvaluation e = flow.velocity(x, v);
    const dynamics::FlowEvaluation er = turned_flow.velocity(xr, vr);
    EXPECT_FALSE(e.used_symmetry) << "a tilted, asymmetric scene takes the general path";
    EXPECT_FALSE(er.used_symmetry);
    const double scale = v.cwiseAbs().maxCoeff();
    const double diff = (vr - R * v).cwiseAbs().maxCoeff() / scale;
    std::printf("half-turn about x3 (%s, λ = %g): max |v(Rx) − R v(x)| / max |v| = %.3e; τmin %.17g and %.17g\n",
                variant.precision, variant.viscosity_ratio, diff, e.tau_min, er.tau_min);
    EXPECT_GT(scale, 0.1) << "a sheared, loaded capsule moves";
    EXPECT_LT(diff, 1e-12);
    EXPECT_NEAR(er.tau_min, e.tau_min, 1e-12 * std::max(1.0, std::abs(e.tau_min)));
    EXPECT_NEAR(er.volume_flux, e.volume_flux, 1e-12);
  }
}

}  // namespace
}  // namespace capsim
