#pragma once
/// @file
/// @brief The connectivity every boundary-integral operator of the capsule's surface works on (the single layer,
/// the double layer; solver/README.md §3): the elements, the node → (element, local index) incidence, the
/// mirror and central node maps, and the order in which targets are evaluated. Built once from the mesh and
/// checked; it depends on connectivity only, so positions and fields may change freely between evaluations.

#include <array>
#include <vector>

#include <Eigen/Core>

#include "solver/mesh/mesh.h"

namespace capsim::stokes {

/// @brief Connectivity of a boundary operator (copied from the mesh, which need not outlive it).
struct BoundaryMesh {
  int num_nodes = 0;
  std::vector<std::array<int, 6>> elements;
  std::vector<int> node_offsets;             ///< node → incidences, CSR (num_nodes + 1)
  std::vector<int> inc_element, inc_local;   ///< incidence k: the element and the node's local index (0..5) in it
  std::vector<int> mirror;                   ///< image under x3 → −x3; empty if the mesh has none
  std::vector<int> central;                  ///< image under x → −x; empty if the mesh has none
  /// Nodes in the order targets are evaluated: the order of their first element. The mesh's elements come from
  /// recursive subdivision (children of one parent are consecutive), so this order is spatially coherent and
  /// consecutive targets of the correction loops read the same neighbouring elements from cache. Each target's
  /// own sums do not depend on the order.
  std::vector<int> node_order;
};

/// @brief The boundary connectivity of a mesh.
/// @throws std::invalid_argument if an element refers to a missing node or the node → element lists are
/// inconsistent with the elements.
BoundaryMesh make_boundary_mesh(const mesh::SurfaceMesh& mesh);

/// @brief Whether positions x and a nodal field f map onto themselves under the node map `image` with the sign
/// pattern `signs` (mesh::kMirrorSigns, mesh::kCentralSigns): x to x_tol relative to its extent, f to f_tol relative
/// to its largest |f|. False if the map is empty or the sizes differ. The symmetry test of every operator.
bool symmetric_scene(const std::vector<int>& image, const std::array<double, 3>& signs, const Eigen::Matrix3Xd& x,
                     const Eigen::Matrix3Xd& f, double x_tol, double f_tol);

/// @brief The nodes an operator evaluates, in node_order: all of them; or with `mirror` one of each mirror pair
/// (the one with the larger x3; a node on the plane is its own image and is evaluated); or with `central` one node
/// of each orbit of the group {identity, x → −x} (with `mirror` too: {identity, mirror, x → −x, half-turn about
/// x3}), its smallest index. The maps needed must exist (b.mirror for `mirror`, b.central for `central`).
std::vector<int> orbit_targets(const BoundaryMesh& b, const Eigen::Matrix3Xd& x, bool mirror, bool central);

/// @brief The result at the mirror images of the targets of orbit_targets(…, mirror = true, central = false):
/// u(M x0) = M u(x0), M = diag(1, 1, −1). With `zero_on_plane`, u3 = 0 is set exactly at a target on the plane
/// (what the symmetry prescribes; for float sums, which leave it at 1e-7 |u|); otherwise such a u is left as it is.
void expand_mirror(const BoundaryMesh& b, const std::vector<int>& targets, bool zero_on_plane, Eigen::Matrix3Xd& u);

/// @brief The result at every member of each orbit of orbit_targets(…, mirror, central = true), for a field odd
/// under x → −x: u(−x0) = −u(x0), and with `mirror` also u(M x0) = M u(x0) and on the half-turn R = M P about x3
/// u(R x0) = R u(x0). The components the group sets to zero at a target it fixes (u3 on the mirror plane, u1, u2 on
/// the x3 axis) are set exactly.
void expand_central(const BoundaryMesh& b, const std::vector<int>& targets, bool mirror, Eigen::Matrix3Xd& u);

}  // namespace capsim::stokes
