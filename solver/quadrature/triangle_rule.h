#pragma once
/// @file
/// @brief Symmetric triangle quadrature rules with positive weights (Dunavant / Radon), solver/README.md §6.

#include <array>
#include <span>
#include <vector>

namespace capsim::quadrature {

/// @brief A rule on the reference triangle. Points are barycentric (l0, l1, l2); weights sum to 1, so
/// ∫_T f dA ≈ |T| Σ w_i f(p_i) for a flat triangle of area |T|. In the parametric coordinates
/// (ξ, η) = (l1, l2) of the unit right triangle, ∫ f dξ dη ≈ ½ Σ w_i f(ξ_i, η_i).
struct TriangleRule {
  int degree = 0;                               ///< polynomial degree integrated exactly
  std::vector<std::array<double, 3>> points;    ///< barycentric coordinates
  std::vector<double> weights;                  ///< positive, sum to 1

  /// @brief Number of points.
  [[nodiscard]] int size() const { return static_cast<int>(weights.size()); }
};

/// @brief The rule of exactly this degree: 1 (1 point, centroid), 2 (3 interior points), 4 (6 points),
/// 5 (7 points) or 6 (12 points). Degrees 1 and 2 serve the far-field tier of the boundary integral.
/// @throws std::invalid_argument for any other degree.
const TriangleRule& triangle_rule(int degree);

/// @brief Gauss-Legendre rule on [0, 1] with n points (n ≥ 1): nodes and weights summing to 1.
/// Used by the collapsed-square (Duffy) singular integrals.
struct LineRule {
  std::vector<double> nodes;
  std::vector<double> weights;
};
/// @brief Gauss-Legendre rule with n points on [0, 1], exact to degree 2n − 1.
LineRule gauss_legendre(int n);

}  // namespace capsim::quadrature
