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

}  // namespace capsim::mesh
