#pragma once
/// @file
/// @brief The P2 element at the points of a rule, tabulated once: shape functions, their derivatives and
/// weights, and from them the geometry of an element at a point — position, tangents g1 = ∂x/∂ξ,
/// g2 = ∂x/∂η, the area element |g1 × g2| — and the interpolant of a nodal field.
///
/// Every integral over the P2 surface (membrane mechanics, mass matrix, boundary integral, shape moments,
/// wrinkle diagnostics, node normals) uses this one tabulation. The sums over the six nodes run in the local
/// node order a = 0..5 starting from zero, so every caller gets the same rounding.
///
/// Weights are in the parametric measure dξ dη of the unit right triangle: for a TriangleRule (weights
/// summing to 1) w = ½ w_i, so ∫_T f dξ dη ≈ Σ w f and ∫_S f dS ≈ Σ w f |g1 × g2|.

#include <array>
#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "solver/mesh/p2_element.h"
#include "solver/quadrature/triangle_rule.h"

namespace capsim::mesh {

/// @brief One point on the reference triangle: weight, shape values N_a and derivatives ∂N_a/∂ξ, ∂N_a/∂η.
struct P2Point {
  double w = 0.0;  ///< weight in dξ dη (½ w_i for a triangle rule; a sub-triangle or Duffy Jacobian included)
  double xi = 0.0, eta = 0.0;  ///< the point on the reference triangle
  double n[6] = {}, dxi[6] = {}, deta[6] = {};
};

/// @brief P2Point at (ξ, η) with weight w.
inline P2Point p2_point(double xi, double eta, double w) {
  P2Point p;
  p.w = w;
  p.xi = xi;
  p.eta = eta;
  const auto n = p2_shape(xi, eta);
  const auto g = p2_shape_gradients(xi, eta);
  for (int a = 0; a < 6; ++a) {
    p.n[a] = n[a];
    p.dxi[a] = g[0][a];
    p.deta[a] = g[1][a];
  }
  return p;
}

/// @brief Tangents of the P2 map at a point: g1 = ∂x/∂ξ, g2 = ∂x/∂η (g1 × g2 is the outward normal times
/// the area element for the mesh's orientation).
struct Tangents {
  Eigen::Vector3d g1, g2;
};

/// @brief A rule's points tabulated once; the geometry of any element at any of them.
class P2Tabulation {
 public:
  /// @brief No points (to be assigned later).
  P2Tabulation() = default;
  /// @brief The points of a triangle rule, weights ½ w_i (parametric measure).
  explicit P2Tabulation(const quadrature::TriangleRule& rule);
  /// @brief Arbitrary points (e.g. sub-triangle or Duffy rules, or the six nodes with weight 0).
  explicit P2Tabulation(std::vector<P2Point> points) : points_(std::move(points)) {}
  /// @brief The tabulation of quadrature::triangle_rule(degree) (throws std::invalid_argument as it does).
  static P2Tabulation of_degree(int degree) { return P2Tabulation(quadrature::triangle_rule(degree)); }
  /// @brief The six local nodes, weight 0 (for nodal quantities such as node normals).
  static P2Tabulation at_nodes();

  [[nodiscard]] int size() const { return static_cast<int>(points_.size()); }
  [[nodiscard]] const P2Point& operator[](int q) const { return points_[static_cast<std::size_t>(q)]; }
  [[nodiscard]] std::span<const P2Point> points() const { return points_; }
  /// @brief Weight of point q in dξ dη.
  [[nodiscard]] double weight(int q) const { return (*this)[q].w; }

  /// @brief Σ_a N_a(q) f_a over the element's nodes: position (f = x) or any nodal vector field.
  [[nodiscard]] Eigen::Vector3d interpolate(const Eigen::Matrix3Xd& f, const std::array<int, 6>& el, int q) const {
    const P2Point& p = (*this)[q];
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    for (int a = 0; a < 6; ++a) v += p.n[a] * f.col(el[a]);
    return v;
  }
  /// @brief The same for an element's nodal values already gathered (columns in local node order).
  [[nodiscard]] Eigen::Vector3d interpolate(const Eigen::Matrix<double, 3, 6>& fe, int q) const {
    const P2Point& p = (*this)[q];
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    for (int a = 0; a < 6; ++a) v += p.n[a] * fe.col(a);
    return v;
  }
  /// @brief Tangents g1, g2 of element el of the surface x at point q.
  [[nodiscard]] Tangents tangents(const Eigen::Matrix3Xd& x, const std::array<int, 6>& el, int q) const {
    const P2Point& p = (*this)[q];
    Tangents t{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    for (int a = 0; a < 6; ++a) {
      t.g1 += p.dxi[a] * x.col(el[a]);
      t.g2 += p.deta[a] * x.col(el[a]);
    }
    return t;
  }
  /// @brief The same for an element's node positions already gathered (columns in local node order).
  [[nodiscard]] Tangents tangents(const Eigen::Matrix<double, 3, 6>& xe, int q) const {
    const P2Point& p = (*this)[q];
    Tangents t{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    for (int a = 0; a < 6; ++a) {
      t.g1 += p.dxi[a] * xe.col(a);
      t.g2 += p.deta[a] * xe.col(a);
    }
    return t;
  }
  /// @brief Area element |g1 × g2| of element el at point q (multiply by weight(q) to integrate).
  [[nodiscard]] double area_element(const Eigen::Matrix3Xd& x, const std::array<int, 6>& el, int q) const {
    const Tangents t = tangents(x, el, q);
    return t.g1.cross(t.g2).norm();
  }

 private:
  std::vector<P2Point> points_;
};

}  // namespace capsim::mesh
