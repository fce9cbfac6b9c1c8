#pragma once
/// @file
/// @brief The capsule's velocity field dx/dt = v(x) (DESIGN.md §2–§3): on positions x, the membrane gives
/// the load q (M q = ∂W/∂x), and the single-layer integral gives
///   v(x0) = v∞(x0) − 1/(8π Ca) ∫_S J(x0, x)·q(x) dS,   v∞ = (x2, 0, 0).
/// One call of `velocity` is one "flow evaluation", the unit of cost of the time integrators.

#include <memory>

#include <Eigen/Core>

#include "solver/config/case_config.h"
#include "solver/membrane/load_solver.h"
#include "solver/membrane/membrane_law.h"
#include "solver/membrane/membrane_mechanics.h"
#include "solver/mesh/mesh.h"
#include "solver/stokes/single_layer.h"

namespace capsim::dynamics {

/// @brief Side results of one flow evaluation.
struct FlowEvaluation {
  double tau_min = 0.0;         ///< smallest principal tension on x
  double tau_max = 0.0;         ///< largest principal tension on x
  double max_speed = 0.0;       ///< max |v − v∞| over the nodes
  bool used_symmetry = false;   ///< whether the boundary integral used the mirror symmetry
};

/// @brief Accumulated wall time of the phases of flow evaluations (exafmm-style named phases).
struct FlowTimings {
  double membrane_s = 0.0;   ///< kinematics, energy gradient
  double load_s = 0.0;       ///< mass matrix assembly + factorisation + solve
  double stokes_s = 0.0;     ///< boundary integral
  long evaluations = 0;
};

/// @brief Mesh, law, membrane, load solver and boundary-integral operator of one case, built once.
///
/// Contract: the mesh connectivity and reference shape are fixed at construction; `velocity` may be called
/// on any positions of the same mesh. Not thread-safe (caches factorisations and work arrays); internally
/// OpenMP-parallel.
class CapsuleFlow {
 public:
  explicit CapsuleFlow(const config::CaseConfig& config);
  ~CapsuleFlow();

  /// @brief v on positions x (3 × N). Also fills q (the membrane load) when asked.
  /// @throws membrane::DegenerateSurface if x has a collapsed element (a blow-up).
  FlowEvaluation velocity(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, Eigen::Matrix3Xd* load = nullptr);

  [[nodiscard]] const mesh::SurfaceMesh& mesh() const { return *mesh_; }
  [[nodiscard]] const Eigen::Matrix3Xd& reference() const { return mesh_->nodes; }
  [[nodiscard]] const membrane::MembraneMechanics& mechanics() const { return *mechanics_; }
  [[nodiscard]] double capillary_number() const { return Ca_; }
  [[nodiscard]] const FlowTimings& timings() const { return timings_; }
  /// @brief Switch the undisturbed shear flow v∞ off (fluid at rest: relaxation tests) or on (default).
  void set_background_flow(bool on) { background_flow_ = on; }

 private:
  double Ca_;
  std::unique_ptr<mesh::SurfaceMesh> mesh_;
  std::unique_ptr<membrane::MembraneLaw> law_;
  std::unique_ptr<membrane::MembraneMechanics> mechanics_;
  std::unique_ptr<membrane::LoadSolver> load_solver_;
  std::unique_ptr<stokes::SingleLayer> single_layer_;
  Eigen::Matrix3Xd q_, u_;
  FlowTimings timings_;
  bool background_flow_ = true;
};

/// @brief Automatic time step of the explicit schemes: dt = factor · Ca · h_min, h_min the smallest node
/// spacing on the reference mesh. The membrane's fastest relaxation mode on a mesh of spacing h has rate
/// ∝ Gs/(μ h), i.e. 1/(Ca h) in units of γ̇, hence the scaling; the factor is measured (see
/// tests/solver/dynamics) and kept with a safety margin.
double automatic_time_step(const mesh::SurfaceMesh& mesh, double capillary_number, double factor);

}  // namespace capsim::dynamics
