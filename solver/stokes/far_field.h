#pragma once
/// @file
/// @brief The far-field tier of the single-layer operator (Options::far_degree > 0; solver/README.md §3).
///
/// The all-pairs sum uses a coarse rule (degree 1: centroid, or 2: 3 points) on every element. An element e
/// is "far" from a target x0 when |x0 − c_e| > far_radius · ρ_e (c_e the mean of its 6 nodes, ρ_e their
/// largest distance from c_e); for it the coarse rule is the final answer. Every other ("mid") element, and
/// always the target's own elements and near-singular neighbours, gets one contiguous block "regular rule
/// minus coarse rule" added per target, so after this phase the sum is exactly the regular-rule sum on all
/// non-far elements and the singular and near-singular corrections apply unchanged.
///
/// The mid elements of a target are found with a uniform grid of element centroids (cell = ½ far_radius ·
/// max ρ_e), rebuilt every call in O(N) because the geometry moves between calls; the mid blocks are laid out
/// in the grid's cell order (slots) so that a target's blocks form a few contiguous runs.
///
/// Accuracy: the coarse rule's relative error on an element at distance d is ~ (ρ_e/d)^(far_degree+1);
/// summed over the surface the far-field error is ~ ρ · far_radius^(−far_degree), i.e. only O(h) at a fixed
/// radius while the method converges at order ~3. Degree 2 at radius 4 stays below the discretisation error
/// at levels 2–4; degree 1 does not. Its cost and accuracy per level are measured in results/benchmarks.md
/// ("Distance-adaptive quadrature").

#include <array>
#include <vector>

#include <Eigen/Core>

#include "solver/stokes/near_singular.h"
#include "solver/stokes/source_layout.h"

namespace capsim::stokes {

/// @brief Element centroids, radii and the centroid grid of the current positions; elements in slot order.
struct FarFieldGrid {
  /// @brief Rebuilds everything from x (O(N); NaN positions give some grid, and NaN then propagates).
  void build(const Eigen::Matrix3Xd& x, const std::vector<std::array<int, 6>>& elements, double far_radius);

  std::vector<double> cx, cy, cz, rho;              ///< per element: centroid and radius
  std::vector<int> cell_offsets, cell_elements;     ///< cell → slots CSR; slot j holds element cell_elements[j]
  std::vector<int> slot;                            ///< element → slot
  std::vector<std::array<int, 6>> sorted_elements;  ///< elements in slot order
  std::vector<double> scx, scy, scz, sreach2;       ///< per slot: centroid and (far_radius · ρ)²
  double lo[3] = {0, 0, 0}, cell = 1.0, reach = 0.0;  ///< grid origin, cell size, far_radius · max ρ
  int dim[3] = {1, 1, 1};

 private:
  std::vector<int> cursor_, fill_;
};

/// @brief Per-thread scratch of add_mid_blocks, reused between calls (no allocation in the target loop).
struct MidScratch {
  std::vector<std::vector<int>> mark;   ///< per thread, per slot: last target that listed it
  std::vector<std::vector<int>> slots;  ///< per thread: the mid slots of the current target
};

/// @brief u(x0) += Σ over the mid elements of each target of its "regular − coarse" block. mid holds the
/// blocks of mid_rule_size points per slot (laid out on grid.sorted_elements). own_offsets/own_elements:
/// node → own elements CSR. Returns Σ over targets of the mid elements. OpenMP-parallel over targets.
long long add_mid_blocks(const FarFieldGrid& grid, const SourceArrays& mid, int mid_rule_size,
                         const std::vector<int>& own_offsets, const std::vector<int>& own_elements,
                         const NearSingularElements& near, const std::vector<int>& targets,
                         const Eigen::Matrix3Xd& x, MidScratch& scratch, Eigen::Matrix3Xd& u);

}  // namespace capsim::stokes
