// Single-layer operator: exact identities on the sphere and spheroids, symmetry, options.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "solver/mesh/mesh.h"
#include "solver/stokes/single_layer.h"

namespace capsim::stokes {
namespace {

using Eigen::Matrix3Xd;
using Eigen::Vector3d;

constexpr double kPi = std::numbers::pi;

// Max over nodes of |u − (16π/3) f| / |(16π/3) f| for a uniform load f on the unit sphere.
double uniform_load_error(int level, const SingleLayerOptions& opt = {}) {
  const auto m = mesh::make_sphere_mesh(level);
  SingleLayer op(m, opt);
  const Vector3d f(0.3, -0.5, 0.8);
  Matrix3Xd q = f.replicate(1, m.num_nodes());
  const Matrix3Xd u = op.apply(m.nodes, q);
  const Vector3d exact = 16.0 * kPi / 3.0 * f;
  return (u.colwise() - exact).colwise().norm().maxCoeff() / exact.norm();
}

// Outward unit normal at the nodes of the spheroid x1²/a² + (x2² + x3²)/b² = 1.
Matrix3Xd spheroid_normals(const Matrix3Xd& x, double a, double b) {
  Matrix3Xd n(3, x.cols());
  for (int i = 0; i < x.cols(); ++i)
    n.col(i) = Vector3d(x(0, i) / (a * a), x(1, i) / (b * b), x(2, i) / (b * b)).normalized();
  return n;
}

// Max over nodes of |∫ J·n dS| (exactly 0), relative to the surface area (the scale of ∫|J| ~ area / size).
double normal_load_error(int level, double aspect_ratio) {
  const auto m = mesh::make_capsule_mesh(level, aspect_ratio);
  const auto ab = mesh::spheroid_semi_axes(aspect_ratio);
  SingleLayer op(m);
  const Matrix3Xd u = op.apply(m.nodes, spheroid_normals(m.nodes, ab[0], ab[1]));
  return u.colwise().norm().maxCoeff();
}

TEST(SingleLayer, UniformLoadOnSphereGivesStokesDrag) {
  std::vector<double> err;
  for (int level = 1; level <= 4; ++level) {
    err.push_back(uniform_load_error(level));
    std::printf("  level %d: max rel error %.3e", level, err.back());
    if (level > 1) std::printf("  observed order %.2f", std::log2(err[level - 2] / err.back()));
    std::printf("\n");
  }
  for (std::size_t k = 1; k < err.size(); ++k) EXPECT_LT(err[k], err[k - 1] / 4.0) << "level " << k + 1;
  EXPECT_LT(err.back(), 1e-3);
}

TEST(SingleLayer, NormalLoadIntegratesToZero) {
  for (const double r : {1.0, 2.0, 0.5}) {
    std::vector<double> err;
    for (int level = 1; level <= 4; ++level) {
      err.push_back(normal_load_error(level, r));
      std::printf("  a/b = %.1f level %d: max |u| %.3e", r, level, err.back());
      if (level > 1) std::printf("  observed order %.2f", std::log2(err[level - 2] / err.back()));
      std::printf("\n");
    }
    for (std::size_t k = 1; k < err.size(); ++k) EXPECT_LT(err[k], err[k - 1] / 2.0) << "a/b " << r;
  }
}

// A deformed, mirror-symmetric scene: sheared and stretched in the (x1, x2) plane, bent symmetrically in x3.
void symmetric_scene(const mesh::SurfaceMesh& m, Matrix3Xd& x, Matrix3Xd& q) {
  x.resize(3, m.num_nodes());
  q.resize(3, m.num_nodes());
  for (int i = 0; i < m.num_nodes(); ++i) {
    const Vector3d X = m.nodes.col(i);
    x.col(i) << 1.3 * X(0) + 0.4 * X(1) + 0.1 * X(2) * X(2), 0.8 * X(1) - 0.2 * X(0) * X(0), 0.9 * X(2);
    q.col(i) << 0.5 + X(0) * X(1), -0.3 + X(2) * X(2), X(2) * (1.0 + X(0));
  }
}

TEST(SingleLayer, SymmetricEvaluationEqualsFullEvaluation) {
  const auto m = mesh::make_capsule_mesh(2, 2.0);
  Matrix3Xd x, q;
  symmetric_scene(m, x, q);
  SingleLayerOptions full_opt;
  full_opt.symmetry = Symmetry::Off;
  SingleLayer full(m, full_opt), sym(m);
  const Matrix3Xd uf = full.apply(x, q), us = sym.apply(x, q);
  EXPECT_FALSE(full.last_stats().used_symmetry);
  EXPECT_TRUE(sym.last_stats().used_symmetry);
  EXPECT_LT(sym.last_stats().targets, 0.6 * m.num_nodes());
  const double scale = uf.cwiseAbs().maxCoeff();
  const double diff = (uf - us).cwiseAbs().maxCoeff() / scale;
  std::printf("  symmetric vs full: max diff / max |u| = %.2e (%d of %d targets)\n", diff,
              sym.last_stats().targets, m.num_nodes());
  EXPECT_LT(diff, 1e-13);
  // u3 vanishes on the mirror plane in both.
  for (int i = 0; i < m.num_nodes(); ++i)
    if (m.mirror_node[i] == i) EXPECT_LT(std::abs(us(2, i)), 1e-12 * scale);
}

TEST(SingleLayer, SymmetryIsSkippedForAnAsymmetricScene) {
  const auto m = mesh::make_capsule_mesh(2, 2.0);
  Matrix3Xd x, q;
  symmetric_scene(m, x, q);
  SingleLayerOptions off;
  off.symmetry = Symmetry::Off;
  SingleLayer full(m, off), sym(m);

  // An odd load component breaks the symmetry of q only.
  Matrix3Xd q_odd = q;
  q_odd.row(2).array() += 0.05;
  const Matrix3Xd u1 = sym.apply(x, q_odd);
  EXPECT_FALSE(sym.last_stats().used_symmetry);
  EXPECT_EQ(sym.last_stats().targets, m.num_nodes());
  EXPECT_EQ((u1 - full.apply(x, q_odd)).cwiseAbs().maxCoeff(), 0.0);

  // A small position perturbation of one node (1e-6 of the size) breaks it too; 1e-14 does not.
  Matrix3Xd x_bad = x;
  x_bad(0, 17) += 1e-6;
  EXPECT_FALSE(sym.is_symmetric(x_bad, q));
  x_bad(0, 17) = x(0, 17) + 1e-14;
  EXPECT_TRUE(sym.is_symmetric(x_bad, q));

  // Forcing it on an asymmetric scene is an error.
  SingleLayerOptions on;
  on.symmetry = Symmetry::On;
  SingleLayer forced(m, on);
  EXPECT_THROW(forced.apply(x, q_odd), std::invalid_argument);
}

TEST(SingleLayer, FastAndPlainKernelsAgree) {
  const auto m = mesh::make_capsule_mesh(2, 0.5);
  Matrix3Xd x, q;
  symmetric_scene(m, x, q);
  q.row(2).array() += 0.3;
  SingleLayerOptions plain_opt;
  plain_opt.kernel = KernelChoice::Plain;
  SingleLayer fast(m), plain(m, plain_opt);
  const Matrix3Xd uf = fast.apply(x, q), up = plain.apply(x, q);
  const double rel = (uf - up).colwise().norm().maxCoeff() / up.colwise().norm().minCoeff();
  EXPECT_LT(rel, 1e-12);
}

TEST(SingleLayer, RejectsBadInput) {
  const auto m = mesh::make_sphere_mesh(1);
  SingleLayerOptions bad;
  bad.regular_degree = 3;
  EXPECT_THROW(SingleLayer(m, bad), std::invalid_argument);
  bad = {};
  bad.duffy_order = 0;
  EXPECT_THROW(SingleLayer(m, bad), std::invalid_argument);
  SingleLayer op(m);
  EXPECT_THROW(op.apply(m.nodes, Matrix3Xd::Zero(3, 5)), std::invalid_argument);
}

}  // namespace
}  // namespace capsim::stokes
