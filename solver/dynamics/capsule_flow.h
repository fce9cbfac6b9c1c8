#pragma once
/// @file
/// @brief The capsule's velocity field dx/dt = v(x) (solver/README.md §2–§3): on positions x, the membrane gives
/// the load q (M q = ∂W/∂x), and the single-layer integral gives
///   v(x0) = v∞(x0) − 1/(8π Ca) ∫_S J(x0, x)·q(x) dS,   v∞ = (x2, 0, 0).
/// One call of `velocity` is one "flow evaluation", the unit of cost of the time integrators.
///
/// Volume correction (numerics.volume_correction, default on): the exact flow has ∫_S v·n dS = 0, the
/// discrete one does not, and the enclosed volume drifts (−1.2% over γ̇t = 60 at level 3, −3.6% at level 2
/// for a/b = 2, Ca = 0.9). The drift is not harmless: a capsule losing volume becomes flaccid and its
/// tensions fall period after period (max τmin fell from +0.062 to +0.025 over five periods at level 3),
/// which biases CaH. With the correction, v ← v − c n with n the node normals and c chosen so that the
/// discrete flux ∫ v·n dS (P2 interpolation, exact geometry, integrated exactly: mesh::node_normals_and_flux_moments)
/// is exactly zero: a uniform
/// normal velocity of the size of the discretisation error, vanishing under refinement.

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "solver/config/case_config.h"
#include "solver/membrane/bending.h"
#include "solver/membrane/load_solver.h"
#include "solver/membrane/membrane_law.h"
#include "solver/membrane/membrane_mechanics.h"
#include "solver/mesh/mesh.h"
#include "solver/mesh/p2_tabulation.h"
#include "solver/stokes/single_layer.h"

