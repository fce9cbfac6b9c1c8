#pragma once
/// @file
/// @brief The single-layer boundary integral of the capsule's flow (DESIGN.md §3).
///
/// At every node x0 of the surface mesh, SingleLayer::apply computes
///     u(x0) = ∫_S J(x0, x)·q(x) dS(x),   J = I/r + r r/r³,  r = x0 − x,
/// with x and q the P2 interpolants of the nodal positions and nodal loads over each element. It does NOT
/// include the physical prefactor: the dynamics forms the velocity as
///     v(x0) = v∞(x0) − u(x0) / (8π Ca)
/// (q = load the fluids exert on the membrane, so the membrane pushes the fluid with −q; DESIGN.md §3).
/// Identity for tests: on the unit sphere, a uniform q = f gives u = (16π/3) f, i.e. v − v∞ = −2f/(3Ca).
///
/// Method:
///  - Regular part: one triangle rule (degree 4/5/6) on every element; all quadrature points of the surface
///    are laid out once per call as structure-of-arrays (x, y, z and w·|∂x/∂ξ × ∂x/∂η|·q), padded to the
///    SIMD width with zero loads, and summed for all targets by kernel::sum_fast (or sum_plain).
///  - Singular part: for each target node and each element containing it, the regular-rule contribution of
///    that element is subtracted and replaced by a Duffy (collapsed-square) integral with the node at the
///    apex on the exact P2 geometry: one sub-triangle for a corner node; for a mid-side node the two halves
///    through the opposite vertex (DESIGN.md §3), each split again at the midpoint of its far edge (4
///    sub-triangles with ~45° apex angles: error 3e-6 → 1e-9 at n = 10 on a curved level-0 element), an
///    n × n Gauss-Legendre product rule on each (the s Jacobian cancels the 1/r singularity).
///  - Near-singular part: elements sharing a vertex with an element that contains the target are close to
///    it (h/2 for a mid-side node); their regular-rule contribution is replaced by a subdivided rule
///    (Options::near_subdivision, near_degree). The neighbour lists come from connectivity only.
///  - Mirror symmetry x3 → −x3: if positions and loads are symmetric (checked in O(N) with
///    mesh.mirror_node, to a tolerance relative to the extent of x and the largest |q|), only the targets
///    with x3 ≥ 0 are evaluated and u is mirrored to the others (u3 flips sign). Otherwise every target is
///    evaluated. Options::symmetry forces either way.
///
/// Contract:
///  - Cached from the constructor (depends only on connectivity and Options): element → nodes, node →
///    (element, local index) incidence, mirror map, the rule's shape functions and derivatives, the Duffy
///    points of each of the 6 local node positions with their shape functions, derivatives and weights,
///    the near-singular neighbour lists and the subdivided rule.
///  - The mesh connectivity (elements, node_element CSR, mirror_node, node count) must not change after
///    construction; the mesh object itself need not outlive the SingleLayer (connectivity is copied).
///  - Positions and loads may change freely between calls (nothing geometric is cached between calls).
///  - apply() reuses internal work arrays: one SingleLayer must not be used by two threads at once. It is
///    internally OpenMP-parallel.

#include <vector>

#include <Eigen/Core>

#include "solver/mesh/mesh.h"
#include "solver/stokes/stokeslet.h"

