#pragma once
/// @file
/// @brief The single-layer boundary integral of the capsule's flow (solver/README.md §3).
///
/// At every node x0 of the surface mesh, SingleLayer::apply computes
///     u(x0) = ∫_S J(x0, x)·q(x) dS(x),   J = I/r + r r/r³,  r = x0 − x,
/// with x and q the P2 interpolants of the nodal positions and nodal loads over each element. It does NOT
/// include the physical prefactor: the dynamics forms the velocity as
///     v(x0) = v∞(x0) − u(x0) / (8π Ca)
/// (q = load the fluids exert on the membrane, so the membrane pushes the fluid with −q; solver/README.md §3).
/// Identity for tests: on the unit sphere, a uniform q = f gives u = (16π/3) f, i.e. v − v∞ = −2f/(3Ca).
///
/// Method, in the order apply() runs its phases:
///  1. Layout (source_layout.h): one triangle rule (degree 4/5/6) on every element; all quadrature points of
///     the surface are laid out once per call as structure-of-arrays (x, y, z and w·|∂x/∂ξ × ∂x/∂η|·q),
///     padded to the SIMD width with zero loads.
///  2. Regular part: kernel::sum_fast (or sum_plain; or sum_mixed with Options::precision = Mixed) sums them
///     for all targets.
///  3. Far-field tier (far_field.h; Options::far_degree > 0, off by default): the all-pairs sum of phase 2
///     runs over a COARSE rule instead, and each target's near ("mid") elements are upgraded back to the
///     regular rule, so the phases below apply unchanged.
///  4. Singular part (singular_rules.h): for each target node and each element containing it, the
///     regular-rule contribution of that element is subtracted and replaced by a Duffy (collapsed-square)
///     integral with the node at the apex on the exact P2 geometry, an n × n Gauss-Legendre product rule on
///     each sub-triangle (the s Jacobian cancels the 1/r singularity).
///     Near-singular part (near_singular.h): elements sharing a vertex with an element that contains the
///     target are close to it (h/2 for a mid-side node); their regular-rule contribution is replaced by a
///     subdivided rule (Options::near_subdivision, near_degree).
///  5. Mirror symmetry x3 → −x3: if positions and loads are symmetric (checked in O(N) with
///     mesh.mirror_node, to tolerances relative to the extent of x and to the largest |q|: symmetry_tol and
///     the looser load_symmetry_tol, see SingleLayerOptions), only the targets
///     with x3 ≥ 0 are evaluated and u is mirrored to the others (u3 flips sign). Otherwise every target is
///     evaluated. Options::symmetry forces either way.
///     Central symmetry x → −x (Options::central_symmetry, off by default): if positions and loads are also
///     antisymmetric under mesh.central_node (x_P(i) = −x_i, q_P(i) = −q_i, to the same tolerances), only one
///     node of each orbit of the group {identity, mirror, x → −x, half-turn about x3} is evaluated (its
///     smallest index; of each pair {i, P(i)} without the mirror), and u(−x0) = −u(x0) fills the rest; a node
///     fixed by a group element gets exactly what the symmetry prescribes (u3 = 0 on the mirror plane,
///     u1 = u2 = 0 on the x3 axis). Half the targets of the mirror alone, so half the cost of phases 2 and 4.
///
/// Contract:
///  - Cached from the constructor (depends only on connectivity and Options): element → nodes, node →
///    (element, local index) incidence, mirror map, the rule's shape functions and derivatives, the Duffy
///    points of each of the 6 local node positions with their shape functions, derivatives and weights,
///    the near-singular neighbour lists and the subdivided rule, and the coarse and "regular − coarse" rules
///    of the far-field tier. Element centroids, radii and the centroid grid are rebuilt by every apply().
///  - The mesh connectivity (elements, node_element CSR, mirror_node, node count) must not change after
///    construction; the mesh object itself need not outlive the SingleLayer (connectivity is copied).
///  - Positions and loads may change freely between calls (nothing geometric is cached between calls).
///  - apply() reuses internal work arrays (including per-thread scratch of the far-field tier): one
///    SingleLayer must not be used by two threads at once. It is internally OpenMP-parallel.
///  - far_degree = 0 gives bit for bit the result of the operator without the far-field tier.

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "solver/mesh/mesh.h"
#include "solver/mesh/p2_tabulation.h"
#include "solver/stokes/boundary_mesh.h"
#include "solver/stokes/far_field.h"
#include "solver/stokes/near_singular.h"
#include "solver/stokes/singular_rules.h"
#include "solver/stokes/source_layout.h"
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