namespace capsim::dynamics {

/// @brief Side results of one flow evaluation. boundary_velocity fills the boundary fields (max_speed,
/// used_symmetry, used_central, volume_flux) alone; velocity fills all.
struct FlowEvaluation {
  double tau_min = 0.0;         ///< smallest principal tension on x
  double tau_max = 0.0;         ///< largest principal tension on x
  double max_speed = 0.0;       ///< max |v − v∞| over the nodes (before the volume correction)
  bool used_symmetry = false;   ///< whether the boundary integral used the mirror symmetry
  bool used_central = false;    ///< whether it used the point symmetry x → −x (numerics.central_symmetry)
  double volume_flux = 0.0;     ///< ∫ v·n dS of the uncorrected discrete velocity (0 for the exact flow)
  double bending_energy = 0.0;  ///< W_b on x (0 without bending stiffness)
  double max_bending_moment = 0.0;  ///< max κ_b |c − c0| on x (solver/membrane/bending.h)
};

/// @brief Accumulated wall time of the phases of flow evaluations (exafmm-style named phases), whichever
/// public phase of CapsuleFlow ran them. The boundary integral's total (stokes_s) is split into the
/// SingleLayer phases (SingleLayerStats).
struct FlowTimings {
  double membrane_s = 0.0;   ///< kinematics, elastic energy gradient
  double bending_s = 0.0;    ///< bending energy gradient with its two mass solves (0 when κ_b = 0)
  double load_s = 0.0;       ///< mass matrix assembly + factorisation + solve
  double stokes_s = 0.0;     ///< boundary integral: the sum of the five phases below
  double layout_s = 0.0;     ///< symmetry check, quadrature points laid out as SoA
  double regular_s = 0.0;    ///< regular Stokeslet sum over all quadrature points
  double far_s = 0.0;        ///< far-field tier (0 when off)
  double singular_s = 0.0;   ///< Duffy correction of the elements containing each node
  double near_s = 0.0;       ///< near-singular correction of their neighbours, mirror
  double second_kind_s = 0.0;  ///< the SecondKindSolve of a viscosity contrast (0 without one)
  double volume_s = 0.0;     ///< v = v∞ − u/(8πCa), node normals, flux and volume correction
  long evaluations = 0;      ///< calls of CapsuleFlow::velocity (the phases called alone do not count)
};

/// @brief Iteration counts of the second-kind solves of a CapsuleFlow since its construction (all zero at λ = 1).
struct SecondKindStatistics {
  long solves = 0;         ///< converged solves (one per boundary_velocity)
  long iterations = 0;     ///< Krylov iterations summed over them
  int max_iterations = 0;  ///< the largest count of one solve
  long applications = 0;   ///< applications of the double layer (the iterations and each warm start's residual)
  // Wall time of the solves by phase (seconds, summed; stokes::SecondKindResult): not checkpointed.
  double setup_s = 0.0;           ///< deflation set-up
  double layer_prepare_s = 0.0;   ///< double layer: the surface's point geometry and correction matrices
  double layer_layout_s = 0.0;    ///< double layer: symmetry checks, the density at the points
  double layer_regular_s = 0.0;   ///< double layer: regular all-pairs sum
  double layer_singular_s = 0.0;  ///< double layer: the singular and near-singular corrections
  double layer_near_s = 0.0;      ///< double layer: −4πv, symmetry images
  double total_s = 0.0;           ///< the solves in all
  /// @brief Mean iterations per solve (0 without solves).
  [[nodiscard]] double mean_iterations() const {
    return solves > 0 ? static_cast<double>(iterations) / static_cast<double>(solves) : 0.0;
  }
};

/// @brief The second-kind boundary integral equation of a viscosity contrast λ ≠ 1 (inner/outer viscosity),
/// the place where the interior fluid enters CapsuleFlow::boundary_velocity. With f = v∞ − S[q]/(8π Ca) the
/// surface velocity of equal viscosities (the single layer of the load), the velocity v of the contrast solves
///   (1 + λ)/2 · v(x0) − (1 − λ)/(8π) · PV∫_S v(x)·T(x − x0)·n(x) dS(x) = f(x0)
/// (../shared/DESIGN.md §10; the double layer D lives beside the single layer in solver/stokes). At λ = 1 the
/// equation is v = f and CapsuleFlow has no SecondKindSolve: the λ = 1 path is bitwise the one without the seam.
///
/// Contract for an implementation:
/// - `solve(x, f, v)`: x and f are 3 × N (nodes of the CapsuleFlow's mesh), v is output only (3 × N on
///   return). The solve is linear in f at fixed x; f already holds v∞ (zero with the background flow off).
///   CapsuleFlow applies the volume correction to the returned v (its flux, not f's, is reported).
/// - It may carry state between calls (a warm start from the previous stage's v), but `begin_step` must forget
///   it, as CapsuleFlow::begin_step does for the load: a resumed run then repeats an uninterrupted one bitwise.
/// - A solve that does not converge throws an exception derived from std::runtime_error whose what() names the
///   cause; the caller records it as the case's outcome (a numerical result, never a wrong velocity).
/// - The mirror and point symmetries hold for the double layer as for the single layer: an implementation that
///   uses them must check them on (x, f) itself, as SingleLayer does on (x, q).
class SecondKindSolve {
 public:
  virtual ~SecondKindSolve() = default;
  /// @brief v with (1+λ)/2 v − (1−λ)/(8π) D_x[v] = f on the nodes of x.
  virtual void solve(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& f, Eigen::Matrix3Xd& v) = 0;
  /// @brief A time step begins (CapsuleFlow::begin_step): drop every warm start.
  virtual void begin_step() {}
  /// @brief Iterations of the solves so far (an implementation without iterations keeps the zeros).
  [[nodiscard]] virtual SecondKindStatistics statistics() const { return {}; }
};

/// @brief Mesh, law, membrane, load solver and boundary-integral operator of one case, built once.
///
/// A flow evaluation is a composition of public phases, so that a time integrator can treat them differently
/// (an implicit bending step, the second-kind solve of a viscosity contrast) without reaching inside:
///
///   velocity(x)          = boundary_velocity(x, membrane_load(x))
///   membrane_load(x)     = M(x)⁻¹ (R_el(x) + R_b(x))     one load solve of the summed forces
///   elastic_load(x)      = M(x)⁻¹ R_el(x)                 the elastic law's part alone
///   bending_load(x)      = M(x)⁻¹ R_b(x)                  the bending part alone (0 when κ_b = 0)
///   boundary_velocity(x, q) = P_x [ K( v∞ − S_x[q]/(8π Ca) ) ]
///
/// S_x the single layer (stokes::SingleLayer), K the SecondKindSolve (the identity without one, λ = 1), P_x the
/// volume correction (numerics.volume_correction; the identity when off). membrane_load = elastic_load +
/// bending_load to the load solve's tolerance (numerics.load_tolerance, relative), not bitwise: velocity solves
/// once for the summed forces, the path every committed result was computed on. At fixed x, boundary_velocity is
/// affine in q, and linear with the background flow off (set_background_flow(false)): the form a linearly
/// implicit step needs, e.g. v = boundary_velocity(x, q_el) + (bending velocity, background off) with the second
/// term treated implicitly. Each phase adds its wall time to its FlowTimings field whoever calls it.
///
/// Contract: the mesh connectivity and reference shape are fixed at construction; every phase may be called on
/// any positions of the same mesh (3 × N). Not thread-safe (caches factorisations and work arrays); internally
/// OpenMP-parallel, and bitwise the same on any number of threads.
class CapsuleFlow {
 public:
  explicit CapsuleFlow(const config::CaseConfig& config);
  ~CapsuleFlow();

