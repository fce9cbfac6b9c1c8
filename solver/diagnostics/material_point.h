#pragma once
/// @file
/// @brief The material point P of the seed's figure 1: a membrane node initially on the short axis of the
/// capsule in the shear plane, followed through the motion (near its initial place when tumbling, carried
/// around the shape by the membrane rotation when swinging).

#include <Eigen/Core>

#include "solver/mesh/mesh.h"

namespace capsim::diagnostics {

/// @brief Index of the node chosen as material point P on the initial positions x.
///
/// The short in-plane axis of the initial ellipsoid of inertia (direction of L2, perpendicular to the
/// inclination θ) gives the target point c + L2 e, with e oriented toward +x2 if it is nearer x2 than x1, else toward +x1.
/// P is the node nearest that target among the nodes lying in the shear plane (mirror_node[i] == i, i.e.
/// x3 = 0); if there are none, among all nodes. Hence for a/b = 2 (axis along x1) P is the node nearest
/// (0, b, 0); for a/b = 0.5 the short axis is x1 and P is the node nearest (a, 0, 0).
/// A sphere has no short axis: when the initial D12 is below `round_D12` (default 1e-3, far above the
/// discretisation noise of a meshed sphere, far below the study's D12 = 1/3) e is taken along +x2, the same
/// choice as for the prolate capsule, so P is the in-plane node nearest (0, R, 0).
/// @throws std::invalid_argument if x does not match the mesh.
int choose_material_point(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, double round_D12 = 1e-3);

}  // namespace capsim::diagnostics
