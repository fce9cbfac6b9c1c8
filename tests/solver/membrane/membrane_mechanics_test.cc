#include "solver/membrane/membrane_mechanics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <utility>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "solver/membrane/load_solver.h"
#include "tests/solver/membrane/deformations.h"

namespace capsim::membrane {
namespace {

using Eigen::Matrix3Xd;

using testing::smooth_deformation;

TEST(AreaVolume, SphereConvergesUnderRefinement) {
  double prev_a = 0, prev_v = 0;
  std::printf("%5s %14s %14s %8s %8s\n", "level", "area err", "volume err", "order A", "order V");
  for (int level = 0; level <= 4; ++level) {
    const auto m = mesh::make_sphere_mesh(level);
    const auto av = area_and_volume(m, m.nodes);
    const double ea = std::abs(av.area - 4 * std::numbers::pi), ev = std::abs(av.volume - 4 * std::numbers::pi / 3);
    // h halves per level: order = log2(e_{l-1}/e_l).
    const double oa = level ? std::log2(prev_a / ea) : 0.0, ov = level ? std::log2(prev_v / ev) : 0.0;
    std::printf("%5d %14.3e %14.3e %8.2f %8.2f\n", level, ea, ev, oa, ov);
    if (level >= 2) {
      EXPECT_GT(oa, 3.5) << "P2 surfaces should converge at about fourth order";
      EXPECT_GT(ov, 3.5);
    }
    prev_a = ea;
    prev_v = ev;
  }
}

TEST(AreaVolume, SpheroidEnclosesUnitSphereVolume) {
  for (double r : {0.5, 2.0}) {
    const auto m = mesh::make_capsule_mesh(4, r);
    EXPECT_NEAR(area_and_volume(m, m.nodes).volume, 4 * std::numbers::pi / 3, 2e-5) << "a/b=" << r;
  }
}

class MembraneLaws : public ::testing::TestWithParam<config::MembraneLawKind> {};

TEST_P(MembraneLaws, RigidMotionGivesNoForce) {
  const auto law = make_law(GetParam(), 1.0);
  const auto m = mesh::make_capsule_mesh(2, 2.0);
  const MembraneMechanics mech(m, m.nodes, *law);
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -1.0, 0.5).normalized()).toRotationMatrix();
  const Matrix3Xd x = (Q * m.nodes).colwise() + Eigen::Vector3d(0.4, -2.0, 1.5);
  const auto s = mech.evaluate(x);
  // Force and load scales of a 10% deformation for comparison.
  const Matrix3Xd deformed = smooth_deformation(m.nodes, 0.1);
  const auto ref_state = mech.evaluate(deformed);
  const double scale = ref_state.internal_force.cwiseAbs().maxCoeff();
  LoadSolver ref_solver(m);
  Matrix3Xd q_ref;
  ref_solver.compute_load(deformed, ref_state.internal_force, q_ref);
  const double q_scale = q_ref.cwiseAbs().maxCoeff();
  // Round-off bound: positions of size |x| ≈ 2.5 on elements h ≈ 0.1 carry a strain error ε|x|/h ≈ 5e-15,
  // i.e. ≈ 5e-14 of the 10% deformation; the mass-matrix solve amplifies it by its condition number (~10).
  EXPECT_LT(s.internal_force.cwiseAbs().maxCoeff(), 1e-12 * scale);
  EXPECT_NEAR(s.energy, 0.0, 1e-13);
  EXPECT_NEAR(s.tau_min, 0.0, 1e-12);
  EXPECT_NEAR(s.tau_max, 0.0, 1e-12);
  LoadSolver solver(m);
  Matrix3Xd q;
  solver.compute_load(x, s.internal_force, q);
  EXPECT_LT(q.cwiseAbs().maxCoeff(), 1e-11 * q_scale);
}

TEST_P(MembraneLaws, ForcesAreTheGradientOfTheEnergy) {
  const auto law = make_law(GetParam(), 1.0);
  const auto m = mesh::make_capsule_mesh(1, 2.0);
  const MembraneMechanics mech(m, m.nodes, *law);
  Matrix3Xd x = smooth_deformation(m.nodes, 0.3);
  const auto s = mech.evaluate(x);
  const double h = 1e-6;
  for (int node : {0, 7, 25, 60, 100, 161}) {
    for (int c = 0; c < 3; ++c) {
      const double keep = x(c, node);
      x(c, node) = keep + h;
      const double wp = mech.energy(x);
      x(c, node) = keep - h;
      const double wm = mech.energy(x);
      x(c, node) = keep;
      const double fd = (wp - wm) / (2 * h);
      EXPECT_NEAR(s.internal_force(c, node), fd, 1e-7 * (1.0 + std::abs(fd))) << "node " << node << " comp " << c;
    }
  }
}