  /// @brief One flow evaluation: v on positions x (3 × N), boundary_velocity(x, membrane_load(x)); also fills q
  /// (the membrane load) when asked. With numerics.load_warm_start, the load solve starts from the previous
  /// evaluation's load within a step (begin_step).
  /// @throws membrane::DegenerateSurface if x has a collapsed element (a blow-up).
  FlowEvaluation velocity(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, Eigen::Matrix3Xd* load = nullptr);

  /// @brief The membrane load q on positions x (elastic and bending forces, one load solve from zero; no boundary
  /// integral): for diagnostics that need q but not v, and for integrators that compose the phases themselves.
  /// Not counted as a flow evaluation. Returns the membrane state (tensions, elastic forces; not the energy, NaN);
  /// with bending stiffness q includes the bending load, whose energy and largest moment last_bending() holds.
  /// @throws membrane::DegenerateSurface if x has a collapsed element.
  membrane::MembraneState membrane_load(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& q);
  /// @brief The elastic law's load alone, q = M(x)⁻¹ R_el(x) (from zero), as membrane_load without bending.
  /// @throws membrane::DegenerateSurface if x has a collapsed element.
  membrane::MembraneState elastic_load(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& q);
  /// @brief The bending load alone, q = M(x)⁻¹ R_b(x) (from zero); q = 0 (3 × N) when κ_b = 0. Returns the bending
  /// state (energy, largest moment, R_b), also kept as last_bending().
  /// @throws membrane::DegenerateSurface if x has a collapsed element.
  const membrane::BendingState& bending_load(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& q);
  /// @brief The fluids' part: v = P_x[K(v∞ − S_x[q]/(8π Ca))] for a load q (3 × N) on positions x (see the class
  /// comment). Fills the boundary fields of the returned FlowEvaluation. Not counted as a flow evaluation.
  /// @throws whatever the SecondKindSolve throws when it does not converge (never without one).
  FlowEvaluation boundary_velocity(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q, Eigen::Matrix3Xd& v);

  /// @brief Install the second-kind solve of a viscosity contrast (nullptr: none, λ = 1). The constructor
  /// installs a ViscosityContrast (viscosity_contrast.h) when flow.viscosity_ratio ≠ 1.
  void set_second_kind_solve(std::unique_ptr<SecondKindSolve> solve);
  /// @brief Iterations of the installed second-kind solve (zeros without one).
  [[nodiscard]] SecondKindStatistics second_kind_statistics() const {
    return second_kind_ ? second_kind_->statistics() : SecondKindStatistics{};
  }
  /// @brief λ = flow.viscosity_ratio of the case.
  [[nodiscard]] double viscosity_ratio() const { return viscosity_ratio_; }

