#pragma once
/// @file
/// @brief The node fields of a snapshot (what ParaView colours): the membrane load q and its normal part
/// q·n, the velocity v, and the principal tensions tau_min and tau_max (units of Gs), so that the compressed
/// regions (tau_min < 0, where a membrane without bending stiffness wrinkles) are visible.
///
/// The mechanics gives the tensions at the quadrature points of each element. They are brought to the nodes
/// by an area-weighted average over the quadrature points of the elements around each node:
///   τ(a) = Σ_{e ∋ a} Σ_k dA_{e,k} τ_{e,k} / Σ_{e ∋ a} Σ_k dA_{e,k},
/// dA the current area element times the rule weight. The weights are positive (unlike the P2 shape
/// functions at the quadrature points, which the L2 projection would use), so the nodal value lies between
/// the smallest and largest tension around the node: a compressed node is one surrounded by compression,
/// and a uniform tension is reproduced exactly. It smooths over one ring of elements, which is the
/// resolution of the mesh anyway.

#include <array>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "solver/dynamics/time_stepper.h"
#include "solver/io/case_file.h"
#include "solver/membrane/membrane_mechanics.h"
#include "solver/mesh/mesh.h"

namespace capsim::driver {

/// @brief Principal tensions at the nodes.
struct NodalTensions {
  Eigen::VectorXd tau_min;  ///< the smaller principal tension
  Eigen::VectorXd tau_max;  ///< the larger principal tension
};

/// @brief The area-weighted nodal average (file comment) of the principal tensions.
/// @param tensions one pair per quadrature point, element-major, in either order (the smaller of each pair
///        goes to tau_min: no ordering of τ1, τ2 is assumed)
/// @param degree the triangle rule of those points
/// @throws std::invalid_argument if the sizes do not match the mesh and rule.
NodalTensions nodal_principal_tensions(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x,
                                       std::span<const std::array<double, 2>> tensions, int degree);

/// @brief The fields of a snapshot of state x: q_n, q, velocity (from the step's first stage, @p start: no
/// flow evaluation of its own), tau_min, tau_max.
std::vector<io::NodeField> snapshot_fields(const mesh::SurfaceMesh& mesh, const membrane::MembraneMechanics& mechanics,
                                           const Eigen::Matrix3Xd& x, const dynamics::StartFields& start,
                                           int membrane_degree);

}  // namespace capsim::driver
