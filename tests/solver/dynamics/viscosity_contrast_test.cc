// The viscosity ratio in the flow (solver/dynamics/viscosity_contrast.h, CapsuleFlow::boundary_velocity): an
// undisturbed rigid motion with zero load is the surface velocity for every λ; a sphere without load in shear
// flow moves with the exact drop solution; warm start, statistics and non-convergence follow the contract.
#include "solver/dynamics/viscosity_contrast.h"

#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "solver/dynamics/capsule_flow.h"
#include "solver/mesh/mesh.h"

namespace capsim::dynamics {
namespace {

config::CaseConfig make_case(int level, double aspect_ratio, double lambda) {
  config::CaseConfig c;
  c.level = level;
  c.aspect_ratio = aspect_ratio;
  c.capillary_number = 0.1;
  c.viscosity_ratio = lambda;
  return c;
}

constexpr double kRatios[] = {0.05, 0.2, 1.0, 5.0, 20.0};

// Zero load in an undisturbed flow that is a rigid motion U = c + ω × x: the capsule moves with it, v = U, for
// every λ (D[U] = −4π U, so (1 + λ)/2 U − (1 − λ)/(8π) D[U] = U). On the a/b = 2 spheroid at level 2, through
// the solve CapsuleFlow installs (translation, rotation, and both).
TEST(ViscosityContrast, RigidMotionWithZeroLoadIsTheUndisturbedFlow) {
  for (const double lambda : kRatios) {
    if (lambda == 1.0) continue;  // no second-kind solve: v = f by construction (checked below through the flow)
    const config::CaseConfig c = make_case(2, 2.0, lambda);
    CapsuleFlow flow(c);
    ViscosityContrast solve(flow.mesh(), flow.single_layer().options(), lambda, stokes::SecondKindOptions{});
    const Eigen::Matrix3Xd& x = flow.reference();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d t = k == 1 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0.3, -0.5, 0.8);
      const Eigen::Vector3d w = k == 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(-0.2, 0.9, 0.4);
      Eigen::Matrix3Xd U(3, x.cols());
      for (int i = 0; i < x.cols(); ++i) U.col(i) = t + w.cross(Eigen::Vector3d(x.col(i)));
      Eigen::Matrix3Xd v;
      solve.begin_step();
      solve.solve(x, U, v);
      const double err = (v - U).cwiseAbs().maxCoeff() / U.cwiseAbs().maxCoeff();
      EXPECT_LT(err, 1e-7) << "λ " << lambda << " motion " << k;
    }
  }
}

// A sphere without load in shear flow v∞ = (x2, 0, 0) = W x + E x (rotation W, strain E): the surface velocity of
// a spherical drop is v = W x + 5/(3 + 2λ) E x (D[E x] = −(4π/5) E x on the unit sphere). Through
// CapsuleFlow::boundary_velocity (single layer of q = 0, second-kind solve, volume correction) on levels 2 and 3:
// the error falls by at least 4 (the operator's order), for every λ; at λ = 1 it is v∞ exactly.
TEST(ViscosityContrast, UnloadedSphereInShearMovesAsTheExactDrop) {
  for (const double lambda : kRatios) {
    std::vector<double> err;
    for (int level : {2, 3}) {
      CapsuleFlow flow(make_case(level, 1.0, lambda));
      const Eigen::Matrix3Xd x = flow.reference();
      const Eigen::Matrix3Xd q = Eigen::Matrix3Xd::Zero(3, x.cols());
      Eigen::Matrix3Xd v;
      flow.begin_step();
      (void)flow.boundary_velocity(x, q, v);
      const double s = 5.0 / (3.0 + 2.0 * lambda);
      Eigen::Matrix3Xd exact(3, x.cols());
      for (int i = 0; i < x.cols(); ++i)
        exact.col(i) << 0.5 * x(1, i) + s * 0.5 * x(1, i), -0.5 * x(0, i) + s * 0.5 * x(0, i), 0.0;
      err.push_back((v - exact).cwiseAbs().maxCoeff());
      std::printf("  λ = %5.2f level %d: max error %.3e, GMRES iterations %d\n", lambda, level, err.back(),
                  flow.second_kind_statistics().max_iterations);
      if (lambda == 1.0) {
        EXPECT_EQ(flow.second_kind_statistics().solves, 0);
      }
    }
    if (lambda == 1.0) {
      EXPECT_LT(err.back(), 1e-12);
    } else {
      EXPECT_LT(err[1], err[0] / 4.0) << "λ " << lambda;
      EXPECT_LT(err[0], 1e-3) << "λ " << lambda;
    }
  }
}

