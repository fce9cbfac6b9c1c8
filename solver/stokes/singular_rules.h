#pragma once
/// @file
/// @brief The singular rules of the single-layer operator (solver/README.md §3): for each of the six local node
/// positions of a P2 element, a Duffy (collapsed-square) rule with that node at the apex on the reference
/// triangle, and its structure-of-arrays table for the vectorised correction loop.
///
/// One sub-triangle for a corner node (the element itself); for a mid-side node the two halves through the
/// opposite vertex, each split again at the midpoint of its far edge (4 sub-triangles with ~45° apex angles,
/// on which the collapsed-square rule converges much faster than on the right-angled halves; see the
/// Duffy test). On each sub-triangle (P, A, B), P the apex, (s, t) ∈ [0,1]² ↦ P + s (A − P) + s t (B − A)
/// with Jacobian s |det(A − P, B − P)|: the s cancels the 1/r singularity, and an order × order
/// Gauss-Legendre product rule integrates the rest.

#include <vector>

#include "solver/mesh/p2_tabulation.h"
#include "solver/stokes/stokeslet.h"

namespace capsim::stokes {

/// @brief Duffy rule with local node `local` (0..5) at the apex, `order` Gauss-Legendre points per
/// direction of each collapsed square. Weights in dξ dη (Duffy Jacobian included).
std::vector<mesh::P2Point> duffy_rule(int local, int order);

/// @brief A rule as structure of arrays: the points (ξ, η) and weights w, each of length count.
struct PointTable {
  int count = 0;
  AlignedVector xi, eta, w;
};

/// @brief The SoA table of a rule.
PointTable make_point_table(const std::vector<mesh::P2Point>& rule);

/// @brief A Duffy rule in single precision for the mixed-precision correction (SingleLayerOptions::precision):
/// the points relative to the apex, (u, v) = (ξ − ξ_P, η − η_P), and the weights. Relative coordinates keep
/// the float terms accurate next to the apex, where the points crowd: a point at distance s from P is known
/// to ≈ 6e-8 · s, not 6e-8 (the element's monomials are re-expanded about P in double before rounding).
struct ApexTableF {
  int count = 0;
  double apex_xi = 0, apex_eta = 0;  ///< (ξ_P, η_P) of the local node at the apex
  std::vector<float, AlignedAllocator<float>> u, v, w;
};

/// @brief The single-precision apex table of duffy_rule(local, order).
ApexTableF make_apex_table(int local, int order);

}  // namespace capsim::stokes