// Inflated sphere x = λX: the load is normal and uniform with Laplace's value q·n = 2τ(λ)/(λ R0).
TEST_P(MembraneLaws, InflatedSphereObeysLaplaceLaw) {
  const auto law = make_law(GetParam(), 1.0);
  const double lambda = 1.1;
  const double tau = law->tensions(lambda, lambda)[0];
  const double expected = 2.0 * tau / lambda;
  if (GetParam() == config::MembraneLawKind::NeoHookean) {
    EXPECT_NEAR(tau, 1.0 - std::pow(lambda, -6), 1e-14);
  }
  std::printf("%s, lambda = %.2f, q.n exact = %.6f\n%5s %14s %14s %8s\n", config::word_of(GetParam()).data(), lambda, expected,
              "level", "max |q.n-p|/p", "max |q_t|/p", "order");
  double prev = 0.0;
  for (int level = 0; level <= 4; ++level) {
    const auto m = mesh::make_sphere_mesh(level);
    const MembraneMechanics mech(m, m.nodes, *law);
    const Matrix3Xd x = lambda * m.nodes;
    const auto s = mech.evaluate(x);
    LoadSolver solver(m);
    Matrix3Xd q;
    solver.compute_load(x, s.internal_force, q);
    double err_n = 0.0, err_t = 0.0;
    for (int i = 0; i < m.num_nodes(); ++i) {
      const Eigen::Vector3d n = m.nodes.col(i);  // outward normal of the sphere
      const double qn = q.col(i).dot(n);
      err_n = std::max(err_n, std::abs(qn - expected) / expected);
      err_t = std::max(err_t, (q.col(i) - qn * n).norm() / expected);
    }
    const double order = level ? std::log2(prev / err_n) : 0.0;
    std::printf("%5d %14.3e %14.3e %8.2f\n", level, err_n, err_t, order);
    if (level >= 2) {
      EXPECT_GT(order, 1.5) << "Laplace error must fall under refinement";
    }
    if (level >= 3) {
      EXPECT_LT(err_t, err_n) << "the load must be essentially normal";
    }
    prev = err_n;
  }
}

INSTANTIATE_TEST_SUITE_P(Laws, MembraneLaws, ::testing::Values(config::MembraneLawKind::NeoHookean, config::MembraneLawKind::Skalak));

TEST(MembraneMechanics, PrincipalStretchesOfAnAffineStretch) {
  const auto m = mesh::make_sphere_mesh(2);
  const NeoHookeanLaw law;
  const MembraneMechanics mech(m, m.nodes, law);
  const auto st = mech.principal_stretches(1.3 * m.nodes);
  for (const auto& s : st) {
    EXPECT_NEAR(s[0], 1.3, 1e-12);
    EXPECT_NEAR(s[1], 1.3, 1e-12);
  }
}

TEST(MembraneMechanics, DegenerateElementsAreReported) {
  auto m = mesh::make_sphere_mesh(1);
  const NeoHookeanLaw law;
  Matrix3Xd bad = m.nodes;
  const auto& e = m.elements[3];
  for (int a = 0; a < 6; ++a) bad.col(e[a]) = m.nodes.col(e[0]);  // element 3 collapsed to a point
  EXPECT_THROW(MembraneMechanics(m, bad, law), std::invalid_argument);
  const MembraneMechanics mech(m, m.nodes, law);
  EXPECT_THROW((void)mech.evaluate(bad), DegenerateSurface);
  Matrix3Xd nan = m.nodes;
  nan(0, 5) = std::nan("");
  EXPECT_THROW((void)mech.evaluate(nan), DegenerateSurface);
}

