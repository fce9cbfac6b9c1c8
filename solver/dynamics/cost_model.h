#pragma once
/// @file
/// @brief What a case costs, as one model: the campaign's case order and progress ETA
/// (CaseParams::estimated_cost), `capsim bench flow`'s repeat count and the cost statements of
/// campaign/README.md all read it. The measured constants live here, each with the results/ file and section
/// it comes from.

#include "solver/config/case_config.h"

namespace capsim::dynamics {

/// @brief The symmetry a scene's flow evaluation uses (solver/README.md §3). It sets how many nodes the
/// boundary integral evaluates and on how many elements the membrane and its load are computed.
enum class SceneSymmetry {
  kNone,              ///< the general scene: every node a target (a capsule whose axis leaves the shear plane)
  kMirror,            ///< x3 → −x3: half the nodes (every capsule that starts with its axis in the shear plane)
  kMirrorAndCentral,  ///< and x → −x (numerics.central_symmetry): a quarter of the nodes, half the membrane
  kCentral,           ///< x → −x alone (an axis out of the plane with numerics.central_symmetry): half the nodes,
                      ///< half the membrane
};

/// @brief The relative cost of cases, in milliseconds of one thread of the machine of the "Flow evaluation by
/// phase" section of results/benchmarks.md (the AVX2 EPYC). One flow evaluation on mesh level L costs
///
///     E(L) = kRegularSumMs · 16^(L−3) · p / σ + (kCorrectionsMs / σ + kMembraneMs / σ_m + kRestMs) · 4^(L−3)
///
/// : the all-pairs regular Stokeslet sum (targets × sources, both ∝ N), the singular and near-singular
/// corrections (a fixed set of points per target), the membrane and its load solve, and the rest (point
/// layout, volume correction: ∝ N, on the whole surface whatever the symmetry). σ is the boundary integral's
/// reduction by the symmetry (1 none, 2 mirror, 4 mirror and central), σ_m the membrane's and load's (2 with
/// the central symmetry, else 1), p = 1 / kMixedSumSpeedup
/// with numerics.kernel_precision = "mixed" (only the all-pairs sum gets faster), else 1. A case costs
///
///     t_end · (flow evaluations per unit time) · (E(L) + n_D · D(L)),
///
/// the evaluations per unit time from the solver's own step rule on the reference mesh
/// (evaluations_per_unit_time: the RKC stages grow as (Ca h)^−1/2, with the bending stiffness
/// capsule.bending_modulus as sqrt(1 + ρ_b/ρ_el), and with a viscosity ratio λ as sqrt(2/(1 + λ)), the stiffness
/// factor). At λ ≠ 1 each evaluation also solves the second-kind equation: n_D applications of the double layer
/// (double_layer_applications: the GMRES iterations and the warm starts' initial residuals, about
/// kGmresIterationsPerDecade per decade of numerics.viscosity_tolerance), each costing
///
///     D(L) = kDoubleLayerPerSingleLayer · (kRegularSumMs · 16^(L−3) · p + kCorrectionsMs · 4^(L−3)) / σ
///
/// (the double layer has the single layer's quadrature and symmetries, its own precision: p = 1 /
/// kMixedSumSpeedup with numerics.double_layer_precision = "mixed", else 1; its set-up per solve is spread over
/// the applications in the constant). n_D = 0 at λ = 1.
///
/// Not a prediction of seconds: periodic cases stop before t_end, the prestress adds stages along a run, and
/// other machines share the work out differently (the AVX-512 kernel makes the all-pairs sum a smaller share).
/// What it is for: the ratios between cases — of one level (wall ∝ cost^0.75 within a level,
/// EtaModel::kCostExponent), and of one case across levels, symmetries and precisions.
class CostModel {
 public:
  /// @brief The scene's symmetry as the solver uses it: a capsule whose axis starts in the shear plane
  /// (capsule.tilt = 0) has the mirror (the boundary integral detects it), one tilted out of it has not (the mesh
  /// clears its mirror map, solver/README.md §1b); numerics.central_symmetry adds the point symmetry, which holds
  /// for every orientation.
  static SceneSymmetry symmetry(const config::CaseConfig& config);
  /// @brief Milliseconds of one flow evaluation on mesh level @p level (the formula of the class comment).
  static double evaluation_ms(int level, SceneSymmetry symmetry, bool mixed_precision);
  /// @brief Milliseconds of one flow evaluation of @p config's scene.
  static double evaluation_ms(const config::CaseConfig& config);
  /// @brief Applications of the double layer per flow evaluation: 0 at λ = 1, else the expected GMRES
  /// iterations of a warm-started solve to numerics.viscosity_tolerance (kGmresIterationsPerDecade per decade).
  static double double_layer_applications(const config::CaseConfig& config);
  /// @brief Milliseconds of one application of the double layer on mesh level @p level (class comment).
  static double double_layer_ms(int level, SceneSymmetry symmetry, bool mixed_precision);
  /// @brief Relative cost of a whole case whose reference mesh has smallest node spacing @p h_min, in
  /// seconds of the reference machine (see the class comment for what that is not).
  static double case_cost(const config::CaseConfig& config, double h_min);

  /// @brief The all-pairs regular sum of a level-3 evaluation over all 2562 targets, double precision:
  /// 35.70 ms (results/benchmarks.md, "Flow evaluation by phase", level 3, 1 thread, general scene).
  static constexpr double kRegularSumMs = 35.70;
  /// @brief The singular (Duffy) and near-singular corrections of the same evaluation: 9.25 + 5.37 ms (ibid.).
  static constexpr double kCorrectionsMs = 9.25 + 5.37;
  /// @brief The membrane and its load solve in the same evaluation: 1.48 + 2.70 ms (ibid.).
  static constexpr double kMembraneMs = 1.48 + 2.70;
  /// @brief The rest of the same evaluation (layout, volume correction, timers): 56.26 ms less the parts
  /// above (ibid.). With these four the model gives 31.1 ms for the symmetric scene (measured 32.01 ms),
  /// 10.9× from level 3 to 4 (measured 10.3×), and 1.89× from the central symmetry at level 3 (measured 1.77×
  /// in mixed precision: results/benchmarks.md, "Central symmetry x → −x").
  static constexpr double kRestMs = 56.26 - kRegularSumMs - kCorrectionsMs - kMembraneMs;
  /// @brief How much faster the regular sum is in mixed precision inside an evaluation: 18.5 ms against
  /// 7.4 ms at level 3 (results/benchmarks.md, "Mixed precision").
  static constexpr double kMixedSumSpeedup = 2.5;
  /// @brief One double-layer application (its per-solve set-up spread over the solve's applications) against the
  /// single layer's regular sum and corrections in the same precision, same scene, same run: 0.85–1.15 in mixed
  /// precision (medians 0.96 symmetric, 0.89 general, 0.95 central) and 0.86–0.97 in double, level 3, 1 thread
  /// (results/benchmarks.md, "The viscosity-ratio evaluation by phase").
  static constexpr double kDoubleLayerPerSingleLayer = 0.9;
  /// @brief Double-layer applications per decade of the relative tolerance (iterations, and one initial
  /// residual for each warm-started solve, about half of them): 8.56 + 0.5 at 1e-8, 6.22 + 0.5 at 1e-6 and 3.82
  /// + 0.5 at 1e-4 (λ = 5, level 2, the main preset's numerics; 8.33 iterations at 1e-8 on level 3;
  /// results/benchmarks.md, "The viscosity-ratio evaluation by phase"): 1.1 per decade.
  static constexpr double kGmresIterationsPerDecade = 1.1;
};

}  // namespace capsim::dynamics
