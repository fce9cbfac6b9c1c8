#pragma once
/// @file
/// @brief Volume, area, centroid and second moments of the region enclosed by a closed P2 surface, and its
/// ellipsoid of inertia in the shear plane (solver/README.md §5; seed paper §3.1, eq. 11) and in 3D.

#include <array>

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

/// @brief The full (3D) ellipsoid of inertia: the ellipsoid with the volume's second moments, for a shape in
/// any orientation (off the shear plane x3 need not be a principal direction, and the in-plane block no longer
/// gives the principal axes).
///
/// With μa ≥ μb ≥ μc the eigenvalues of the moment tensor M = ∫_V (x − c)(x − c)ᵀ dV and ea, eb, ec its unit
/// eigenvectors, the semi-axes are
///   L_k = sqrt(5 μ_k / V),  k = a, b, c,  so La ≥ Lb ≥ Lc,
/// the relation of EllipsoidOfInertia (an ellipsoid of semi-axis L along a principal direction has the second
/// moment V L²/5 there), now for all three directions. An exact ellipsoid gives its own semi-axes and axes.
///
/// Sign of the directions. An axis is a line: e and −e are one answer, and no rule that depends on the present
/// shape alone can orient a line that turns through a half-turn continuously (it comes back reversed). The rule
/// is that of the inclination θ and the axis azimuth: the x1 component is positive, i.e. the direction is
/// reversed exactly where the axis crosses the plane x1 = 0, as θ jumps at ±π/2. The x1 component counts as
/// zero when |e1| ≤ 1e-9 (far above the 1e-16 by which an eigenvector that lies along x3 or in the plane
/// x1 = 0 picks up round-off components, far below any real turn of an axis); then the x2 component decides, and
/// if it is also zero the x3 component. So a direction along x3 (the spheroid's third axis in the plane, or its
/// revolution axis at tilt 90) is +x3 at every step rather than flipping with round-off; an in-plane long axis
/// at inclination θ is (cos θ, sin θ, 0) with θ ∈ (−π/2, π/2], as θ; and a tumbling axis flips once per
/// half-turn, where θ does (a reader wanting a continuous direction reverses e(t) where e(t)·e(t − Δt) < 0).
/// Where two eigenvalues coincide (a sphere; a spheroid's two equal axes) the directions within their plane
/// are arbitrary, and they jump as the nearly equal μ change order.
struct EllipsoidOfInertia3D {
  double La = 0, Lb = 0, Lc = 0;  ///< semi-axes, La ≥ Lb ≥ Lc
  /// Unit directions of La, Lb, Lc, oriented as above; a right-handed or left-handed triad as it comes.
  std::array<Eigen::Vector3d, 3> axes{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
};

/// @brief The 3D ellipsoid of inertia of the given moments (see EllipsoidOfInertia3D), by
/// Eigen::SelfAdjointEigenSolver on the symmetric 3×3 moment tensor (a negative eigenvalue of round-off gives 0).
/// @throws std::invalid_argument if the volume is not positive or the moments are not finite.
EllipsoidOfInertia3D ellipsoid_of_inertia_3d(const ShapeMoments& moments);

}  // namespace capsim::diagnostics