namespace capsim::stokes {

/// @brief Use of the x3 → −x3 mirror symmetry.
enum class Symmetry {
  Auto,  ///< use it when positions and loads are symmetric to the tolerance, else evaluate all targets
  Off,   ///< always evaluate every target (reference / testing)
  On,    ///< require it: apply() throws std::invalid_argument if the scene is not symmetric
};

/// @brief Which Stokeslet sum the regular part uses.
enum class KernelChoice { Fast, Plain };

/// @brief Options of the single-layer operator.
struct SingleLayerOptions {
  int regular_degree = 4;      ///< triangle rule for regular elements: 4 (6 pts), 5 (7 pts), 6 (12 pts)
  int duffy_order = 6;         ///< Gauss-Legendre points per direction of each Duffy square (≥ 1)
  /// Near-singular correction: elements that share a vertex with an element containing the target (but do
  /// not contain it) are re-integrated with `near_degree` on each of 4^near_subdivision sub-triangles
  /// (0 = off). Without it the error at mid-side nodes (h/2 from such elements) is O(h).
  int near_subdivision = 1;
  int near_degree = 6;         ///< rule of the near-singular sub-triangles: 4, 5 or 6
  Symmetry symmetry = Symmetry::Auto;
  double symmetry_tol = 1e-10; ///< relative tolerance of the symmetry check
  KernelChoice kernel = KernelChoice::Fast;
  kernel::FastConfig fast{};   ///< tuning of the fast kernel
};

/// @brief Timing and size of the last apply() (seconds).
struct SingleLayerStats {
  bool used_symmetry = false;  ///< whether only half of the targets were evaluated
  int targets = 0;             ///< number of targets evaluated
  int sources = 0;             ///< quadrature points (unpadded)
  double build_s = 0.0;        ///< laying out the quadrature points (SoA)
  double regular_s = 0.0;      ///< regular Stokeslet sum
  double singular_s = 0.0;     ///< singular and near-singular corrections (including their point layout)
  double total_s = 0.0;
};

/// @brief u(x0) = ∫_S J(x0, x)·q(x) dS(x) at every node (see the file comment).
class SingleLayer {
 public:
  /// @throws std::invalid_argument for an unknown rule degree or duffy_order < 1, or an inconsistent mesh.
  explicit SingleLayer(const mesh::SurfaceMesh& mesh, const SingleLayerOptions& options = {});

  /// @brief u at every node; x and q are 3 × num_nodes. u is resized as needed.
  void apply(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q, Eigen::Matrix3Xd& u);
  /// @brief Convenience overload returning u.
  [[nodiscard]] Eigen::Matrix3Xd apply(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q);

  /// @brief Whether (x, q) is mirror-symmetric under x3 → −x3 to the tolerance (the check apply() uses).
  [[nodiscard]] bool is_symmetric(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q) const;

  [[nodiscard]] const SingleLayerStats& last_stats() const { return stats_; }
  [[nodiscard]] const SingleLayerOptions& options() const { return opt_; }
  [[nodiscard]] int num_nodes() const { return num_nodes_; }
  [[nodiscard]] int num_elements() const { return static_cast<int>(elements_.size()); }
  /// @brief Quadrature points of the regular rule over the whole surface (sources of the hot loop).
  [[nodiscard]] int num_quadrature_points() const { return num_elements() * rule_size_; }

  /// @brief The regular sources of the current (x, q) as SoA, padded to the SIMD width (for benchmarks).
  /// Valid until the next call of apply() or build_sources().
  kernel::Sources build_sources(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q);

 private:
  struct ShapeAt {
    double w;                   // weight in the reference (ξ, η) measure (includes ½ or the Duffy Jacobian)
    double n[6], dxi[6], deta[6];
  };

  static void layout(const std::vector<ShapeAt>& rule, const std::vector<std::array<int, 6>>& elements,
                     const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q, AlignedVector& px, AlignedVector& py,
                     AlignedVector& pz, AlignedVector& pqx, AlignedVector& pqy, AlignedVector& pqz, int width);
  void singular_correction(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q, const std::vector<int>& targets,
                           Eigen::Matrix3Xd& u) const;

  SingleLayerOptions opt_;
  int num_nodes_ = 0;
  int rule_size_ = 0;
  std::vector<std::array<int, 6>> elements_;
  std::vector<int> node_offsets_;           // node → incidences CSR
  std::vector<int> inc_element_, inc_local_;
  std::vector<int> mirror_;                 // empty if the mesh has none
  std::vector<ShapeAt> regular_;            // rule points
  std::vector<ShapeAt> duffy_[6];           // per local node position
  /// The same Duffy points as structure of arrays (vectorised loop): n[a], dxi[a], deta[a] for a = 0..5,
  /// then w, each of length duffy_count_[l].
  struct ShapeTable {
    int count = 0;
    AlignedVector n[6], dxi[6], deta[6], w;
  };
  ShapeTable duffy_soa_[6];
  std::vector<ShapeAt> near_rule_;          // subdivided rule, then the regular rule negated (empty if off)
  std::vector<int> near_offsets_, near_elements_;  // node → near-singular elements CSR
  // Work arrays (SoA sources, targets, results).
  AlignedVector sx_, sy_, sz_, sqx_, sqy_, sqz_;
  AlignedVector nx_, ny_, nz_, nqx_, nqy_, nqz_;  // near-rule points, element-major
  AlignedVector tx_, ty_, tz_, ux_, uy_, uz_;
  std::vector<int> target_ids_;
  SingleLayerStats stats_;
};

}  // namespace capsim::stokes
