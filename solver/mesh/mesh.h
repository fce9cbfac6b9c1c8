#pragma once
/// @file
/// @brief Closed P2 surface meshes of the capsule: a subdivided icosahedron on the unit sphere, mapped to a
/// spheroid of revolution about x1 with semi-axes (a, b, b), a/b = r, a b² = 1 (solver/README.md §1–§2).

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace capsim::mesh {

/// @brief Vertex of the underlying flat triangulation, or mid-side node of a P2 element.
enum class NodeKind : std::uint8_t { Vertex = 0, MidSide = 1 };

/// @brief How sphere nodes are placed on the spheroid.
enum class SpheroidMap {
  /// x = (a X1, b X2, b X3): simple, but at a/b = 2 the equatorial elements are stretched twice as much
  /// along meridians as around them.
  AxisScaling,
  /// Nodes moved along meridians so that meridional arc length is proportional to the sphere's polar
  /// angle: uniform spacing along meridians, anisotropy only at the equator. The default: at a/b = 2 it
  /// lowers the worst edge ratio from 2.0 to 1.6 and raises the smallest angle from 29° to 37° while
  /// keeping element sizes more uniform than the plain scaling (measured in mesh_test).
  EqualArcLength,
  /// Nodes moved along meridians so that the map sphere → spheroid is conformal (isothermal latitude):
  /// element angles are those of the sphere mesh up to the discretisation, but element areas vary by a
  /// factor ≈ 9 at a/b = 2 (large tips, small equator), which shrinks the stable time step.
  Conformal,
};

/// @brief A closed surface of P2 triangles.
struct SurfaceMesh {
  /// Node coordinates, one column per node.
  Eigen::Matrix3Xd nodes;
  /// Element → 6 node indices (vertices 0,1,2; mid-sides 3: 0–1, 4: 1–2, 5: 2–0). Counter-clockwise seen
  /// from outside, so (x1 − x0) × (x2 − x0) points outward.
  std::vector<std::array<int, 6>> elements;
  /// Vertex or mid-side, per node.
  std::vector<NodeKind> kind;
  /// Node → elements containing it, compressed: elements of node i are
  /// node_elements[node_element_offsets[i] .. node_element_offsets[i + 1]).
  std::vector<int> node_element_offsets;
  std::vector<int> node_elements;
  /// Mirror image of each node under x3 → −x3 (itself when x3 = 0); mirror_node[mirror_node[i]] == i.
  std::vector<int> mirror_node;
  /// Image of each node under the point reflection x → −x (never itself: the origin is inside);
  /// central_node[central_node[i]] == i. Built bitwise on the sphere; the spheroid map keeps it to round-off
  /// (it maps the polar angles θ and π − θ independently), which is why every use of it has a tolerance.
  std::vector<int> central_node;
  /// The two nodes on the revolution axis of the sphere and spheroid meshes, at +x1 and −x1 before any rotation
  /// (the mid-side nodes of the icosahedron's edges (φ, 0, ±1) and (−φ, 0, ±1), exactly (±1, 0, 0) on the sphere):
  /// the material axis of the orientation diagnostics runs from pole_node[1] to pole_node[0]. −1 if absent.
  std::array<int, 2> pole_node{-1, -1};
  /// The node on the equator of the revolution axis at +x2 before any rotation (the mid-side node of the
  /// icosahedron's edge (±1, φ, 0), exactly (0, 1, 0) on the sphere, (≈0, b, 0) on the spheroid): the material
  /// point whose turn about the material axis is the membrane's spin (diagnostics/membrane_spin.h). A property of
  /// the mesh, not of a state, so a resumed run has the same one without storing it. −1 if absent.
  int equator_node = -1;
  /// Subdivision level of the icosahedron (0..6).
  int level = 0;

  [[nodiscard]] int num_nodes() const { return static_cast<int>(nodes.cols()); }
  [[nodiscard]] int num_elements() const { return static_cast<int>(elements.size()); }
};

/// @brief Unit sphere: icosahedron subdivided `level` times (0..6), 20·4^level P2 elements,
/// 10·4^level + 2 vertices and 30·4^level mid-side nodes (40·4^level + 2 nodes), all on the sphere.
/// @throws std::invalid_argument if level is outside 0..6.
SurfaceMesh make_sphere_mesh(int level);

/// @brief Semi-axes (a, b) of the spheroid with a/b = aspect_ratio and a b² = 1 (ℓ = 1).
/// @throws std::invalid_argument if aspect_ratio ≤ 0 or not finite.
std::array<double, 2> spheroid_semi_axes(double aspect_ratio);

/// @brief The capsule's reference mesh: the sphere mesh of `level` mapped to the spheroid a/b =
/// aspect_ratio (revolution axis x1) with the given map. aspect_ratio = 1 gives the unit sphere.
SurfaceMesh make_capsule_mesh(int level, double aspect_ratio, SpheroidMap map = SpheroidMap::EqualArcLength);

/// @brief The unit vector of an axis with tilt `tilt_deg` out of the plane (x1, x2) and azimuth `azimuth_deg` of
/// its projection from x1 toward x2 (capsule.tilt, capsule.azimuth): (cos t cos φ, cos t sin φ, sin t). Sines and
/// cosines of multiples of 90° are exact (0, ±1), so an axis at tilt 90 is exactly e3.
Eigen::Vector3d axis_of_orientation(double tilt_deg, double azimuth_deg);

/// @brief The rotation that puts the capsule's revolution axis e1 on axis_of_orientation(tilt, azimuth):
/// R = Rz(φ) · R2(t), first a turn by t about −x2 (e1 → (cos t, 0, sin t), e2 fixed), then by φ about x3. Its
/// columns are the images of e1, e2, e3; e2 stays in the shear plane. Which rotation about the axis itself is
/// chosen is immaterial for the exact spheroid and fixes how its mesh (not exactly axisymmetric) is placed.
Eigen::Matrix3d orientation_rotation(double tilt_deg, double azimuth_deg);

/// @brief Rotates the capsule mesh rigidly to the orientation (tilt, azimuth), in degrees: every node x ↦ R x
/// (orientation_rotation). With tilt = azimuth = 0 nothing is touched at all (no multiplication by the
/// identity), so the unrotated mesh stays bitwise what it was. The maps:
/// - central_node stays valid for any rotation, exactly: (R x) → −(R x) is x → −x, and R(−x) is bitwise −(R x)
///   (every product and sum changes sign exactly).
/// - mirror_node (x3 → −x3) stays valid at tilt 0 (a turn about x3 leaves x3 bitwise alone); at any other tilt it
///   is cleared (empty): it no longer maps the scene onto itself, and without it nothing tests or imposes the
///   mirror (is_mirror_symmetric is false, symmetrise skips it, the boundary integral takes the general path).
///   At tilt 90 the scene has the mirror again, but its map would be x1 → −x1 of the unrotated spheroid, which
///   the spheroid map keeps only to round-off; not built (such a scene pays the general path's cost).
/// @throws std::invalid_argument for angles that are not finite.
void orient_capsule_mesh(SurfaceMesh& mesh, double tilt_deg, double azimuth_deg);

/// @brief Element-shape statistics of the flat vertex triangles.
struct MeshQuality {
  double min_angle_deg = 0;           ///< smallest interior angle over all elements
  double max_edge_ratio = 0;          ///< worst longest/shortest edge within one element
  double mean_edge_ratio = 0;         ///< mean of longest/shortest edge over elements
  double min_edge = 0, max_edge = 0;  ///< global extreme edge lengths (h_min, h_max)
  double size_ratio = 0;              ///< max over min element area
};

/// @brief Quality statistics of a mesh.
MeshQuality mesh_quality(const SurfaceMesh& mesh);

/// @brief Smallest distance between two nodes of the same element, on the current positions x
/// (the h of the explicit stability limit dt ≲ c Ca h).
double min_node_spacing(const SurfaceMesh& mesh, const Eigen::Matrix3Xd& x);

/// @brief Outward unit normals at the nodes of positions x: the average of the exact P2 normals of the
/// elements around each node, evaluated at the node.
Eigen::Matrix3Xd node_normals(const SurfaceMesh& mesh, const Eigen::Matrix3Xd& x);

/// @brief node_normals and, in one pass over the elements, the flux moments of the nodes
///   m_i = Σ_{e ∋ i} ∫ N_{a(e,i)}(ξ, η) (g1 × g2)(ξ, η) dξ dη,
/// so that the flux of a P2 field v through the P2 surface is exactly ∫_S v·n dS = Σ_i v_i · m_i: the integrand
/// v_h · (g1 × g2) is a quartic in (ξ, η) (v_h quadratic, the tangents linear), which the degree-4 rule
/// integrates exactly. Sums over the elements are serial in element order (bitwise for any thread count).
/// @param scratch per-element work array, reused between calls (resized as needed).
void node_normals_and_flux_moments(const SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& normals,
                                   Eigen::Matrix3Xd& moments, std::vector<double>& scratch);
/// @brief The same for the elements of a mesh given by their connectivity alone (e.g. a boundary operator's copy);
/// x has one column per node.
void node_normals_and_flux_moments(std::span<const std::array<int, 6>> elements, const Eigen::Matrix3Xd& x,
                                   Eigen::Matrix3Xd& normals, Eigen::Matrix3Xd& moments, std::vector<double>& scratch);

/// @brief Parse a spheroid-map name ("conformal" | "equal-arc-length" | "axis-scaling").
/// @throws std::invalid_argument naming the accepted values.
SpheroidMap parse_spheroid_map(const std::string& name);

/// @brief Sign patterns of the symmetries as diagonal maps: the mirror x3 → −x3 and the point reflection x → −x.
inline constexpr std::array<double, 3> kMirrorSigns{1.0, 1.0, -1.0};
inline constexpr std::array<double, 3> kCentralSigns{-1.0, -1.0, -1.0};

/// @brief Whether the nodal field v maps onto itself under a symmetry: Σ_k |v(k, image[i]) − signs[k] v(k, i)| ≤ tol
/// (absolute) at every node i; false for a NaN or if image does not have one entry per column of v. The one check
/// behind the mesh's and the boundary integral's symmetry tests (positions, loads).
bool symmetric_under(std::span<const int> image, const std::array<double, 3>& signs, const Eigen::Matrix3Xd& v,
                     double tol);

/// @brief Whether x is mirror-symmetric under x3 → −x3 (mirror_node pairs) to `tol` relative to the extent
/// of x; false if the mesh has no mirror map.
bool is_mirror_symmetric(const SurfaceMesh& m, const Eigen::Matrix3Xd& x, double tol);

/// @brief One element of a symmetry group of the mesh: the node each node maps to, and the signs it puts on a vector.
struct NodeSymmetry {
  std::vector<int> map;
  std::array<double, 3> sign{};
};
/// @brief The non-identity elements of the group generated by the mirror x3 → −x3 and/or the point reflection
/// x → −x: the mirror (kMirrorSigns), the point reflection (kCentralSigns) and, with both, their product, the
/// half-turn about x3 (node map mirror then x → −x), in that order. Empty if neither is asked or the mesh lacks a map
/// the group needs.
std::vector<NodeSymmetry> symmetry_group(const SurfaceMesh& m, bool mirror, bool central);

/// @brief The elements under the group generated by the mirror x3 → −x3 and/or the point reflection x → −x (and
/// their product, the half-turn about x3): one representative element per orbit (the smallest index), and every
/// other element as the image of its representative under one group element — which element, the signs that group
/// element puts on a vector (mirror kMirrorSigns, x → −x kCentralSigns, their product), and where each local node of
/// the representative lands in it. Per-element quantities that are even (energy, tensions, element mass matrices)
/// or equivariant vectors (membrane forces) are then computed on the representatives alone: a half of the elements
/// with one symmetry, a quarter with both (an element that is its own image — across the mirror plane — forms a
/// smaller orbit and is computed whole). Empty if the mesh lacks a map the group needs (then the caller computes
/// every element).
struct ElementOrbits {
  struct Image {
    int element = 0;               ///< the image element
    int from = 0;                  ///< its representative
    std::array<int, 6> local{};    ///< local node a of `from` is local node local[a] of `element`
    std::array<double, 3> sign{};  ///< S_g of the group element
  };
  std::vector<int> representatives;
  std::vector<Image> images;
  [[nodiscard]] bool empty() const { return representatives.empty(); }
};
ElementOrbits element_orbits(const SurfaceMesh& m, bool mirror, bool central);

/// @brief Whether x is centrally symmetric, x_central(i) = −x_i for every node, to `tol` relative to the
/// extent of x; false if the mesh has no central map.
bool is_centrally_symmetric(const SurfaceMesh& m, const Eigen::Matrix3Xd& x, double tol);

/// @brief Makes x exactly symmetric under the group generated by the chosen symmetries: the mirror x3 → −x3
/// (`mirror`, the default) and the point reflection x → −x (`central`); with both, also their product, the
/// half-turn (x1, x2, x3) → (−x1, −x2, x3) about the x3 axis. Each orbit of nodes (2 or 4 nodes; 2 on the
/// mirror plane or the x3 axis) becomes, at its smallest node index, the mean of its members mapped back
/// there, and is written to the other members by exact sign changes: the result is bitwise symmetric and
/// bitwise idempotent (an exactly symmetric x is unchanged), and a node on the plane gets x3 = 0.
/// Why: a state that starts symmetric stays symmetric under the exact flow, but round-off (the CG's residual
/// in the load, sums in node order) makes the discrete state drift off it, and once the loads' asymmetry
/// passes the boundary integral's test every evaluation costs the general scene's (twice the mirror-symmetric
/// one's; results/benchmarks.md, "Whole cases, old build against new"). The central part: a spheroid centred
/// at the origin in linear shear keeps x → −x under the exact flow (v∞(−x) = −v∞(x)), whatever the
/// orientation of its axis, and a state kept exactly so lets the boundary integral evaluate one node of each
/// orbit (stokes::SingleLayerOptions::central_symmetry). Does nothing for a symmetry the mesh has no map of.
void symmetrise(const SurfaceMesh& m, Eigen::Matrix3Xd& x, bool mirror = true, bool central = false);

}  // namespace capsim::mesh