TEST(LoadSolver, CholmodAndConjugateGradientAgree) {
  const auto m = mesh::make_capsule_mesh(2, 2.0);
  const SkalakLaw law(1.0);
  const MembraneMechanics mech(m, m.nodes, law);
  const Matrix3Xd x = smooth_deformation(m.nodes, 0.2);
  const auto s = mech.evaluate(x);
  LoadSolver direct(m, {LoadSolver::Backend::Cholmod, 6, 1e-12});
  LoadSolver cg(m, {LoadSolver::Backend::ConjugateGradient, 6, 1e-13});
  Matrix3Xd q1, q2;
  direct.compute_load(x, s.internal_force, q1);
  cg.compute_load(x, s.internal_force, q2);
  EXPECT_LT((q1 - q2).cwiseAbs().maxCoeff(), 1e-9 * q1.cwiseAbs().maxCoeff());
  EXPECT_GT(cg.last_iterations(), 0);
  // The mass matrix integrates 1: Σ_ab M_ab = area.
  EXPECT_NEAR(direct.mass_matrix().sum(), area_and_volume(m, x).area, 1e-12);
}

// The flow evaluations skip the energy (MembraneMechanics::evaluate's with_energy): the forces and tensions must be
// bitwise those of the full evaluation, and the energy must not pass for a number.
TEST(MembraneMechanics, EvaluationWithoutEnergyHasTheSameForcesAndTensions) {
  const auto m = mesh::make_capsule_mesh(2, 0.5);
  for (const bool skalak : {false, true}) {
    const NeoHookeanLaw nh;
    const SkalakLaw sk(1.0);
    const MembraneLaw& law = skalak ? static_cast<const MembraneLaw&>(sk) : nh;
    const MembraneMechanics mech(m, m.nodes, law);
    const Matrix3Xd x = smooth_deformation(m.nodes, 0.3);
    const MembraneState full = mech.evaluate(x), lean = mech.evaluate(x, false);
    EXPECT_TRUE(full.internal_force == lean.internal_force) << (skalak ? "Skalak" : "NH");
    EXPECT_EQ(full.tau_min, lean.tau_min);
    EXPECT_EQ(full.tau_max, lean.tau_max);
    EXPECT_GT(full.energy, 0.0);
    EXPECT_TRUE(std::isnan(lean.energy));
  }
}

// The centrally symmetric evaluation (numerics.central_symmetry): half the elements, their images negated on the
// image nodes. On a large deformation that is odd under x → −x (the spheroid's reference has the symmetry to
// round-off) it gives evaluate()'s forces and tensions to round-off, forces exactly odd element by element; an
// off-plane tilt keeps it (the point symmetry does not need the mirror).
TEST(MembraneMechanics, SymmetricEvaluationHasTheSameForcesAndTensions) {
  const auto m = mesh::make_capsule_mesh(2, 0.5);
  const SkalakLaw law(1.0);
  const MembraneMechanics mech(m, m.nodes, law);
  ASSERT_TRUE(mech.has_central_map());
  for (const auto& [mirror, central] : {std::pair{false, true}, std::pair{true, false}, std::pair{true, true}}) {
    SCOPED_TRACE(std::string(mirror ? "mirror " : "") + (central ? "central" : ""));
    Matrix3Xd x = m.nodes;
    for (int i = 0; i < x.cols(); ++i) {
      const double a = m.nodes(0, i), b = m.nodes(1, i), c = m.nodes(2, i);
      x(0, i) = 1.25 * a + 0.3 * b + 0.1 * a * b * b + (central ? 0.0 : 0.07 * b * b);  // b² breaks x → −x
      x(1, i) = 0.85 * b - 0.2 * a * a * a + 0.03 * b * c * c;
      x(2, i) = 0.95 * c + (mirror ? 0.05 * a * b * c : 0.15 * a);  // the tilt 0.15 a breaks the mirror
    }
    mesh::symmetrise(m, x, mirror, central);
    const MembraneState full = mech.evaluate(x), reduced = mech.evaluate_symmetric(x, true, mirror, central);
    const double scale = full.internal_force.cwiseAbs().maxCoeff();
    const double diff = (reduced.internal_force - full.internal_force).cwiseAbs().maxCoeff() / scale;
    // The noise floor: how far the full evaluation itself is from equivariant (its sums for node i and its images
    // run in different element orders on a reference symmetric only to round-off).
    double defect = 0.0;
    for (int i = 0; i < x.cols(); ++i) {
      if (central)
        defect = std::max(defect, (full.internal_force.col(i) + full.internal_force.col(m.central_node[i])).cwiseAbs().maxCoeff());
      if (mirror) {
        const Eigen::Vector3d image(full.internal_force(0, i), full.internal_force(1, i), -full.internal_force(2, i));
        defect = std::max(defect, (full.internal_force.col(m.mirror_node[i]) - image).cwiseAbs().maxCoeff());
      }
    }
    defect /= scale;
    std::printf("  %s%s vs full membrane forces: max diff / max |R| = %.2e; full evaluation's own defect %.2e\n",
                mirror ? "mirror " : "", central ? "central" : "", diff, defect);
    EXPECT_GT(diff, 0.0);  // the images are not computed: the sums differ in the last bits
    EXPECT_GT(defect, 0.0);
    // Both evaluations carry the round-off of those nodal sums (1e-13 here: element forces that largely cancel),
    // which the full one's defect measures; a wrong image element, local permutation or sign gives O(1).
    EXPECT_LE(diff, 2.0 * defect);
    EXPECT_NEAR(reduced.tau_min, full.tau_min, 1e-13 * std::abs(full.tau_min));
    EXPECT_NEAR(reduced.tau_max, full.tau_max, 1e-13 * std::abs(full.tau_max));
    EXPECT_NEAR(reduced.energy, full.energy, 1e-13 * full.energy);
  }
  Matrix3Xd x = m.nodes;
  mesh::symmetrise(m, x, false, true);
  const MembraneState full = mech.evaluate(x);
  // A mesh without the central map: the plain evaluation.
  mesh::SurfaceMesh plain = m;
  plain.central_node.clear();
  const MembraneMechanics no_map(plain, plain.nodes, law);
  EXPECT_FALSE(no_map.has_central_map());
  EXPECT_TRUE(no_map.evaluate_centrally_symmetric(x).internal_force == full.internal_force);
}