// numerics.double_layer_precision reaches the double layer and nothing else: on a deformed a/b = 2 capsule at
// λ = 5 the mixed double layer moves the velocity by the round-off of float pair terms (above 1e-12, below 1e-5
// of max |v|), whichever precision the single layer has; and at λ = 1, where there is no double layer, the key
// changes nothing, bitwise.
TEST(ViscosityContrast, DoubleLayerPrecisionIsItsOwnKey) {
  const auto velocity = [](double lambda, const std::string& single, const std::string& dl) {
    config::CaseConfig c = make_case(2, 2.0, lambda);
    c.kernel_precision = single;
    c.double_layer_precision = dl;
    CapsuleFlow flow(c);
    Eigen::Matrix3Xd x = flow.reference();
    for (int i = 0; i < x.cols(); ++i) x(0, i) *= 1.0 + 0.1 * x(1, i);  // a load and a general scene
    Eigen::Matrix3Xd v;
    flow.begin_step();
    (void)flow.velocity(x, v);
    return v;
  };
  const Eigen::Matrix3Xd dd = velocity(5.0, "double", "double"), dm = velocity(5.0, "double", "mixed");
  const double scale = dd.cwiseAbs().maxCoeff(), moved = (dm - dd).cwiseAbs().maxCoeff() / scale;
  std::printf("  λ = 5: mixed double layer moves the velocity by %.2e of max |v|\n", moved);
  EXPECT_GT(moved, 1e-12);
  EXPECT_LT(moved, 1e-5);
  // With a mixed single layer: each key still moves v on its own.
  const Eigen::Matrix3Xd md = velocity(5.0, "mixed", "double"), mm = velocity(5.0, "mixed", "mixed");
  EXPECT_GT((mm - md).cwiseAbs().maxCoeff() / scale, 1e-12);
  EXPECT_GT((md - dd).cwiseAbs().maxCoeff() / scale, 1e-12);
  const Eigen::Matrix3Xd one_d = velocity(1.0, "double", "double"), one_m = velocity(1.0, "double", "mixed");
  EXPECT_EQ((one_m - one_d).cwiseAbs().maxCoeff(), 0.0) << "λ = 1 has no double layer";
}

// Within a step the second solve of the same right-hand side starts from the first one's solution and needs no
// iteration; begin_step forgets it (the next solve repeats the first bitwise); the statistics count the solves.
TEST(ViscosityContrast, WarmStartLastsOneStep) {
  CapsuleFlow flow(make_case(2, 2.0, 5.0));
  const Eigen::Matrix3Xd x = flow.reference();
  Eigen::Matrix3Xd q(3, x.cols());
  for (int i = 0; i < x.cols(); ++i) q.col(i) << x(0, i), -0.5 * x(1, i), 0.2 * x(2, i) * x(0, i);
  Eigen::Matrix3Xd v1, v2, v3;
  flow.begin_step();
  (void)flow.boundary_velocity(x, q, v1);
  const SecondKindStatistics first = flow.second_kind_statistics();
  ASSERT_EQ(first.solves, 1);
  EXPECT_GT(first.iterations, 0);
  (void)flow.boundary_velocity(x, q, v2);
  // Warm: at most one iteration (the true residual of the converged iterate may sit at the tolerance).
  const long warm = flow.second_kind_statistics().iterations - first.iterations;
  EXPECT_LE(warm, 1) << "warm start: already converged";
  EXPECT_LT((v2 - v1).cwiseAbs().maxCoeff(), 1e-7 * v1.cwiseAbs().maxCoeff());
  flow.begin_step();
  (void)flow.boundary_velocity(x, q, v3);
  EXPECT_EQ(flow.second_kind_statistics().iterations, 2 * first.iterations + warm);
  EXPECT_EQ(flow.second_kind_statistics().max_iterations, first.iterations);
  EXPECT_EQ(flow.second_kind_statistics().solves, 3);
  EXPECT_DOUBLE_EQ(flow.second_kind_statistics().mean_iterations(), (2.0 * first.iterations + warm) / 3.0);
  EXPECT_TRUE(v3 == v1) << "a fresh step repeats the first solve bitwise";
}

// A solve that cannot reach its tolerance throws SecondKindNotConverged naming the cause, and leaves no warm start.
TEST(ViscosityContrast, NonConvergenceThrowsANamedError) {
  CapsuleFlow flow(make_case(2, 2.0, 0.05));
  stokes::SecondKindOptions o;
  o.tolerance = 1e-14;
  o.max_iterations = 2;
  flow.set_second_kind_solve(std::make_unique<ViscosityContrast>(flow.mesh(), flow.single_layer().options(), 0.05, o));
  const Eigen::Matrix3Xd x = flow.reference();
  Eigen::Matrix3Xd v;
  try {
    (void)flow.velocity(x, v);
    ADD_FAILURE() << "no exception";
  } catch (const SecondKindNotConverged& e) {
    EXPECT_NE(std::string(e.what()).find("did not converge"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("iteration limit"), std::string::npos) << e.what();
  }
  EXPECT_EQ(flow.second_kind_statistics().solves, 0);
}

TEST(ViscosityContrast, RejectsBadParameters) {
  CapsuleFlow flow(make_case(1, 1.0, 1.0));
  const auto& so = flow.single_layer().options();
  EXPECT_THROW(ViscosityContrast(flow.mesh(), so, 1.0, {}), std::invalid_argument);
  EXPECT_THROW(ViscosityContrast(flow.mesh(), so, 0.0, {}), std::invalid_argument);
  stokes::SecondKindOptions o;
  o.tolerance = 2.0;
  EXPECT_THROW(ViscosityContrast(flow.mesh(), so, 5.0, o), std::invalid_argument);
}

}  // namespace
}  // namespace capsim::dynamics
