#pragma once
/// @file
/// @brief The cost of one flow evaluation by named phase, measured beside the bare regular Stokeslet sum over
/// the same targets and sources in the same run (`capsim bench flow`).
///
/// The regular sum is the irreducible part of an evaluation: every target against every quadrature point,
/// O(N²). Everything else (point layout, the singular and near-singular corrections, the membrane, the load
/// solve, the volume correction) is overhead that a good implementation keeps small next to it. The figure
/// of merit is therefore the ratio
///     overhead_ratio = evaluation time / bare regular-sum time,
/// both medians of timings taken alternately in one process, so that the ratio does not depend on the
/// machine's speed or on what else runs (measured absolute times do: compare them within one run only).
///
/// Two scenes, both the a/b = 2 Skalak capsule at Ca = 0.3 with a smooth deformation: "symmetric" keeps the
/// x3 → −x3 mirror symmetry (the boundary integral evaluates half the targets, as in every run that starts
/// in the shear plane), "general" breaks it (all targets); "central" has both the mirror and the point symmetry
/// x → −x and is evaluated with numerics.central_symmetry (a quarter of the targets).

#include <string>
#include <vector>

#include "solver/config/case_config.h"

namespace capsim::dynamics {

/// @brief What to measure.
struct FlowBenchOptions {
  /// @brief The measured capsule as a case: by default the a/b = 2 Skalak capsule at Ca = 0.3 on mesh level 3
  /// in double precision; any case key may change it (scene_with). With numerics.kernel_precision "mixed" the
  /// same scene is also evaluated in double, alternately in the same run (FlowBenchScene::evaluation_double_ms):
  /// the speed-up. With flow.viscosity_ratio ≠ 1 the scene is also evaluated at λ = 1, alternately in the same
  /// run (FlowBenchScene::evaluation_equal_viscosity_ms).
  config::CaseConfig scene = scene_with({});
  int repeat = 0;  ///< timed evaluations per scene; 0 = automatic (about a second per scene, 5..400)
  /// @brief Whether the options are usable; if not and why is not null, *why says which and why (the case
  /// keys' ranges are the key registry's: the message names the key).
  [[nodiscard]] bool valid(std::string* why = nullptr) const;
  /// @brief The default scene with `section.key=value` overrides, read and checked as `capsim run --set` reads
  /// them (config::parse_case_config; a later override of a key replaces an earlier one).
  /// @throws config::ConfigError naming the key of a bad override.
  [[nodiscard]] static config::CaseConfig scene_with(const std::vector<std::string>& overrides);
};

/// @brief One scene's measurement. Times are milliseconds per evaluation.
struct FlowBenchScene {
  std::string name;             ///< "symmetric", "general" or "central"
  int nodes = 0;                ///< mesh nodes N
  int targets = 0;              ///< targets the boundary integral evaluated (N, or about N/2 with symmetry)
  int sources = 0;              ///< regular quadrature points (unpadded)
  bool used_symmetry = false;   ///< whether the evaluation used the mirror symmetry
  bool used_central = false;    ///< whether it used the point symmetry x → −x too
  int repeat = 0;               ///< timed evaluations (and as many bare sums)
  double evaluation_ms = 0.0;   ///< median wall time of CapsuleFlow::velocity
  double evaluation_double_ms = 0.0;  ///< the same in double precision (only with kernel_precision "mixed"; else 0)
  double regular_sum_ms = 0.0;  ///< median wall time of the bare kernel::sum_fast over the same targets/sources
  double overhead_ratio = 0.0;  ///< evaluation_ms / regular_sum_ms
  // Mean time per evaluation of each named phase (CapsuleFlow / SingleLayer timers).
  double membrane_ms = 0.0;     ///< kinematics and energy gradient R = ∂W/∂x
  double bending_ms = 0.0;      ///< bending energy gradient, its two mass solves included (0 without)
  double load_ms = 0.0;         ///< mass matrix assembly and M q = R
  double layout_ms = 0.0;       ///< symmetry check, quadrature points as SoA
  double regular_ms = 0.0;      ///< regular Stokeslet sum inside the evaluation
  double far_ms = 0.0;          ///< far-field tier (0 when off, the default)
  double singular_ms = 0.0;     ///< Duffy correction
  double near_ms = 0.0;         ///< near-singular correction and mirror
  double volume_ms = 0.0;       ///< velocity assembly, node normals, flux, volume correction
  double second_kind_ms = 0.0;  ///< the viscosity-ratio solve (0 at λ = 1)
  /// Mean GMRES iterations per evaluation of the viscosity-ratio solve (0 at λ = 1). Every timed evaluation starts
  /// a step (CapsuleFlow::begin_step): a cold solve, the first stage of a step, the dearest.
  double gmres_iterations = 0.0;
  /// The viscosity-ratio solve (second_kind_ms) by phase, means per evaluation (all 0 at λ = 1): the double
  /// layer's applications per evaluation and their phases (DoubleLayerStats), the deflation set-up, and the rest
  /// (GMRES's own vector work).
  double layer_applications = 0.0;
  double layer_prepare_ms = 0.0;
  double layer_layout_ms = 0.0;
  double layer_regular_ms = 0.0;
  double layer_singular_ms = 0.0;
  double layer_near_ms = 0.0;
  double deflation_setup_ms = 0.0;
  double gmres_other_ms = 0.0;
  double evaluation_equal_viscosity_ms = 0.0;  ///< the same scene at λ = 1, alternated (0 when λ = 1 already)
  /// At λ ≠ 1, the evaluation of a second stage: at x + dt v (dt the case's automatic step, v the first stage's
  /// velocity), warm-started from the first stage's solution, as the later stages of a step are (median wall
  /// time, after the timed loop), and its mean GMRES iterations. Both 0 at λ = 1.
  double evaluation_warm_ms = 0.0;
  double gmres_iterations_warm = 0.0;
  double other_ms = 0.0;        ///< mean evaluation time not in a named phase (timers, copies)
};

/// @brief The measurement of both scenes at one level.
struct FlowBenchReport {
  int level = 0;
  int threads = 0;              ///< OpenMP threads (omp_get_max_threads at the call)
  std::string isa;              ///< instruction set of the Stokeslet kernel
  std::vector<FlowBenchScene> scenes;
};

/// @brief Measure (see the file comment). Runs on the current OpenMP thread count.
/// @throws std::invalid_argument if !options.valid().
FlowBenchReport bench_flow(const FlowBenchOptions& options);

}  // namespace capsim::dynamics