// The load of a symmetric state solved for one node of each orbit of its symmetries (the mirror x3 → −x3, the point
// reflection x → −x of numerics.central_symmetry, or both): the full solve's q to the CG tolerance, exactly
// equivariant (q3 = 0 on the mirror plane), meeting the full residual test, with a half or a quarter of the
// unknowns; cold and warm-started.
TEST(LoadSolver, SymmetryReducedSolveGivesTheFullSolvesLoad) {
  const auto m = mesh::make_capsule_mesh(2, 2.0);
  const SkalakLaw law(1.0);
  const MembraneMechanics mech(m, m.nodes, law);
  for (const auto& [mirror, central] : {std::pair{false, true}, std::pair{true, false}, std::pair{true, true}}) {
    SCOPED_TRACE(std::string(mirror ? "mirror " : "") + (central ? "central" : ""));
    Matrix3Xd x0 = m.nodes, x1;
    for (int i = 0; i < x0.cols(); ++i) {
      const double a = m.nodes(0, i), b = m.nodes(1, i), c = m.nodes(2, i);
      // Odd in (a, b) and even in c for x1, x2, odd in c for x3: a map with both symmetries, and with the mirror
      // alone once an even term breaks x → −x.
      x0(0, i) = 1.2 * a + 0.3 * b + 0.1 * a * b * b + 0.05 * a * c * c + (central ? 0.0 : 0.08 * b * b);
      x0(1, i) = 0.85 * b - 0.2 * a * a * a + 0.04 * b * c * c;
      x0(2, i) = 0.95 * c + (mirror ? 0.1 * a * a * c : 0.15 * a);
    }
    mesh::symmetrise(m, x0, mirror, central);
    ASSERT_EQ(mesh::is_mirror_symmetric(m, x0, 1e-12), mirror);
    ASSERT_EQ(mesh::is_centrally_symmetric(m, x0, 1e-12), central);
    x1 = 1.001 * x0;
    const double tol = 1e-10;
    LoadSolver::Options o;
    o.cg_tolerance = tol;
    LoadSolver full(m, o), reduced(m, o);
    auto force = [&](const Matrix3Xd& x) {
      return central ? mech.evaluate_centrally_symmetric(x).internal_force : mech.evaluate(x).internal_force;
    };
    for (const bool warm : {false, true}) {
      Matrix3Xd qf, qr;
      if (warm) {  // the guess: the load of a nearby state, as the previous stage's
        const Matrix3Xd R0 = force(x0);
        full.compute_load(x0, R0, qf);
        reduced.compute_load_symmetric(x0, R0, qr, false, mirror, central);
      }
      const Matrix3Xd R = force(x1);
      full.compute_load(x1, R, qf, warm);
      const int full_iterations = full.last_iterations();
      reduced.compute_load_symmetric(x1, R, qr, warm, mirror, central);
      const double scale = qf.cwiseAbs().maxCoeff();
      const double diff = (qr - qf).cwiseAbs().maxCoeff() / scale;
      std::printf("  %s%s, %s: reduced vs full load, max diff / max |q| = %.2e (CG iterations %d and %d)\n",
                  mirror ? "mirror " : "", central ? "central" : "", warm ? "warm" : "cold", diff,
                  reduced.last_iterations(), full_iterations);
      // Both stop at |R − M q| ≤ tol |R|; the load error is about the residual times the condition number (≈ 10).
      EXPECT_LT(diff, 1e3 * tol);
      EXPECT_GT(reduced.last_iterations(), 0);
      for (int i = 0; i < m.num_nodes(); ++i) {
        if (central)
          for (int c = 0; c < 3; ++c) ASSERT_EQ(qr(c, m.central_node[i]), -qr(c, i));
        if (mirror) {
          const int j = m.mirror_node[i];
          ASSERT_EQ(qr(0, j), qr(0, i));
          ASSERT_EQ(qr(1, j), qr(1, i));
          ASSERT_EQ(qr(2, j), -qr(2, i));
          if (j == i) ASSERT_EQ(qr(2, i), 0.0);
        }
      }
      // The reduced solution meets the full residual test: |R − M q| ≤ tol |R| per component (M of x1).
      const Matrix3Xd res = R - qr * full.mass_matrix();
      for (int c = 0; c < 3; ++c) EXPECT_LE(res.row(c).norm(), 1.01 * tol * R.row(c).norm()) << "component " << c;
    }
  }
}