/// @brief Working precision of the pair terms (numerics.kernel_precision). Double: every phase in double.
/// Mixed: the all-pairs regular (or far-field coarse) sum by kernel::sum_mixed — pair terms in float, sums in
/// double (its error: kernel::sum_mixed) — and the Duffy integrals of the singular correction in float too,
/// on coordinates relative to the target (so a term next to it keeps float's relative accuracy; summed in
/// float per Duffy square, in double across), while the subtraction of the regular rule from those elements and
/// the near-singular and far-field corrections stay in double (they work on absolute positions, where float
/// rounding would cost 6e-8/r relative next to the target). Ignored with KernelChoice::Plain (the reference).
enum class KernelPrecision { Double, Mixed };

/// @brief Options of the single-layer operator.
///
/// The case registry (solver/config/case_config.h) owns the user-facing keys numerics.regular_degree,
/// duffy_order, far_degree and far_radius: CapsuleFlow always fills them from the case, so a run never uses
/// the defaults below. They equal the registry's defaults (tests/solver/stokes checks it) so that a
/// default-constructed operator (tests, benchmarks, `capsim bench`) is the operator of a default case. The
/// ranges valid() accepts are what the operator can compute; the registry may restrict them further.
struct SingleLayerOptions {
  int regular_degree = 4;      ///< triangle rule for regular elements: 4 (6 pts), 5 (7 pts), 6 (12 pts)
  int duffy_order = 8;         ///< Gauss-Legendre points per direction of each Duffy square (2..64)
  /// Near-singular correction: elements that share a vertex with an element containing the target (but do
  /// not contain it) are re-integrated with `near_degree` on each of 4^near_subdivision sub-triangles
  /// (0 = off, at most 4). Without it the error at mid-side nodes (h/2 from such elements) is O(h).
  int near_subdivision = 1;
  int near_degree = 6;         ///< rule of the near-singular sub-triangles: 4, 5 or 6
  /// Far-field tier (far_field.h): 0 = off (every element gets the regular rule for every target),
  /// 1 = centroid rule, 2 = 3-point degree-2 rule on elements farther than far_radius · ρ_e from the target.
  int far_degree = 0;
  double far_radius = 4.0;     ///< far when |x0 − c_e| > far_radius · ρ_e; finite and > 1 (ignored when off)
  Symmetry symmetry = Symmetry::Auto;
  /// Also use the point reflection x → −x when the scene has it (numerics.central_symmetry; see the file
  /// comment). Off by default so that the operator of an existing case stays bit for bit what it was: the
  /// images get −u exactly where the full sum gives −u to round-off (1e-7 of |u| in mixed precision).
  /// Ignored with Symmetry::Off.
  bool central_symmetry = false;
  double symmetry_tol = 1e-10; ///< relative tolerance of the symmetry check on the positions (≥ 0)
  /// Relative tolerance of the symmetry check on the load (≥ 0), |q_i − P q_mirror(i)| ≤ tol · max |q|. Looser
  /// than the positions' on purpose: the load is a function of the positions (membrane law, bending, mass
  /// solve), so on a symmetric surface its asymmetry is the round-off of those sums, and that grows with the
  /// level and the bending stiffness — measured on a deformed a/b = 2 capsule, 1.8e-12 of max |q| on level 4
  /// without bending, 1.1e-11 with κ_b = 1e-3 and 1.1e-10 with κ_b = 1e-2 (≈ × 9 per level), which under a
  /// 1e-10 tolerance turned level-4 bending runs to the general evaluation (every target, twice the cost).
  /// Evaluating a load asymmetric by δ symmetrically changes u by O(δ) |u|: 1e-8 is far below the kernel's
  /// own error in mixed precision (3e-7) and any discretisation error, and leaves a margin of ≈ 10 for level 5.
  double load_symmetry_tol = 1e-8;
  KernelChoice kernel = KernelChoice::Fast;
  KernelPrecision precision = KernelPrecision::Double;  ///< of the fast regular sum (see KernelPrecision)
  kernel::FastConfig fast{};   ///< tuning of the fast kernel (block 1..4)

  /// @brief Whether the operator can be built with these options; if not and why is not null, *why names
  /// the first offending option, its value and its range.
  [[nodiscard]] bool valid(std::string* why = nullptr) const;
};

/// @brief Timing and size of the last apply() (seconds).
struct SingleLayerStats {
  bool used_symmetry = false;  ///< whether the mirror symmetry was used
  bool used_central = false;   ///< whether the central symmetry was used (a quarter of the targets with both)
  int targets = 0;             ///< number of targets evaluated
  int sources = 0;             ///< quadrature points of the all-pairs sum (unpadded; coarse rule if far on)
  double build_s = 0.0;        ///< symmetry check and laying out the regular and near-rule points (SoA)
  double regular_s = 0.0;      ///< regular Stokeslet sum (target selection and scatter included)
  double singular_s = 0.0;     ///< singular (Duffy) correction of the elements containing each target
  double near_s = 0.0;         ///< near-singular correction of their neighbours (and the mirror)
  double far_s = 0.0;          ///< far-field tier: centroid grid and "regular − coarse" blocks (0 when off)
  long long mid_elements = 0;  ///< Σ over targets of the elements given the regular rule (0 when off)
  double total_s = 0.0;
};

