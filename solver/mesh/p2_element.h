#pragma once
/// @file
/// @brief The 6-node quadratic (P2) triangle: shape functions and their derivatives on the reference
/// triangle (ξ, η) ∈ {ξ ≥ 0, η ≥ 0, ξ + η ≤ 1}. Local node order: vertices 0, 1, 2 at (0,0), (1,0), (0,1);
/// mid-side nodes 3 on edge 0–1, 4 on edge 1–2, 5 on edge 2–0.

#include <array>

namespace capsim::mesh {

/// @brief Values N_a(ξ, η) of the six P2 shape functions.
inline std::array<double, 6> p2_shape(double xi, double eta) {
  const double l0 = 1.0 - xi - eta;
  return {l0 * (2.0 * l0 - 1.0), xi * (2.0 * xi - 1.0), eta * (2.0 * eta - 1.0),
          4.0 * l0 * xi,         4.0 * xi * eta,        4.0 * eta * l0};
}

/// @brief Derivatives ∂N_a/∂ξ (first array) and ∂N_a/∂η (second array).
inline std::array<std::array<double, 6>, 2> p2_shape_gradients(double xi, double eta) {
  const double l0 = 1.0 - xi - eta;
  return {{{1.0 - 4.0 * l0, 4.0 * xi - 1.0, 0.0, 4.0 * (l0 - xi), 4.0 * eta, -4.0 * eta},
           {1.0 - 4.0 * l0, 0.0, 4.0 * eta - 1.0, -4.0 * xi, 4.0 * xi, 4.0 * (l0 - eta)}}};
}

/// @brief Monomial coefficients of a P2 interpolant of nodal values f_a (one component):
///     f(ξ, η) = c0 + c1 ξ + c2 η + c3 ξ² + c4 ξη + c5 η²,
/// so that f = c0 + ξ (c1 + c3 ξ + c4 η) + η (c2 + c5 η), ∂f/∂ξ = c1 + 2 c3 ξ + c4 η and
/// ∂f/∂η = c2 + c4 ξ + 2 c5 η: position and both tangents at a point for 8 multiply-adds per component
/// instead of 18 for the three sums Σ_a over the nodal shape functions (the hot loops of the boundary
/// integral use it; the two forms agree to rounding).
inline void p2_monomials(const double f[6], double c[6]) {
  c[0] = f[0];
  c[1] = -3.0 * f[0] - f[1] + 4.0 * f[3];
  c[2] = -3.0 * f[0] - f[2] + 4.0 * f[5];
  c[3] = 2.0 * f[0] + 2.0 * f[1] - 4.0 * f[3];
  c[4] = 4.0 * (f[0] + f[4] - f[3] - f[5]);
  c[5] = 2.0 * f[0] + 2.0 * f[2] - 4.0 * f[5];
}

/// @brief The monomial coefficients of a vector field (c[m][k] = coefficient m of component k) of an element.
inline void p2_monomials3(const double f[6][3], double c[6][3]) {
  for (int k = 0; k < 3; ++k) {
    const double fk[6] = {f[0][k], f[1][k], f[2][k], f[3][k], f[4][k], f[5][k]};
    double ck[6];
    p2_monomials(fk, ck);
    for (int m = 0; m < 6; ++m) c[m][k] = ck[m];
  }
}

/// @brief Value f and tangents ∂f/∂ξ, ∂f/∂η at (ξ, η) of a vector field in monomial form (p2_monomials3).
/// Used by scalar loops (the mass matrix). The two `omp simd` loops of the boundary integral (layout and Duffy,
/// solver/stokes/) write the same formula out by hand: through this helper's array arguments GCC 12 leaves
/// them in memory and the Duffy loop ran 3× slower (measured with `capsim bench flow`).
inline void p2_monomial_geometry(const double c[6][3], double xi, double eta, double f[3], double g1[3], double g2[3]) {
  for (int k = 0; k < 3; ++k) {
    const double a = c[1][k] + xi * c[3][k] + eta * c[4][k], b = c[2][k] + eta * c[5][k];
    f[k] = c[0][k] + xi * a + eta * b;
    g1[k] = a + xi * c[3][k];
    g2[k] = b + xi * c[4][k] + eta * c[5][k];
  }
}

/// @brief Value at (ξ, η) of a vector field in monomial form.
inline void p2_monomial_value(const double c[6][3], double xi, double eta, double f[3]) {
  for (int k = 0; k < 3; ++k)
    f[k] = c[0][k] + xi * (c[1][k] + xi * c[3][k] + eta * c[4][k]) + eta * (c[2][k] + eta * c[5][k]);
}

}  // namespace capsim::mesh