  /// @brief Bending energy and largest moment of the last membrane_load / bending_load / velocity (zero without
  /// bending).
  [[nodiscard]] const membrane::BendingState& last_bending() const { return bending_state_; }
  /// @brief κ_b (capsule.bending_modulus).
  [[nodiscard]] double bending_modulus() const { return bending_ ? bending_->model().modulus() : 0.0; }

  [[nodiscard]] const mesh::SurfaceMesh& mesh() const { return *mesh_; }
  [[nodiscard]] const Eigen::Matrix3Xd& reference() const { return mesh_->nodes; }
  [[nodiscard]] const membrane::MembraneMechanics& mechanics() const { return *mechanics_; }
  [[nodiscard]] double capillary_number() const { return Ca_; }
  [[nodiscard]] const FlowTimings& timings() const { return timings_; }
  /// @brief The boundary-integral operator (benchmarks compare its phases with the bare kernel).
  [[nodiscard]] stokes::SingleLayer& single_layer() { return *single_layer_; }
  /// @brief Switch the undisturbed shear flow v∞ off (fluid at rest: relaxation tests) or on (default).
  void set_background_flow(bool on) { background_flow_ = on; }
  /// @brief A time step begins: with numerics.load_warm_start, the next `velocity` starts its load solve from
  /// zero again (later ones from the previous evaluation's load), and the SecondKindSolve drops its warm start.
  /// The driver calls it before every step, so that nothing carried between steps is missing from a checkpoint
  /// and a resumed run repeats an uninterrupted one bitwise. Without either it changes nothing.
  void begin_step();

 private:
  // How the load solve gets its mass matrix on x.
  enum class LoadMatrix {
    Assemble,           // assemble and factorise M(x): compute_load
    AssembleSymmetric,  // the same, reduced to one node of each orbit of x's symmetries: compute_load_symmetric
                        // (compute_load when x has none)
    Factorised,         // M(x) already factorised by the bending evaluation on x: solve
  };
  // The symmetries of x the load solve uses (elastic_force decides).
  struct LoadSymmetry {
    bool mirror = false;   // x3 → −x3
    bool central = false;  // x → −x (numerics.central_symmetry)
  };
  // The elastic forces on x, and the symmetries of x: with `central` the forces are those of half the elements
  // and their images. Timed as membrane_s.
  membrane::MembraneState elastic_force(const Eigen::Matrix3Xd& x, LoadSymmetry& symmetry);
  // The bending forces on x into bending_state_, leaving the load solver factorised on x. Timed as bending_s.
  void bending_force(const Eigen::Matrix3Xd& x);
  // M(x) q = R, from q's values when `warm` (LoadSolver::solve). Timed as load_s.
  void solve_load(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& R, Eigen::Matrix3Xd& q, bool warm,
                  LoadMatrix matrix, LoadSymmetry symmetry);
  // membrane_load, with the load solve started from q's values when `warm`.
  membrane::MembraneState membrane_load(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& q, bool warm);