/// @brief u(x0) = ∫_S J(x0, x)·q(x) dS(x) at every node (see the file comment).
class SingleLayer {
 public:
  /// @throws std::invalid_argument if !options.valid() (with its reason) or for an inconsistent mesh.
  explicit SingleLayer(const mesh::SurfaceMesh& mesh, const SingleLayerOptions& options = {});

  /// @brief u at every node; x and q are 3 × num_nodes. u is resized as needed.
  void apply(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q, Eigen::Matrix3Xd& u);
  /// @brief Convenience overload returning u.
  [[nodiscard]] Eigen::Matrix3Xd apply(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q);

  /// @brief Whether (x, q) is mirror-symmetric under x3 → −x3 to the tolerance (the check apply() uses).
  [[nodiscard]] bool is_symmetric(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q) const;
  /// @brief Whether (x, q) is antisymmetric under x → −x (mesh.central_node) to the same tolerances.
  [[nodiscard]] bool is_centrally_symmetric(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q) const;

  [[nodiscard]] const SingleLayerStats& last_stats() const { return stats_; }
  /// @brief The nodes the last apply() evaluated (all, or one of each orbit of the symmetries used), in
  /// evaluation order.
  [[nodiscard]] const std::vector<int>& last_targets() const { return target_ids_; }
  [[nodiscard]] const SingleLayerOptions& options() const { return opt_; }
  [[nodiscard]] int num_nodes() const { return topo_.num_nodes; }
  [[nodiscard]] int num_elements() const { return static_cast<int>(topo_.elements.size()); }
  /// @brief Quadrature points of the regular rule over the whole surface (sources of the hot loop).
  [[nodiscard]] int num_quadrature_points() const { return num_elements() * rule_size_; }

  /// @brief The regular sources of the current (x, q) as SoA, padded to the SIMD width (for benchmarks).
  /// Valid until the next call of apply() or build_sources().
  kernel::Sources build_sources(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q);

 private:
  // apply() phases (see the file comment).
  void select_targets(const Eigen::Matrix3Xd& x, bool symmetric, bool central);
  void regular_sum(const kernel::Sources& src, Eigen::Matrix3Xd& u);
  long long far_field(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q, Eigen::Matrix3Xd& u);
  // The two corrections accumulate per target into ux_, uy_, uz_ (free after regular_sum), and the near
  // phase adds the total to u: the same additions in the same order as one fused loop.
  void singular_correction(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q);
  void near_correction(Eigen::Matrix3Xd& u);
  void mirror(Eigen::Matrix3Xd& u) const;
  // Whether float pair terms are in use (KernelPrecision::Mixed with the fast kernel): the regular sum and the
  // Duffy terms in float, u3 = 0 set on the mirror plane.
  [[nodiscard]] bool uses_mixed_precision() const {
    return opt_.precision == KernelPrecision::Mixed && opt_.kernel == KernelChoice::Fast;
  }

  SingleLayerOptions opt_;
  BoundaryMesh topo_;                       // connectivity, incidence, symmetry maps, target order
  int rule_size_ = 0;
  std::vector<mesh::P2Point> regular_;      // rule points
  PointTable duffy_[6];                     // Duffy rule per local node position (SoA)
  ApexTableF duffy_f_[6];                   // the same in float about the apex (mixed precision only)
  std::vector<mesh::P2Point> near_rule_;    // subdivided rule, then the regular rule negated (empty if off)
  NearSingularElements near_;               // node → near-singular elements (empty if off)
  std::vector<int> near_begin_;             // first near point of each entry of near_.elements
  std::vector<mesh::P2Point> coarse_;       // far-field rule (empty if off)
  std::vector<mesh::P2Point> mid_rule_;     // regular rule, then the coarse rule negated (empty if off)
  // Work arrays of apply().
  SourceArrays sources_;                    // all-pairs sources (regular or coarse rule)
  SourceArrays near_points_;                // near-rule points, element-major
  SourceArrays mid_points_;                 // mid-rule points, block per element in slot order (far tier)
  AlignedVector tx_, ty_, tz_, ux_, uy_, uz_;
  AlignedVector element_monomials_;         // mixed Duffy: per element 6×3 position, 6×3 load monomials
  FarFieldGrid grid_;                       // far tier geometry of the current call
  MidScratch mid_scratch_;                  // per-thread scratch of the far tier
  // Where the singular correction finds each element's regular points: SoA, block stride, slot (or null).
  const SourceArrays* regular_points_ = nullptr;
  int regular_stride_ = 0;
  const int* regular_slot_ = nullptr;
  std::vector<int> target_ids_;
  SingleLayerStats stats_;
};

}  // namespace capsim::stokes
