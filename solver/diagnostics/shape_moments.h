#pragma once
/// @file
/// @brief Volume, area, centroid and second moments of the region enclosed by a closed P2 surface, and its
/// ellipsoid of inertia in the shear plane (solver/README.md §5; seed paper §3.1, eq. 11).

#include <Eigen/Core>

#include "solver/mesh/mesh.h"

namespace capsim::diagnostics {

/// @brief Integral properties of the enclosed volume V and of its boundary S.
struct ShapeMoments {
  double volume = 0;                                       ///< |V| = 1/3 ∫_S x·n dS
  double area = 0;                                         ///< |S|
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();      ///< c = 1/|V| ∫_V x dV
  Eigen::Matrix3d second_moment = Eigen::Matrix3d::Zero(); ///< ∫_V (x − c)_i (x − c)_j dV
};

/// @brief Moments of the volume bounded by the P2 surface with node positions x (one column per node of
/// `mesh`), integrated on the exact curved P2 geometry by the divergence theorem:
///   |V| = 1/3 ∫ x·n dS,  ∫_V x_i dV = 1/4 ∫ x_i (x·n) dS,  ∫_V x_i x_j dV = 1/5 ∫ x_i x_j (x·n) dS.
/// With n dS = (∂x/∂ξ × ∂x/∂η) dξ dη exactly, the integrands are polynomials in (ξ, η) of degree 4 (volume),
/// 6 (first moments) and 8 (second moments); so the degree-6 rule (default) gives the volume and centroid of
/// the discrete P2 body exactly and the second moments with a quadrature error O(h^7), far below the O(h^3..4)
/// geometric error of P2 elements (measured in tests/solver/diagnostics/shape_moments_test.cc). The area (a square root) is never exact. The integrals are taken
/// about the node mean, not the origin, to avoid cancellation when the capsule is far from it.
/// @param rule_degree 4, 5 or 6 (see quadrature::triangle_rule).
/// @throws std::invalid_argument if x has the wrong number of columns.
ShapeMoments shape_moments(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, int rule_degree = 6);

/// @brief The ellipsoid of inertia restricted to the shear plane (x1, x2).
///
/// An ellipsoid of volume V with semi-axis L_k along a principal direction has second moment V L_k²/5 there,
/// so L_k = sqrt(5 μ_k / V) with μ_k an eigenvalue of the moment tensor. By the mirror symmetry x3 → −x3 of
/// the study's scenes, x3 is a principal direction and the two others lie in the shear plane: they are the
/// eigenvectors of the 2×2 (x1, x2) block. Off the symmetric case this block still defines the in-plane axes.
struct EllipsoidOfInertia {
  double L1 = 0;     ///< longer in-plane semi-axis
  double L2 = 0;     ///< shorter in-plane semi-axis (L1 ≥ L2)
  double L3 = 0;     ///< semi-axis along x3, sqrt(5 M33 / V)
  double D12 = 0;    ///< Taylor parameter (L1 − L2)/(L1 + L2), seed eq. (11)
  double theta = 0;  ///< inclination of the L1 axis to x1 in (−π/2, π/2], counter-clockwise positive
};

/// @brief Ellipsoid of inertia of the given moments (see EllipsoidOfInertia).
/// θ = ½ atan2(2 M12, M11 − M22); for a circular section (M11 = M22, M12 = 0) θ is 0 and meaningless.
/// @throws std::invalid_argument if the volume is not positive.
EllipsoidOfInertia ellipsoid_of_inertia(const ShapeMoments& moments);

}  // namespace capsim::diagnostics