  double Ca_;
  double viscosity_ratio_ = 1.0;
  std::unique_ptr<mesh::SurfaceMesh> mesh_;
  std::unique_ptr<membrane::MembraneLaw> law_;
  std::unique_ptr<membrane::MembraneMechanics> mechanics_;
  std::unique_ptr<membrane::LoadSolver> load_solver_;
  std::unique_ptr<membrane::BendingMechanics> bending_;  // null when κ_b = 0: the seed's membrane, untouched
  membrane::BendingState bending_state_;
  std::unique_ptr<stokes::SingleLayer> single_layer_;
  std::unique_ptr<SecondKindSolve> second_kind_;  // null: λ = 1, v = f
  Eigen::Matrix3Xd q_, u_, f_;
  bool load_warm_start_ = false;  // numerics.load_warm_start
  bool load_guess_ = false;       // q_ is the load of a successful evaluation since the last begin_step()
  FlowTimings timings_;
  bool background_flow_ = true;
  bool volume_correction_ = true;
  // Rule of the flux integral: shape functions and derivatives at its points, weights · ½.
  Eigen::Matrix3Xd normals_, flux_moments_;  // volume correction: node normals and flux moments on x
  std::vector<double> flux_scratch_;          // their per-element work array
};

/// @brief Stable time step of the explicit two-stage scheme (rk2):
///   dt = factor · Ca · h_min / (1 + kLargeCaCoefficient · Ca),
/// h_min the smallest node spacing on the reference mesh.
///
/// Why: the stiff part of dv/dx is the membrane relaxation of the shortest resolved wavelengths, with
/// nearly real eigenvalues of modulus ρ ≈ C (1 + 0.4 τmax)/(Ca h_min), C = 5.1–6.1 (power iteration, see
/// membrane_spectral_radius); Heun's real stability interval is 2, so dt ≤ 2/ρ, about a third of Ca h_min at
/// small Ca. At large Ca the prestress τmax (∝ Ca once the capsule is deformed) stiffens these modes: the limit
/// becomes ∝ h_min alone (a CFL-like bound, but set by tension, not by advection: nodes move with the
/// material). Measured limit of dt/(Ca h_min) (RK2, Skalak C = 1, shear flow, 5% initial stretch + 1e-6 h_min
/// noise on every node, γ̇t = 3 or 1000 steps (600 at level 3), whichever first; blow-up = collapsed element,
/// NaN, |Δx| > h_min/2, volume change > 5%; bisection: largest stable factor found, the next unstable one
/// is 5% above it; the table is in results/benchmarks.md, "RK2 stability limit"): all measurements are
/// bounded from below by 0.36/(1 + 0.75 Ca). The default factor 0.25 (time.dt_factor) keeps a
/// margin of ≥ 1.45 over every measurement; twice the automatic dt blows up (tested). At Ca = 0.3, a/b = 2
/// dt = 0.3 Ca h_min (margin 1.2) already shows a spurious τmin excursion of 0.26 by γ̇t = 4.
double automatic_time_step(const mesh::SurfaceMesh& mesh, double capillary_number, double factor);
inline constexpr double kLargeCaCoefficient = 0.75;

/// @brief The automatic dt of a case (time.dt = "auto"): rk2 → the stable dt above with time.dt_factor;
/// rkc → time.dt_accuracy (accuracy-limited, the stages follow the stiffness), but never less than the rk2
/// dt (at large Ca the stiffness is mild and the rk2 step is already accurate). With bending stiffness the rk2
/// dt shrinks by the ratio of the elastic to the total stiffness at the reference,
/// 1 / (1 + kBendingSpectralConstant κ_b / (kSpectralRadiusConstant h_min²)) (time_stepper.h): rk2 must stay
/// stable, rkc keeps its accuracy step and takes the stages the stiffness needs — at most half of
/// RkcIntegrator::Options::max_stages on the reference state (dt is capped below the accuracy step where
/// that would be exceeded).
double automatic_time_step(const config::CaseConfig& config, const mesh::SurfaceMesh& mesh);
/// @brief The same for a mesh whose smallest node spacing is @p h_min (the mesh form evaluates it there).
double automatic_time_step(const config::CaseConfig& config, double h_min);

/// @brief Flow evaluations per unit time the configured time stepping takes on the reference shape with
/// smallest node spacing @p h_min: 2/dt for rk2, stages/dt for rkc with the stages RkcIntegrator chooses for
/// membrane_spectral_radius at rest (safety included); dt is time.dt when set, else the automatic dt.
/// Along a run the prestress and the shrinking h_min add stages, and periodic cases stop before t_end, so it
/// is a rate, not a prediction: the campaign's relative cost estimate (CaseParams::estimated_cost) is built
/// on it because the stages — hence the cost per unit time — grow as (Ca h)^−1/2 where the step is
/// accuracy-limited, not as 1/(Ca h).
double evaluations_per_unit_time(const config::CaseConfig& config, double h_min);

}  // namespace capsim::dynamics
