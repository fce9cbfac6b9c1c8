// The singular (Duffy) integral on one curved P2 element against a brute-force adaptive reference.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>

#include "solver/mesh/mesh.h"
#include "solver/mesh/p2_element.h"
#include "solver/quadrature/triangle_rule.h"
#include "solver/stokes/single_layer.h"

namespace capsim::stokes {
namespace {

using Eigen::Matrix3Xd;
using Eigen::Vector3d;
using Tri = std::array<std::array<double, 2>, 3>;  // sub-triangle of the reference triangle

// A mesh made of a single element: apply() then returns, at each of its 6 nodes, exactly the singular
// integral over the element (the regular sum of the element is added and subtracted again).
mesh::SurfaceMesh one_element(const Matrix3Xd& x) {
  mesh::SurfaceMesh m;
  m.nodes = x;
  m.elements = {{0, 1, 2, 3, 4, 5}};
  m.kind = {mesh::NodeKind::Vertex, mesh::NodeKind::Vertex, mesh::NodeKind::Vertex,
            mesh::NodeKind::MidSide, mesh::NodeKind::MidSide, mesh::NodeKind::MidSide};
  m.node_element_offsets = {0, 1, 2, 3, 4, 5, 6};
  m.node_elements = {0, 0, 0, 0, 0, 0};
  return m;
}

struct Element {
  Matrix3Xd x, q;
  // J(x0, x(ξ,η))·q(ξ,η) |x_ξ × x_η| at a reference point.
  Vector3d integrand(const Vector3d& x0, double xi, double eta) const {
    const auto n = mesh::p2_shape(xi, eta);
    const auto g = mesh::p2_shape_gradients(xi, eta);
    Vector3d p = Vector3d::Zero(), t1 = Vector3d::Zero(), t2 = Vector3d::Zero(), qq = Vector3d::Zero();
    for (int a = 0; a < 6; ++a) {
      p += n[a] * (x.col(a) - x0);
      t1 += g[0][a] * x.col(a);
      t2 += g[1][a] * x.col(a);
      qq += n[a] * q.col(a);
    }
    const Vector3d r = -p;
    Vector3d u = Vector3d::Zero();
    kernel::add_stokeslet(r(0), r(1), r(2), qq(0), qq(1), qq(2), 1.0 / r.norm(), t1.cross(t2).norm(), u(0), u(1), u(2));
    return u;
  }
  Vector3d rule(const Vector3d& x0, const Tri& t) const {
    const auto& r = quadrature::triangle_rule(6);
    const double ax = t[1][0] - t[0][0], ay = t[1][1] - t[0][1], bx = t[2][0] - t[0][0], by = t[2][1] - t[0][1];
    const double area2 = std::abs(ax * by - ay * bx);
    Vector3d s = Vector3d::Zero();
    for (int k = 0; k < r.size(); ++k) {
      const double u = r.points[k][1], v = r.points[k][2];
      s += r.weights[k] * integrand(x0, t[0][0] + u * ax + v * bx, t[0][1] + u * ay + v * by);
    }
    return 0.5 * area2 * s;
  }
};

std::array<Tri, 4> children(const Tri& t) {
  auto mid = [&](int a, int b) {
    return std::array<double, 2>{0.5 * (t[a][0] + t[b][0]), 0.5 * (t[a][1] + t[b][1])};
  };
  const auto m01 = mid(0, 1), m12 = mid(1, 2), m20 = mid(2, 0);
  return {Tri{t[0], m01, m20}, Tri{m01, t[1], m12}, Tri{m20, m12, t[2]}, Tri{m12, m20, m01}};
}

// Brute force: sub-triangles touching the singular point are split down to depth 40 (their share is
// O(size)); the others adaptively until the 12-point rule and its 4-child refinement agree to `tol`.
Vector3d reference(const Element& el, const Vector3d& x0, const std::array<double, 2>& ps, const Tri& t, int depth,
                   long& evals) {
  const bool singular = std::any_of(t.begin(), t.end(), [&](const auto& v) { return v == ps; });
  const auto ch = children(t);
  if (singular) {
    if (depth >= 40) return el.rule(x0, t);
    Vector3d s = Vector3d::Zero();
    for (const auto& c : ch) s += reference(el, x0, ps, c, depth + 1, evals);
    return s;
  }
  const Vector3d coarse = el.rule(x0, t);
  Vector3d fine = Vector3d::Zero();
  for (const auto& c : ch) fine += el.rule(x0, c);
  evals += 60;
  if ((fine - coarse).norm() < 1e-15 || depth >= 60) return fine;
  Vector3d s = Vector3d::Zero();
  for (const auto& c : ch) s += reference(el, x0, ps, c, depth + 1, evals);
  return s;
}

TEST(DuffyIntegral, MatchesAdaptiveReferenceOnCurvedElement) {
  // A strongly curved element: an icosahedron face of the unit sphere (P2 nodes on the sphere), stretched
  // anisotropically, with a non-uniform load.
  const auto sphere = mesh::make_sphere_mesh(0);
  Element el;
  el.x.resize(3, 6);
  el.q.resize(3, 6);
  for (int a = 0; a < 6; ++a) {
    const Vector3d X = sphere.nodes.col(sphere.elements[0][a]);
    el.x.col(a) << 1.3 * X(0), 0.8 * X(1) + 0.1 * X(0), X(2);
    el.q.col(a) << 1.0 + 0.3 * a, -0.5 + 0.1 * a * a, 0.2 - 0.4 * a;
  }
  const auto m = one_element(el.x);
  constexpr double kRef[6][2] = {{0, 0}, {1, 0}, {0, 1}, {0.5, 0}, {0.5, 0.5}, {0, 0.5}};
  const Tri whole{{{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}}};
  for (const int order : {4, 6, 10, 16}) {
    SingleLayerOptions opt;
    opt.duffy_order = order;
    SingleLayer op(m, opt);
    const Matrix3Xd u = op.apply(el.x, el.q);
    double worst = 0.0;
    for (int l = 0; l < 6; ++l) {
      long evals = 0;
      const Vector3d ref = reference(el, el.x.col(l), {kRef[l][0], kRef[l][1]}, whole, 0, evals);
      const double err = (u.col(l) - ref).norm() / ref.norm();
      worst = std::max(worst, err);
      if (order == 16) std::printf("  node %d (%s): |ref| %.6f, rel error %.2e (%ld reference evaluations)\n", l,
                                   l < 3 ? "corner" : "mid-side", ref.norm(), err, evals);
      if (order == 16) {
        EXPECT_LT(err, 1e-12) << "local node " << l;
      }
      if (order == 10) {
        EXPECT_LT(err, 1e-8) << "local node " << l;
      }
      if (order == 6) {  // on a level-0 element (the default is 8)
        EXPECT_LT(err, 1e-5) << "local node " << l;
      }
    }
    std::printf("  Duffy order %2d: worst rel error over the 6 nodes %.2e\n", order, worst);
  }
}

}  // namespace
}  // namespace capsim::stokes
