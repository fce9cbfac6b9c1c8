#pragma once
/// @file
/// @brief The second-kind boundary integral equation of a viscosity ratio λ ≠ 1 and its GMRES solve with
/// Wielandt deflation (solver/README.md §3b).
///
/// For the surface velocity v at the nodes, given f = v∞ − S[q]/(8π Ca) (the λ = 1 velocity: the undisturbed
/// flow and the single layer, solver/README.md §3):
///     (1 + λ)/2 · v − (1 − λ)/(8π) · D[v] = f,          D the double layer (double_layer.h).
/// Divided by (1 + λ)/2, with κ = (1 − λ)/(1 + λ) ∈ (−1, 1) and K = D/(4π):
///     A v := v − κ K v = g,     g = 2 f/(1 + λ).
/// K has the eigenvalue −1 on the six rigid-body motions (exactly, also discretely: double_layer.h) and +1 on
/// one "volume" mode, whose left eigenvector is the normal (∫ n·K[v] dS = ∫ n·v dS on a closed surface); the rest of
/// its spectrum lies inside (−1, 1). So A has the eigenvalues 1 + κ = 2/(1 + λ) (rigid motions) and 1 − κ =
/// 2λ/(1 + λ) (volume mode), which go to 0 as λ → ∞ and λ → 0: the iteration stalls on them.
///
/// Wielandt deflation (Pozrikidis, "Boundary integral and singularity methods", 1992, ch. 4 and 6), with Q (3N × 6)
/// an orthonormal basis of the nodal rigid motions, a the flux functional (DoubleLayer::flux_weights: aᵀv = ∫ v·n
/// dS) and u = n_h/(aᵀ n_h) the node normals scaled to aᵀu = 1: GMRES solves
///     Â w := w − κ (K w + Q Qᵀ w − u aᵀ w) = g,
/// in which K + Q Qᵀ − u aᵀ has the rigid motions (exact right eigenvectors, aᵀQ = 0) and the volume mode (a its
/// left eigenvector up to the discretisation error) moved to the eigenvalue 0, so Â has them at 1 and the rest of
/// A's spectrum unchanged: the iteration count stays bounded as λ → 0 or ∞. The velocity is recovered exactly as
///     v = w − κ/(1 + κ) Q Qᵀ w
/// (A Q = (1 + κ) Q), and then solves A v + κ u (aᵀv) = g: the original equation where the volume mode's flux term
/// is replaced. For a right-hand side without flux (aᵀg = 0: any v∞ of an incompressible flow and any single
/// layer, whose flux vanishes on a closed surface) the two equations have the same solution, and v's flux is
/// aᵀv ≈ aᵀg; without deflation the discretisation error of aᵀg is amplified by 1/(1 − κ) into a spurious
/// volume change instead. Discretely aᵀg is of the size of the discretisation error, which the flow's volume
/// correction removes in either case (solver/README.md §3).
///
/// Warm start: the initial guess v0 enters as w0 = v0 + κ Q Qᵀ v0 (the inverse of the recovery).
/// λ = 1 (κ = 0): v = f, without applying D.

#include <string>

#include <Eigen/Core>

#include "solver/mesh/mesh.h"
#include "solver/stokes/double_layer.h"

namespace capsim::stokes {

/// @brief Options of the second-kind solve.
struct SecondKindOptions {
  /// Relative residual ‖g − Â w‖ / ‖g‖ (Euclidean over the nodal values) to stop at; in (0, 1).
  double tolerance = 1e-8;
  int max_iterations = 200; ///< Krylov iterations (operator applications) at most, over all restarts; ≥ 1
  int restart = 40;         ///< Krylov vectors kept before a restart (GMRES(m)); 1..500
  bool deflate = true;      ///< Wielandt deflation of the rigid-body motions and the volume mode (file comment)

  /// @brief Whether the solve can run with these options; if not and why is not null, *why names the first
  /// offending option, its value and its range.
  [[nodiscard]] bool valid(std::string* why = nullptr) const;
};

/// @brief Outcome of a solve. Non-convergence is an outcome, not an exception: v then holds the last iterate.
struct SecondKindResult {
  bool converged = false;
  int iterations = 0;      ///< Krylov iterations (one application of D each)
  int applications = 0;    ///< applications of D in all: the iterations and the warm start's initial residual
  /// Relative residual of the system solved (the deflated one with `deflate`) at the end, carried through the
  /// Arnoldi relation (no extra application).
  double residual = 0.0;
  /// "converged", "initial guess already converged", "viscosity ratio 1", "iteration limit", "breakdown" or
  /// "non-finite residual".
  std::string reason;
  // Wall time of the solve by phase (seconds): the deflation set-up (rigid-motion basis, flux weights, node
  // normals), the applications of D summed by DoubleLayerStats phase, and the whole solve; what is left of
  // total_s is GMRES's own work (orthogonalisation, deflation terms, vector updates).
  double setup_s = 0.0;          ///< SystemOperator set-up (0 without deflation)
  double layer_prepare_s = 0.0;  ///< DoubleLayerStats::prepare_s, summed over the applications
  double layer_layout_s = 0.0;   ///< DoubleLayerStats::build_s, summed
  double layer_regular_s = 0.0;  ///< DoubleLayerStats::regular_s, summed
  double layer_singular_s = 0.0; ///< DoubleLayerStats::singular_s, summed
  double layer_near_s = 0.0;     ///< DoubleLayerStats::near_s, summed
  double total_s = 0.0;          ///< the whole solve_second_kind call
};

/// @brief Solves (1 + λ)/2 · v − (1 − λ)/(8π) · D[v] = f on the surface x (see the file comment).
/// @param mesh the mesh of `layer` (its node normals build the volume mode's deflation vector)
/// @param v on entry the initial guess if it is 3 × N (warm start), else ignored (cold start from w = 0); on
///          return the solution (or the last iterate if not converged)
/// @throws std::invalid_argument if λ is not a finite number > 0, the options are invalid, or x, f do not have
///         one column per node.
SecondKindResult solve_second_kind(DoubleLayer& layer, const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x,
                                   double lambda, const Eigen::Matrix3Xd& f, Eigen::Matrix3Xd& v,
                                   const SecondKindOptions& options = {});

}  // namespace capsim::stokes
