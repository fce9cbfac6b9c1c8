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
///  - Far-field tier (Options::far_degree > 0; off by default): the all-pairs sum above uses a COARSE rule
///    (degree 1: centroid, or degree 2: 3 points) on every element instead. An element e is "far" from a
///    target x0 when |x0 − c_e| > far_radius · ρ_e (c_e the mean of its 6 nodes, ρ_e their largest distance
///    from c_e); for it the coarse rule is the final answer. Every other ("mid") element, and always the
///    target's own elements and near-singular neighbours, gets one contiguous block "regular rule minus
///    coarse rule" (the coarse points with negated weights) added per target, so after this step the sum is
///    exactly the regular-rule sum on all non-far elements and the corrections below apply unchanged. The
///    mid elements of a target are found with a uniform grid of element centroids (cell = ½ far_radius ·
///    max ρ_e), rebuilt every call in O(N) because the geometry moves between calls; the mid blocks are
///    laid out in the grid's cell order so that a target's blocks form a few contiguous runs.
///    Accuracy: the coarse rule's relative error on an element at distance d is ~ (ρ_e/d)^(far_degree+1);
///    summed over the surface the far-field error is ~ ρ · far_radius^(−far_degree), i.e. only O(h) at a
///    fixed radius (the method itself converges at order ~3). Measured (tests/benchmarks/stokes_bench.cc,
///    deformed surface, levels 2–4): degree 1 costs 25–100× the discretisation error at any radius; degree 2
///    at radius 4 costs ~0.15× of it, and pays off (1.3×, one thread) only from level 4 on, because the
///    singular correction and the mid blocks (~60 elements per target at radius 4) are a fixed cost.
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
///    the near-singular neighbour lists and the subdivided rule, and the coarse and "regular − coarse" rules
///    of the far-field tier. Element centroids, radii and the centroid grid are rebuilt by every apply().
///  - The mesh connectivity (elements, node_element CSR, mirror_node, node count) must not change after
///    construction; the mesh object itself need not outlive the SingleLayer (connectivity is copied).
///  - Positions and loads may change freely between calls (nothing geometric is cached between calls).
///  - apply() reuses internal work arrays (including per-thread scratch of the far-field tier): one
///    SingleLayer must not be used by two threads at once. It is internally OpenMP-parallel.
///  - far_degree = 0 gives bit for bit the result of the operator without the far-field tier.

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
  /// Far-field tier (see the file comment): 0 = off (every element gets the regular rule for every target),
  /// 1 = centroid rule, 2 = 3-point degree-2 rule on elements farther than far_radius · ρ_e from the target.
  int far_degree = 0;
  double far_radius = 4.0;     ///< far when |x0 − c_e| > far_radius · ρ_e; must be > 1
  Symmetry symmetry = Symmetry::Auto;
  double symmetry_tol = 1e-10; ///< relative tolerance of the symmetry check
  KernelChoice kernel = KernelChoice::Fast;
  kernel::FastConfig fast{};   ///< tuning of the fast kernel
};

/// @brief Timing and size of the last apply() (seconds).
struct SingleLayerStats {
  bool used_symmetry = false;  ///< whether only half of the targets were evaluated
  int targets = 0;             ///< number of targets evaluated
  int sources = 0;             ///< quadrature points of the all-pairs sum (unpadded; coarse rule if far on)
  double build_s = 0.0;        ///< laying out the quadrature points (SoA)
  double regular_s = 0.0;      ///< regular Stokeslet sum
  double singular_s = 0.0;     ///< singular and near-singular corrections (including their point layout)
  double far_s = 0.0;          ///< far-field tier: centroid grid and "regular − coarse" blocks (0 when off)
  long long mid_elements = 0;  ///< Σ over targets of the elements given the regular rule (0 when off)
  double total_s = 0.0;
};

/// @brief u(x0) = ∫_S J(x0, x)·q(x) dS(x) at every node (see the file comment).
class SingleLayer {
 public:
  /// @throws std::invalid_argument for an unknown rule degree, duffy_order < 1, far_degree ∉ {0, 1, 2},
  /// far_radius ≤ 1, or an inconsistent mesh.
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
  // reg = SoA (x, y, z, qx, qy, qz) holding each element's regular-rule points at [s·stride, s·stride + nq),
  // s = slot[e] (or e if slot is null).
  // Lays out the points of `rule` on every element as the padded SoA sources of the all-pairs sum.
  kernel::Sources layout_sources(const std::vector<ShapeAt>& rule, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q);
  void singular_correction(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q, const std::vector<int>& targets,
                           const double* const reg[6], int stride, const int* slot, Eigen::Matrix3Xd& u) const;
  // Far-field tier: centroids, radii and grid of the current x, then the per-target mid blocks into u.
  void build_centroid_grid(const Eigen::Matrix3Xd& x);
  long long mid_correction(const std::vector<int>& targets, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& u);

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
  std::vector<ShapeAt> coarse_;             // far-field rule (empty if off)
  std::vector<ShapeAt> mid_rule_;           // regular rule, then the coarse rule negated (empty if off)
  // Work arrays (SoA sources, targets, results).
  AlignedVector sx_, sy_, sz_, sqx_, sqy_, sqz_;
  AlignedVector nx_, ny_, nz_, nqx_, nqy_, nqz_;  // near-rule points, element-major
  AlignedVector tx_, ty_, tz_, ux_, uy_, uz_;
  AlignedVector mx_, my_, mz_, mqx_, mqy_, mqz_;  // mid-rule points, block per element in slot order (far tier)
  // Far tier geometry of the current call: element centroids and radii, uniform grid (cell → elements CSR;
  // slot j = position in cell order, element cell_elements_[j]), and per slot: element, centroid and
  // (far_radius · ρ)².
  std::vector<double> cx_, cy_, cz_, rho_;
  std::vector<int> cell_offsets_, cell_elements_, cell_cursor_, cell_fill_, slot_;
  std::vector<std::array<int, 6>> sorted_elements_;
  std::vector<double> scx_, scy_, scz_, sreach2_;
  double grid_lo_[3] = {0, 0, 0}, grid_cell_ = 1.0, far_reach_ = 0.0;
  int grid_dim_[3] = {1, 1, 1};
  std::vector<std::vector<int>> mark_;      // per-thread "already added for this target" stamps (per slot)
  std::vector<std::vector<int>> slots_;     // per-thread mid slots of the current target
  std::vector<int> target_ids_;
  SingleLayerStats stats_;
};

}  // namespace capsim::stokes
