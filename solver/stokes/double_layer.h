#pragma once
/// @file
/// @brief The double-layer boundary integral of the capsule's flow, the operator of a viscosity ratio λ ≠ 1
/// (solver/README.md §3b; its second-kind equation: second_kind_solve.h).
///
/// At every node x0 of the surface mesh, DoubleLayer::apply computes the principal value
///     D[v](x0) = PV∫_S v(x)·T(x − x0)·n(x) dS(x),   T_ijk(r) = −6 r_i r_j r_k / |r|⁵,   n outward,
/// with x and v the P2 interpolants of the nodal positions and of the nodal density v over each element. The
/// kernel is kernel::add_stresslet (stokeslet.h), its one definition.
///
/// Singularity subtraction: on a smooth closed surface PV∫_S T(x − x0)·n(x) dS(x) = −4π I for x0 on S (−8π I
/// inside, 0 outside), so
///     D[v](x0) = ∫_S (v(x) − v(x0))·T(x − x0)·n(x) dS(x) − 4π v(x0).
/// The integrand of the remaining integral is bounded (T·n = O(1/r) because r·n = O(r²) on each element, and
/// v − v(x0) = O(r)), so the quadrature of the single layer applies to it unchanged:
///  1. regular part: the single layer's triangle rule (SingleLayerOptions::regular_degree) on every element, all
///     targets against all points (sources: position, density, weighted normal w·(g1 × g2));
///  2. singular part: on the elements containing the target, that rule is replaced by the single layer's Duffy
///     rules with the node at the apex (duffy_order);
///  3. near-singular part: on the elements sharing a vertex with those, by the subdivided rule (near_subdivision,
///     near_degree), as for the single layer.
/// Consequences of the subtraction, exact on the discrete surface to round-off: a rigid-body motion v = c + ω × x
/// gives D[v] = −4π v at every node (v(x) − v(x0) = ω × r is orthogonal to r, and T contracts it to 0), which is
/// what the deflation of the solve relies on. What the subtraction does not see is that a P2 surface has normal
/// jumps of O(h²) at the element edges, where the true PV would differ from −4π I by O(h²): the continuous
/// surface's identity is used on purpose (the operator then converges to the smooth surface's).
///
/// Symmetry, as the single layer (single_layer.h, phase 5): positions and density symmetric under the mirror
/// x3 → −x3 give D[v](M x0) = M D[v](x0) (T, n and v all transform with M), and odd under x → −x give
/// D[v](−x0) = −D[v](x0) (T is odd in r, n and v odd). When the scene has them (the same tests and tolerances,
/// load_symmetry_tol applied to v), only one node of each orbit is evaluated (orbit_targets) and the others are
/// filled by the symmetry (expand_mirror, expand_central).
///
/// Options: the quadrature fields of SingleLayerOptions (regular_degree, duffy_order, near_subdivision,
/// near_degree), the symmetry fields (symmetry, central_symmetry, symmetry_tol, load_symmetry_tol), so that the
/// two layers of one case integrate on the same rules with the same symmetries, and the kernel choice and
/// precision of the regular sum (kernel: Fast, the SIMD tile kernel::stresslet_sum_fast, or Plain,
/// stresslet_sum_plain; precision Mixed with Fast: stresslet_sum_mixed, float pair terms summed in double, as the
/// single layer's sum_mixed; stokeslet.h). The far-field tier is not implemented here and is ignored.
///
/// What depends on the surface alone is prepared once per x and target set and kept while they do not change
/// (every application within one second-kind solve): the positions and weighted normals of the regular points,
/// and the two corrections as matrices on the density differences. Both corrections are linear in v − v(x0), so
/// for target x0 they are Σ_b G_b (v_b − v(x0)) over the nodes b of its own and near-singular elements, G_b a
/// symmetric 3 × 3 matrix (Σ over the element's points of N_b · (−6 (r·n)/|r|⁵) r rᵀ, the stresslet of
/// kernel::add_stresslet with the density factored out): an application then lays out the density at the regular
/// points, runs the all-pairs sum and applies these matrices (a few dozen per target), in place of re-integrating
/// the Duffy and subdivided rules. The Duffy geometry stays in monomial form about the target (as before), in
/// double; the corrections are in double in both precisions.
///
/// Contract: as SingleLayer (connectivity cached from the constructor and unchanging; positions and density may
/// change freely between calls; one object must not be used by two threads at once; internally OpenMP-parallel
/// over targets; each target's sums do not depend on the thread count).

#include <string>
#include <vector>

#include <Eigen/Core>

#include "solver/mesh/mesh.h"
#include "solver/mesh/p2_tabulation.h"
#include "solver/stokes/boundary_mesh.h"
#include "solver/stokes/near_singular.h"
#include "solver/stokes/single_layer.h"
#include "solver/stokes/singular_rules.h"
#include "solver/stokes/source_layout.h"

