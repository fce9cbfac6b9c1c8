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

}  // namespace
}  // namespace capsim::stokes
