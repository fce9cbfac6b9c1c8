// Double-layer operator and its second-kind solve: exact identities on the sphere and on deformed surfaces, their
// convergence under refinement, and the solve across viscosity ratios with and without deflation.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "solver/mesh/mesh.h"
#include "solver/stokes/double_layer.h"
#include "solver/stokes/second_kind_solve.h"

namespace capsim::stokes {
namespace {

using Eigen::Matrix3d;
using Eigen::Matrix3Xd;
using Eigen::Vector3d;

constexpr double kPi = std::numbers::pi;

// A deformed surface without symmetries (stretched, sheared and bent unit sphere) and a smooth density on it.
Matrix3Xd deformed_positions(const mesh::SurfaceMesh& m) {
  Matrix3Xd x(3, m.num_nodes());
  for (int i = 0; i < m.num_nodes(); ++i) {
    const Vector3d X = m.nodes.col(i);
    x.col(i) << 1.3 * X(0) + 0.25 * X(1) * X(1) + 0.1 * X(2), 0.8 * X(1) + 0.2 * X(0) * X(2),
        0.7 * X(2) + 0.15 * X(0) * X(0) + 0.1 * X(1);
  }
  return x;
}

Matrix3Xd smooth_density(const Matrix3Xd& x) {
  Matrix3Xd v(3, x.cols());
  for (int i = 0; i < x.cols(); ++i)
    v.col(i) << 0.5 + x(0, i) * x(1, i) + 0.3 * x(2, i), -0.3 + x(2, i) * x(2, i) - 0.2 * x(0, i),
        x(2, i) * (1.0 + x(0, i)) + 0.4 * x(1, i);
  return v;
}

// c + ω × x at every node.
Matrix3Xd rigid_motion(const Matrix3Xd& x, const Vector3d& c, const Vector3d& omega) {
  Matrix3Xd v(3, x.cols());
  for (int i = 0; i < x.cols(); ++i) v.col(i) = c + omega.cross(Vector3d(x.col(i)));
  return v;
}

// A generic linear field: trace, symmetric traceless and antisymmetric parts all present.
Matrix3d generic_gradient() {
  Matrix3d a;
  a << 0.7, 0.4, -0.2,  //
      -0.3, 0.1, 0.5,   //
      0.6, -0.25, -0.4;
  return a;
}

// D[A x] on the unit sphere (x0 on it), in closed form. With r = x − x0, (A x − A x0)·r = r·A r and on the unit
// sphere r·n = r²/2, so the subtracted integrand is −3 (r·A r) r / r³; with
//     ∫_S r_a r_b r_j / r³ dS = −(8π/15) (δ_ab x0_j + δ_aj x0_b + δ_bj x0_a)
// (x0 on the pole: elementary integrals in cos θ) it gives
//     D[A x](x0) = (8π/5) ((tr A) x0 + (A + Aᵀ) x0) − 4π A x0:
// 4π x0 for A = I (the normal mode, eigenvalue +1 of D/4π), −4π A x0 for a rotation, −(4π/5) E x0 for a strain E.
Vector3d sphere_linear_field_exact(const Matrix3d& a, const Vector3d& x0) {
  return 8.0 * kPi / 5.0 * (a.trace() * x0 + (a + a.transpose()) * x0) - 4.0 * kPi * a * x0;
}

// Max over nodes of |D[A x] − exact| / max |exact| on the unit sphere of a level.
double linear_field_error(int level, const Matrix3d& a) {
  const auto m = mesh::make_sphere_mesh(level);
  DoubleLayer op(m);
  const Matrix3Xd v = a * m.nodes;
  const Matrix3Xd u = op.apply(m.nodes, v);
  double err = 0.0, scale = 0.0;
  for (int i = 0; i < m.num_nodes(); ++i) {
    const Vector3d exact = sphere_linear_field_exact(a, m.nodes.col(i));
    err = std::max(err, (Vector3d(u.col(i)) - exact).norm());
    scale = std::max(scale, exact.norm());
  }
  return err / scale;
}

TEST(DoubleLayer, RigidBodyMotionsAreExactEigenvectors) {
  // With the subtraction the integrand of a rigid motion vanishes pointwise (ω × r ⟂ r), so D[v] = −4π v holds
  // at every node to round-off, on any surface: the property the deflation of the solve relies on.
  for (const bool deformed : {false, true}) {
    const auto m = mesh::make_sphere_mesh(2);
    const Matrix3Xd x = deformed ? deformed_positions(m) : m.nodes;
    DoubleLayer op(m);
    for (int k = 0; k < 2; ++k) {
      const Vector3d c = k == 0 ? Vector3d(0.3, -0.5, 0.8) : Vector3d::Zero();
      const Vector3d omega = k == 0 ? Vector3d::Zero() : Vector3d(-0.2, 0.9, 0.4);
      const Matrix3Xd v = rigid_motion(x, c, omega);
      const Matrix3Xd u = op.apply(x, v);
      const double err = (u + 4.0 * kPi * v).cwiseAbs().maxCoeff() / (4.0 * kPi * v.cwiseAbs().maxCoeff());
      std::printf("  %s, %s: max |D[v] + 4π v| / max |4π v| = %.2e\n", deformed ? "deformed" : "sphere",
                  k == 0 ? "translation" : "rotation", err);
      EXPECT_LT(err, 1e-14);
    }
  }
}

TEST(DoubleLayer, LinearFieldsOnTheSphereConverge) {
  struct Case {
    const char* name;
    Matrix3d a;
  };
  Matrix3d strain;
  strain << 0.3, 0.5, 0.0, 0.5, -0.1, 0.2, 0.0, 0.2, -0.2;
  const Case cases[] = {{"normal mode x", Matrix3d::Identity()}, {"strain E x", strain},
                        {"generic A x", generic_gradient()}};
  for (const Case& c : cases) {
    std::vector<double> err;
    for (int level = 1; level <= 4; ++level) {
      err.push_back(linear_field_error(level, c.a));
      std::printf("  %s level %d: max rel error %.3e", c.name, level, err.back());
      if (level > 1) std::printf("  order %.2f", std::log2(err[level - 2] / err.back()));
      std::printf("\n");
    }
    for (std::size_t k = 1; k < err.size(); ++k) EXPECT_LT(err[k], err[k - 1] / 4.0) << c.name << " level " << k + 1;
  }
}

TEST(DoubleLayer, FluxIsTheLeftEigenvectorOfTheNormalMode) {
  // ∫ n·D[v] dS = 4π ∫ n·v dS on any closed surface (the PV of T over the surface seen from x is +4π I), so the
  // flux functional a of the solve's deflation is a left eigenvector of D/4π with eigenvalue 1, up to the
  // discretisation error, which must vanish under refinement. And a annihilates the rigid motions exactly.
  std::vector<double> err;
  for (int level = 1; level <= 3; ++level) {
    const auto m = mesh::make_capsule_mesh(level, 2.0);
    DoubleLayer op(m);
    const Matrix3Xd v = smooth_density(m.nodes);
    const Matrix3Xd a = op.flux_weights(m.nodes);
    const double flux = (a.array() * v.array()).sum();
    const double flux_d = (a.array() * op.apply(m.nodes, v).array()).sum();
    const double area_scale = a.colwise().norm().sum();  // ∫ |v| dS scale for |v| = 1
    err.push_back(std::abs(flux_d - 4.0 * kPi * flux) / (4.0 * kPi * area_scale * v.cwiseAbs().maxCoeff()));
    std::printf("  a/b = 2 level %d: |aᵀD[v] − 4π aᵀv| / (4π ∫|v|dS) = %.3e", level, err.back());
    if (level > 1) std::printf("  order %.2f", std::log2(err[level - 2] / err.back()));
    std::printf("\n");
    for (int k = 0; k < 2; ++k) {
      const Matrix3Xd r = rigid_motion(m.nodes, k == 0 ? Vector3d(0.3, -0.5, 0.8) : Vector3d::Zero(),
                                       k == 0 ? Vector3d::Zero() : Vector3d(-0.2, 0.9, 0.4));
      EXPECT_LT(std::abs((a.array() * r.array()).sum()), 1e-14 * area_scale) << "level " << level;
    }
  }
  for (std::size_t k = 1; k < err.size(); ++k) EXPECT_LT(err[k], err[k - 1] / 4.0) << "level " << k + 1;
}

TEST(DoubleLayer, SymmetricEvaluationsEqualTheFullEvaluation) {
  // A deformed surface and a density with both symmetries: mirror x3 → −x3 (components 1, 2 even in X3, component
  // 3 odd) and odd under x → −x.
  const auto m = mesh::make_sphere_mesh(2);
  Matrix3Xd x(3, m.num_nodes()), v(3, m.num_nodes());
  for (int i = 0; i < m.num_nodes(); ++i) {
    const Vector3d X = m.nodes.col(i);
    x.col(i) << 1.3 * X(0) + 0.4 * X(1) + 0.1 * X(0) * X(2) * X(2), 0.8 * X(1) - 0.2 * X(0) * X(0) * X(0),
        0.9 * X(2) + 0.1 * X(2) * X(0) * X(0);
    v.col(i) << X(1) + 0.3 * X(0) * X(1) * X(1), -0.5 * X(0) + X(1) * X(2) * X(2), X(2) * (1.0 + X(0) * X(1));
  }
  SingleLayerOptions full_opt, mirror_opt, central_opt;
  full_opt.symmetry = Symmetry::Off;
  central_opt.central_symmetry = true;
  DoubleLayer full(m, full_opt), mirror(m, mirror_opt), central(m, central_opt);
  const Matrix3Xd uf = full.apply(x, v), um = mirror.apply(x, v), uc = central.apply(x, v);
  EXPECT_FALSE(full.last_stats().used_symmetry);
  EXPECT_TRUE(mirror.last_stats().used_symmetry);
  EXPECT_FALSE(mirror.last_stats().used_central);
  EXPECT_TRUE(central.last_stats().used_central);
  EXPECT_LT(mirror.last_stats().targets, 0.6 * m.num_nodes());
  EXPECT_LT(central.last_stats().targets, 0.3 * m.num_nodes());
  const double scale = uf.cwiseAbs().maxCoeff();
  const double dm = (um - uf).cwiseAbs().maxCoeff() / scale, dc = (uc - uf).cwiseAbs().maxCoeff() / scale;
  std::printf("  mirror (%d targets): %.2e, mirror and central (%d targets): %.2e of max |D[v]| from the full (%d)\n",
              mirror.last_stats().targets, dm, central.last_stats().targets, dc, m.num_nodes());
  // The same integrals on mirrored data, summed in another order: round-off.
  EXPECT_LT(dm, 1e-13);
  EXPECT_LT(dc, 1e-13);
  // A density without the symmetry is evaluated in full.
  Matrix3Xd v_odd = v;
  v_odd.row(2).array() += 0.1;
  const Matrix3Xd u1 = mirror.apply(x, v_odd);
  EXPECT_FALSE(mirror.last_stats().used_symmetry);
  EXPECT_EQ((u1 - full.apply(x, v_odd)).cwiseAbs().maxCoeff(), 0.0);
}

// The regular all-pairs sum by its three implementations (stokeslet.h): the SIMD tile in double (the lanes of
// stokeslet_lanes.h, restating kernel::add_stresslet) and in mixed precision against the plain loop over
// add_stresslet, through the whole operator (the corrections are the same in all three), on a deformed sphere and
// a P2 spheroid a/b = 2 with a generic density, levels 2 and 3. Norm-wise, max_i |Δu_i| / max_i |u_i| (a node's
// own sum can nearly vanish).
TEST(DoubleLayer, SimdTilesAgreeWithThePlainStressletSum) {
  for (const int level : {2, 3})
  for (const bool spheroid : {false, true}) {
    const auto m = spheroid ? mesh::make_capsule_mesh(level, 2.0) : mesh::make_sphere_mesh(level);
    const Matrix3Xd x = spheroid ? Matrix3Xd(m.nodes) : deformed_positions(m), v = smooth_density(x);
    SingleLayerOptions plain_opt, fast_opt, mixed_opt;
    plain_opt.symmetry = fast_opt.symmetry = mixed_opt.symmetry = Symmetry::Off;
    plain_opt.kernel = KernelChoice::Plain;
    mixed_opt.precision = KernelPrecision::Mixed;
    DoubleLayer plain(m, plain_opt), fast(m, fast_opt), mixed(m, mixed_opt);
    const Matrix3Xd up = plain.apply(x, v), uf = fast.apply(x, v), um = mixed.apply(x, v);
    const double scale = up.cwiseAbs().maxCoeff();
    const double df = (uf - up).cwiseAbs().maxCoeff() / scale, dm = (um - up).cwiseAbs().maxCoeff() / scale;
    std::printf("  %s (%d nodes): fast tile %.2e, mixed %.2e of max |D[v]| from the plain sum (%s)\n",
                spheroid ? "spheroid a/b = 2" : "deformed sphere", m.num_nodes(), df, dm, kernel::kernel_isa());
    EXPECT_LT(df, kernel::kFastRelativeBound * 0.1);  // 1e-13
    EXPECT_LT(dm, kernel::kStressletMixedRelativeBound);
    EXPECT_GT(dm, 0.0);  // the mixed path is in use
  }
}

// The lanes' stresslet against the scalar definition pair by pair, over distances from 1e-3 to 10: the tile of one
// target and one source is the sum of that one term.
TEST(DoubleLayer, LaneStressletIsTheScalarDefinition) {
  const double tx[1] = {0.1}, ty[1] = {-0.2}, tz[1] = {0.3}, tvx[1] = {0.5}, tvy[1] = {-1.0}, tvz[1] = {0.25};
  double worst = 0.0;
  for (double dist = 1e-3; dist < 10.0; dist *= 1.7) {
    const double sx[1] = {0.1 + 0.6 * dist}, sy[1] = {-0.2 - 0.48 * dist}, sz[1] = {0.3 + 0.64 * dist};
    const double svx[1] = {0.7}, svy[1] = {-0.1}, svz[1] = {0.4}, snx[1] = {0.3}, sny[1] = {0.9}, snz[1] = {-0.2};
    double ex = 0.0, ey = 0.0, ez = 0.0;
    const double rx = sx[0] - tx[0], ry = sy[0] - ty[0], rz = sz[0] - tz[0];
    kernel::add_stresslet(rx, ry, rz, svx[0] - tvx[0], svy[0] - tvy[0], svz[0] - tvz[0], snx[0], sny[0], snz[0],
                          1.0 / std::sqrt(rx * rx + ry * ry + rz * rz), ex, ey, ez);
    double ux[1], uy[1], uz[1];
    kernel::stresslet_sum_fast({tx, ty, tz, tvx, tvy, tvz, 1}, {sx, sy, sz, svx, svy, svz, snx, sny, snz, 1},
                               {ux, uy, uz});
    const double e = std::hypot(ux[0] - ex, uy[0] - ey, uz[0] - ez) / std::hypot(ex, ey, ez);
    worst = std::max(worst, e);
  }
  std::printf("  lane vs scalar stresslet, worst relative difference %.2e\n", worst);
  EXPECT_LT(worst, 1e-13);
}

constexpr double kRatios[] = {0.05, 0.2, 1.0, 5.0, 20.0};

TEST(SecondKindSolve, RigidMotionIsTheSolutionForEveryViscosityRatio) {
  // (1 + λ)/2 U − (1 − λ)/(8π) D[U] = U for a rigid motion U (D[U] = −4π U): an undisturbed flow that is itself a
  // rigid motion, with no load, moves the capsule with it whatever λ.
  const auto m = mesh::make_sphere_mesh(2);
  const Matrix3Xd x = deformed_positions(m);
  DoubleLayer op(m);
  const Matrix3Xd motion = rigid_motion(x, Vector3d(0.3, -0.5, 0.8), Vector3d(-0.2, 0.9, 0.4));
  for (const bool deflate : {true, false})
    for (const double lambda : kRatios) {
      SecondKindOptions opt;
      opt.deflate = deflate;
      opt.tolerance = 1e-12;
      Matrix3Xd v;
      const SecondKindResult r = solve_second_kind(op, m, x, lambda, motion, v, opt);
      const double err = (v - motion).cwiseAbs().maxCoeff() / motion.cwiseAbs().maxCoeff();
      EXPECT_TRUE(r.converged) << r.reason;
      EXPECT_LE(r.iterations, 2) << "λ " << lambda;  // U is an eigenvector of the system: one Krylov step
      EXPECT_LT(err, 1e-12) << "λ " << lambda << " deflate " << deflate;
    }
}

// Max over nodes of |v − 5/(3 + 2λ) E x| / max |5/(3 + 2λ) E x| for f = E x on the unit sphere.
double strain_solution_error(const mesh::SurfaceMesh& m, DoubleLayer& op, const Matrix3d& e, double lambda,
                             SecondKindResult& r) {
  const Matrix3Xd f = e * m.nodes;
  Matrix3Xd v;
  r = solve_second_kind(op, m, m.nodes, lambda, f, v);
  const Matrix3Xd exact = 5.0 / (3.0 + 2.0 * lambda) * f;
  return (v - exact).colwise().norm().maxCoeff() / exact.colwise().norm().maxCoeff();
}

TEST(SecondKindSolve, StrainOnTheSphereConverges) {
  // D[E x] = −(4π/5) E x on the unit sphere (sphere_linear_field_exact), so f = E x gives
  // ((1 + λ)/2 + (1 − λ)/10) v = f, v = 5/(3 + 2λ) E x. The solution's error is the operator's, carried through
  // (I − κK)⁻¹ (bounded by 1/(1 − |κ|/5) on the strain modes), so it converges with the operator's order.
  Matrix3d e;
  e << 0.3, 0.5, 0.0, 0.5, -0.1, 0.2, 0.0, 0.2, -0.2;
  for (const double lambda : {0.05, 20.0}) {
    std::vector<double> err;
    for (int level = 1; level <= 3; ++level) {
      const auto m = mesh::make_sphere_mesh(level);
      DoubleLayer op(m);
      SecondKindResult r;
      err.push_back(strain_solution_error(m, op, e, lambda, r));
      std::printf("  λ = %g level %d: max rel error %.3e (%d iterations)", lambda, level, err.back(), r.iterations);
      if (level > 1) std::printf("  order %.2f", std::log2(err[level - 2] / err.back()));
      std::printf("\n");
      EXPECT_TRUE(r.converged) << r.reason;
    }
    for (std::size_t k = 1; k < err.size(); ++k) EXPECT_LT(err[k], err[k - 1] / 4.0) << "λ " << lambda;
  }
}

// Krylov iterations to 1e-8 with and without deflation for f on the surface x.
std::array<int, 2> iterations(DoubleLayer& op, const mesh::SurfaceMesh& m, const Matrix3Xd& x, const Matrix3Xd& f,
                              double lambda) {
  std::array<int, 2> it{};
  for (const bool deflate : {true, false}) {
    SecondKindOptions opt;
    opt.deflate = deflate;
    Matrix3Xd v;
    const SecondKindResult r = solve_second_kind(op, m, x, lambda, f, v, opt);
    EXPECT_TRUE(r.converged) << "λ " << lambda << ": " << r.reason;
    EXPECT_LE(r.residual, opt.tolerance);
    it[deflate ? 0 : 1] = r.iterations;
  }
  std::printf("  λ = %7.3f: %2d iterations with deflation, %2d without\n", lambda, it[0], it[1]);
  return it;
}

TEST(SecondKindSolve, DeflationBoundsTheIterationsAcrossViscosityRatios) {
  // A generic right-hand side (with rigid-motion and flux components). Without deflation the eigenvalues
  // 2/(1 + λ) (rigid motions) and 2λ/(1 + λ) (volume mode) of the system approach 0 at the ends of the range; with
  // it they sit at 1. GMRES pays for each such isolated eigenvalue only a few iterations, so the difference is a
  // few iterations per solve, and it grows slowly (logarithmically) with λ or 1/λ.
  // On the sphere the rest of the spectrum of D/4π stays well inside (−1, 1) (−1/5 on the strains, the higher
  // modes smaller), so with deflation the count does not depend on λ at all, over six decades.
  {
    const auto m = mesh::make_sphere_mesh(2);
    const Matrix3Xd f = smooth_density(m.nodes);
    DoubleLayer op(m);
    int lo = 1 << 30, hi = 0;
    for (const double lambda : {1e-3, 0.05, 0.2, 5.0, 20.0, 1e3}) {
      const auto it = iterations(op, m, m.nodes, f, lambda);
      lo = std::min(lo, it[0]);
      hi = std::max(hi, it[0]);
      if (lambda <= 1e-3 || lambda >= 1e3) {
        EXPECT_GE(it[1], it[0] + 2) << "λ " << lambda;
      }
    }
    EXPECT_LE(hi - lo, 2);
  }
  // On a strongly deformed surface D/4π has further eigenvalues near ±1 (not rigid motions, not deflated), so the
  // count grows with |κ| either way; deflation still removes the seven that stall.
  {
    const auto m = mesh::make_sphere_mesh(1);
    const Matrix3Xd x = deformed_positions(m);
    const Matrix3Xd f = smooth_density(x);
    DoubleLayer op(m);
    for (const double lambda : {0.05, 20.0}) {
      const auto it = iterations(op, m, x, f, lambda);
      EXPECT_GT(it[1], it[0]) << "λ " << lambda;
    }
  }
}

TEST(SecondKindSolve, WarmStartSavesIterations) {
  // The next stage's right-hand side differs from this one's by a little: started from this solution, the solve
  // needs fewer iterations than from zero and reaches the same solution.
  const auto m = mesh::make_sphere_mesh(1);
  const Matrix3Xd x = deformed_positions(m);
  const Matrix3Xd f = smooth_density(x);
  DoubleLayer op(m);
  for (const double lambda : {0.2, 5.0}) {
    Matrix3Xd v0;
    ASSERT_TRUE(solve_second_kind(op, m, x, lambda, f, v0).converged);
    const Matrix3Xd f1 = f + 1e-3 * smooth_density(x.cwiseAbs());
    Matrix3Xd cold, warm = v0;
    const SecondKindResult rc = solve_second_kind(op, m, x, lambda, f1, cold);
    const SecondKindResult rw = solve_second_kind(op, m, x, lambda, f1, warm);
    std::printf("  λ = %g: %d iterations cold, %d warm\n", lambda, rc.iterations, rw.iterations);
    EXPECT_TRUE(rc.converged && rw.converged);
    EXPECT_LT(rw.iterations, rc.iterations);
    EXPECT_LT((warm - cold).cwiseAbs().maxCoeff(), 1e-6 * cold.cwiseAbs().maxCoeff());
  }
}

TEST(SecondKindSolve, NonConvergenceIsAnOutcome) {
  const auto m = mesh::make_sphere_mesh(1);
  DoubleLayer op(m);
  const Matrix3Xd f = smooth_density(m.nodes);
  SecondKindOptions opt;
  opt.max_iterations = 2;
  opt.tolerance = 1e-12;
  Matrix3Xd v;
  SecondKindResult r = solve_second_kind(op, m, m.nodes, 20.0, f, v, opt);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.reason, "iteration limit");
  EXPECT_EQ(r.iterations, 2);
  EXPECT_GT(r.residual, opt.tolerance);
  EXPECT_TRUE(v.allFinite());
  Matrix3Xd bad = f;
  bad(1, 3) = std::nan("");
  v.resize(3, 0);
  r = solve_second_kind(op, m, m.nodes, 5.0, bad, v);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.reason, "non-finite residual");
  // λ = 1 needs no solve: v = f.
  r = solve_second_kind(op, m, m.nodes, 1.0, f, v);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.applications, 0);
  EXPECT_EQ((v - f).cwiseAbs().maxCoeff(), 0.0);
}

TEST(SecondKindSolve, RejectsBadInput) {
  const auto m = mesh::make_sphere_mesh(1);
  DoubleLayer op(m);
  const Matrix3Xd f = smooth_density(m.nodes);
  Matrix3Xd v;
  for (const double lambda : {0.0, -1.0, std::nan(""), HUGE_VAL})
    EXPECT_THROW(solve_second_kind(op, m, m.nodes, lambda, f, v), std::invalid_argument) << lambda;
  SecondKindOptions bad;
  bad.tolerance = 0.0;
  EXPECT_FALSE(bad.valid());
  EXPECT_THROW(solve_second_kind(op, m, m.nodes, 5.0, f, v, bad), std::invalid_argument);
  bad = {};
  bad.max_iterations = 0;
  EXPECT_FALSE(bad.valid());
  bad = {};
  bad.restart = 0;
  EXPECT_FALSE(bad.valid());
  EXPECT_TRUE(SecondKindOptions{}.valid());
  EXPECT_THROW(op.apply(m.nodes, Matrix3Xd(3, 2)), std::invalid_argument);
}

}  // namespace
}  // namespace capsim::stokes