// numerics.load_warm_start: CG on the correction to a guess stops at the same residual |R − M q| ≤ tol |R|
// as a cold solve, so it gives the cold answer to the tolerance, in fewer iterations when the guess is close
// (the previous stage's load), and the exact guess needs no more than one iteration per component.
TEST(LoadSolver, WarmStartMeetsTheColdResidualInFewerIterations) {
  const auto m = mesh::make_capsule_mesh(2, 2.0);
  const SkalakLaw law(1.0);
  const MembraneMechanics mech(m, m.nodes, law);
  const double tol = 1e-10;
  const Matrix3Xd x0 = smooth_deformation(m.nodes, 0.2), x1 = smooth_deformation(m.nodes, 0.201);
  const Matrix3Xd R0 = mech.evaluate(x0).internal_force, R1 = mech.evaluate(x1).internal_force;
  LoadSolver direct(m, {LoadSolver::Backend::Cholmod, 6, 1e-12});
  LoadSolver cg(m, {LoadSolver::Backend::ConjugateGradient, 6, tol});
  Matrix3Xd exact1, cold1, q;
  direct.compute_load(x1, R1, exact1);
  cg.compute_load(x1, R1, cold1);
  const int cold_iterations = cg.last_iterations();
  cg.compute_load(x0, R0, q);    // the previous "stage"
  cg.compute_load(x1, R1, q, true);  // warm from it
  const int warm_iterations = cg.last_iterations();
  EXPECT_LT(warm_iterations, cold_iterations);
  EXPECT_GT(warm_iterations, 0);
  const Matrix3Xd residual = R1 - q * cg.mass_matrix();
  for (int c = 0; c < 3; ++c) EXPECT_LE(residual.row(c).norm(), tol * R1.row(c).norm()) << "component " << c;
  const double scale = exact1.cwiseAbs().maxCoeff();
  EXPECT_LT((q - exact1).cwiseAbs().maxCoeff(), 1e3 * tol * scale);
  EXPECT_LT((q - cold1).cwiseAbs().maxCoeff(), 1e3 * tol * scale);
  // From the exact solution: at most one iteration per component, and the answer stays.
  q = exact1;
  cg.compute_load(x1, R1, q, true);
  EXPECT_LE(cg.last_iterations(), 3);
  EXPECT_LT((q - exact1).cwiseAbs().maxCoeff(), 1e3 * tol * scale);
  // A zero component of R has the load 0, whatever the guess; a guess of the wrong size is ignored (cold).
  Matrix3Xd R_flat = R1;
  R_flat.row(2).setZero();
  q = exact1;
  cg.compute_load(x1, R_flat, q, true);
  EXPECT_EQ(q.row(2).cwiseAbs().maxCoeff(), 0.0);
  Matrix3Xd wrong(3, 5);
  wrong.setConstant(1.0);
  cg.compute_load(x1, R1, wrong, true);
  EXPECT_EQ(cg.last_iterations(), cold_iterations);
  EXPECT_EQ(wrong, cold1) << "a cold solve is the same computation every time";
}