namespace capsim::stokes {

/// @brief Timing of the last apply() (seconds).
struct DoubleLayerStats {
  bool used_symmetry = false;  ///< whether the mirror symmetry was used
  bool used_central = false;   ///< whether the central symmetry was used
  int targets = 0;          ///< number of targets evaluated
  int sources = 0;          ///< quadrature points of the regular all-pairs sum
  bool prepared = false;    ///< whether this call (re)built the surface's data (a new x or target set)
  double prepare_s = 0.0;   ///< that: the points' geometry and the correction matrices (0 when kept)
  double build_s = 0.0;     ///< symmetry checks, the density at the regular points (SoA)
  double regular_s = 0.0;   ///< regular all-pairs sum
  double singular_s = 0.0;  ///< the corrections (own elements: Duffy in, regular out; near ones: subdivided in,
                            ///< regular out), applied as the prepared matrices
  double near_s = 0.0;      ///< − 4π v(x0) and the symmetry images
  double total_s = 0.0;
};

/// @brief D[v](x0) = PV∫_S v·T·n dS at every node (see the file comment).
class DoubleLayer {
 public:
  /// @throws std::invalid_argument if !options.valid() (with its reason) or for an inconsistent mesh.
  explicit DoubleLayer(const mesh::SurfaceMesh& mesh, const SingleLayerOptions& options = {});

  /// @brief D[v] at every node; x and v are 3 × num_nodes. u is resized as needed.
  /// @throws std::invalid_argument if x or v has the wrong number of columns.
  void apply(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v, Eigen::Matrix3Xd& u);
  /// @brief Drops what was prepared for the last surface (the next apply prepares again, even on the same x). The
  /// second-kind solve calls it once per solve, so that a solve costs the same whether or not x repeats.
  void forget_surface() { prepared_ = false; }
  /// @brief Convenience overload returning D[v].
  [[nodiscard]] Eigen::Matrix3Xd apply(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v);

  /// @brief Whether (x, v) is mirror-symmetric under x3 → −x3 to the tolerances (the check apply() uses).
  [[nodiscard]] bool is_symmetric(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v) const;
  /// @brief Whether (x, v) is odd under x → −x (mesh.central_node) to the same tolerances.
  [[nodiscard]] bool is_centrally_symmetric(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v) const;

  /// @brief The flux functional of the surface x: a (3 × num_nodes) with Σ_i a_i·v_i = ∫_S v·n dS for the P2
  /// interpolant of any nodal field v, a_i = ∫_S N_i n dS over the elements of node i (n dS = g1 × g2 dξ dη; the
  /// flux moments of mesh::node_normals_and_flux_moments, exact for every P2 field), in particular 0 for every
  /// rigid-body motion on any closed P2 surface. The left eigenvector of
  /// the operator's eigenvalue 4π (∫ n·D[v] dS = 4π ∫ n·v dS on a closed surface) that the solve deflates.
  [[nodiscard]] Eigen::Matrix3Xd flux_weights(const Eigen::Matrix3Xd& x) const;

  [[nodiscard]] const DoubleLayerStats& last_stats() const { return stats_; }
  [[nodiscard]] const SingleLayerOptions& options() const { return opt_; }
  [[nodiscard]] int num_nodes() const { return topo_.num_nodes; }
  [[nodiscard]] int num_elements() const { return static_cast<int>(topo_.elements.size()); }

 private:
  [[nodiscard]] bool uses_mixed_precision() const;
  void regular_sum(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v, Eigen::Matrix3Xd& u);
  void make_correction_slots();
  void prepare_corrections(const Eigen::Matrix3Xd& x);
  void apply_corrections(const Eigen::Matrix3Xd& v, Eigen::Matrix3Xd& u) const;

  SingleLayerOptions opt_;
  BoundaryMesh topo_;
  std::vector<mesh::P2Point> regular_;    // its points (layout)
  std::vector<double> regular_shape_;     // its shape functions (a-major SoA)
  PointTable duffy_[6];                   // Duffy rule per local node position (SoA)
  std::vector<double> duffy_shape_[6];    // their shape functions
  std::vector<mesh::P2Point> near_rule_;  // subdivided rule, then the regular rule negated (empty if off)
  std::vector<double> near_shape_;        // its shape functions
  NearSingularElements near_;             // node → near-singular elements (empty if off)
  // Prepared for one surface x and target set (apply: kept while both stay the same).
  bool prepared_ = false, prepared_mirror_ = false, prepared_central_ = false;
  Eigen::Matrix3Xd prepared_x_;
  std::vector<int> targets_;              // the nodes evaluated (all, or one of each orbit)
  NormalSourceArrays sources_;            // regular points of every element (geometry prepared, density per apply)
  NormalSourceArrays near_points_;        // near-rule points of every element (geometry)
  // The corrections as matrices on the density differences: target i gets Σ_k G_k (v_{node_k} − v_i) over k in
  // [offsets[i], offsets[i+1]) (the nodes of its own and near-singular elements, fixed by the topology), G_k
  // symmetric 3 × 3 (xx, xy, xz, yy, yz, zz; prepared for the targets). own_slots_ / near_slots_: for each
  // incidence (node_offsets order) and near entry (near_.elements order), the slot of each of the element's six
  // nodes in that list (−1: the target itself).
  std::vector<int> correction_offsets_, correction_nodes_, own_slots_, near_slots_;
  std::vector<int> row_offsets_;           // the targets' rows of correction_weights_ (targets_ order)
  std::vector<double> correction_weights_;
  // Work arrays of the regular sum (targets and results as SoA).
  AlignedVector tx_, ty_, tz_, tvx_, tvy_, tvz_, ux_, uy_, uz_;
  DoubleLayerStats stats_;
};

}  // namespace capsim::stokes
