#pragma once
/// @file
/// @brief The near-singular part of the single-layer operator (solver/README.md §3). Elements that share a vertex
/// with an element containing the target (but do not contain it) are close to it — h/2 for a mid-side
/// node — and the regular rule's error there is O(h). Their regular-rule contribution is replaced by a
/// subdivided rule. The neighbour lists depend on connectivity only.

#include <vector>

#include "solver/mesh/mesh.h"
#include "solver/mesh/p2_tabulation.h"

namespace capsim::stokes {

/// @brief The rule `degree` on each of the 4^subdivision sub-triangles of the reference triangle (regular
/// 4-split, `subdivision` times); weights in dξ dη.
std::vector<mesh::P2Point> subdivided_rule(int subdivision, int degree);

/// @brief Node → near-singular elements, CSR: elements sharing a vertex with an element that contains the
/// node, excluding those elements themselves.
struct NearSingularElements {
  std::vector<int> offsets;   ///< num_nodes + 1
  std::vector<int> elements;  ///< of node i at [offsets[i], offsets[i + 1])
};

/// @brief The near-singular elements of every node of the mesh.
NearSingularElements near_singular_elements(const mesh::SurfaceMesh& mesh);

}  // namespace capsim::stokes
