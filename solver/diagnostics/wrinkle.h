#pragma once
/// @file
/// @brief Indicators of membrane wrinkling and mesh-scale noise (issue 6 stress tests).
///
/// A capsule membrane without bending stiffness cannot carry compression: where the smaller principal
/// tension τ2 is negative the continuum problem is ill posed and the discrete one buckles at the mesh scale
/// (the seed discusses the same for its small-Ca oblate cases). Two numbers tell a user whether a run is in
/// that situation:
///  - the compressed area fraction: the share of the current surface where τ2 < 0;
///  - the load roughness: RMS over the nodes of (q·n)_i minus its average over the node's mesh neighbours,
///    divided by the RMS of q·n. For a smooth load the difference is O(h²) (a discrete Laplacian), so the
///    roughness falls like h² (about 4× per mesh level); mesh-scale oscillations (wrinkles, an incipient instability) make
///    it O(1).

#include <span>
#include <vector>

#include <Eigen/Core>

#include "solver/mesh/mesh.h"

namespace capsim::diagnostics {

/// @brief Wrinkle indicators of one state.
struct WrinkleIndicators {
  double compressed_area_fraction = 0;  ///< share of the area with τ2 < 0 (0 … 1)
  double load_roughness = 0;            ///< RMS(q·n − neighbour mean) / RMS(q·n) (0 for a uniform q·n)
};

/// @brief Share of the current area where the smaller principal tension is negative.
/// @param tensions principal tensions (τ1, τ2) at every quadrature point, element-major, as returned by
///        membrane::MembraneMechanics::principal_tensions with the rule of `degree`.
/// @param degree the triangle rule of those points (4, 5 or 6), whose weights the area is summed with.
/// @throws std::invalid_argument if the sizes do not match the mesh and the rule.
double compressed_area_fraction(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x,
                                std::span<const std::array<double, 2>> tensions, int degree);

/// @brief Roughness of the normal load q·n (see the file comment). Returns 0 when q·n vanishes everywhere.
/// @throws std::invalid_argument if x or q do not have one column per node.
double load_roughness(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q);

}  // namespace capsim::diagnostics