// solver/README.md §2: the tension along the larger stretch is not always the larger one. Skalak's
// τ1 − τ2 = (λ1² + λ2² − 1)(λ1/λ2 − λ2/λ1) changes sign when λ1² + λ2² < 1 (strong compression), so
// τmin must be the smaller of the two, not the second. An anisotropic compression of the sphere by
// 0.5–0.7 puts every quadrature point in that state.
TEST(MembraneMechanics, TauMinIsTheSmallerTensionWhenSkalakReversesTheOrder) {
  const auto m = mesh::make_sphere_mesh(2);
  const SkalakLaw law(1.0);
  const MembraneMechanics mech(m, m.nodes, law);
  const Matrix3Xd x = Eigen::Vector3d(0.7, 0.5, 0.6).asDiagonal() * m.nodes;
  const auto stretches = mech.principal_stretches(x);
  double lo = INFINITY, hi = -INFINITY;
  int reversed = 0;
  for (const auto& l : stretches) {
    ASSERT_LT(l[0] * l[0] + l[1] * l[1], 1.0);  // the reversed regime, by construction
    const auto tau = law.tensions(l[0], l[1]);  // tension along λ1, along λ2
    if (l[0] > l[1] * (1 + 1e-6) && tau[0] < tau[1]) ++reversed;
    lo = std::min({lo, tau[0], tau[1]});
    hi = std::max({hi, tau[0], tau[1]});
  }
  ASSERT_GT(reversed, 0) << "the state does not reverse the order: the test would not test anything";
  const auto s = mech.evaluate(x);
  EXPECT_DOUBLE_EQ(s.tau_min, lo);
  EXPECT_DOUBLE_EQ(s.tau_max, hi);
  // principal_tensions keeps its contract τ1 ≥ τ2 (the compressed-area fraction tests τ2 < 0).
  int unordered = 0;
  for (const auto& tau : mech.principal_tensions(x)) unordered += tau[0] < tau[1];
  EXPECT_EQ(unordered, 0);
}

// The CG backend once never looked at its convergence, so a degenerate surface (a NaN
// position, a surface collapsed to a point: the mass matrix is NaN or zero) gave a NaN or garbage load
// silently instead of DegenerateSurface, which the driver turns into an `unstable` outcome.
TEST(LoadSolver, DegenerateSurfaceIsReportedByEitherBackend) {
  const auto m = mesh::make_capsule_mesh(2, 2.0);
  const SkalakLaw law(1.0);
  const MembraneMechanics mech(m, m.nodes, law);
  const Matrix3Xd R = mech.evaluate(smooth_deformation(m.nodes, 0.2)).internal_force;
  Matrix3Xd nan = m.nodes;
  nan(1, 7) = std::nan("");
  const Matrix3Xd point = Matrix3Xd::Zero(3, m.nodes.cols());
  for (const auto backend : {LoadSolver::Backend::Cholmod, LoadSolver::Backend::ConjugateGradient}) {
    const char* name = backend == LoadSolver::Backend::Cholmod ? "CHOLMOD" : "CG";
    LoadSolver solver(m, {backend, 6, 1e-12});
    Matrix3Xd q;
    EXPECT_THROW(solver.compute_load(nan, R, q), DegenerateSurface) << name << ", NaN position";
    EXPECT_THROW(solver.compute_load(point, R, q), DegenerateSurface) << name << ", surface collapsed to a point";
    // The solver is still usable on a good surface afterwards.
    EXPECT_NO_THROW(solver.compute_load(m.nodes, R, q)) << name;
    EXPECT_TRUE(q.allFinite()) << name;
  }
}

}  // namespace
}  // namespace capsim::membrane
