#include "solver/dynamics/capsule_flow.h"

#include <algorithm>
#include <chrono>
#include <numbers>
#include <utility>

#include "solver/dynamics/time_stepper.h"
#include "solver/dynamics/viscosity_contrast.h"


namespace capsim::dynamics {
namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

CapsuleFlow::CapsuleFlow(const config::CaseConfig& c) : Ca_(c.capillary_number), viscosity_ratio_(c.viscosity_ratio) {
  c.validate();
  mesh_ = std::make_unique<mesh::SurfaceMesh>(
      mesh::make_capsule_mesh(c.level, c.aspect_ratio, mesh::parse_spheroid_map(c.spheroid_map)));
  // capsule.tilt / capsule.azimuth: the reference (stress-free) shape is the rotated spheroid, so the membrane
  // and bending references below are built on it and the initial state (reference()) starts from it. At 0, 0
  // the mesh is not touched (bitwise the in-plane cases); off the plane it loses its mirror map (see there).
  mesh::orient_capsule_mesh(*mesh_, c.tilt, c.azimuth);
  law_ = membrane::make_law(c.law, c.skalak_C);
  mechanics_ = std::make_unique<membrane::MembraneMechanics>(*mesh_, mesh_->nodes, *law_,
                                                             membrane::MembraneMechanics::Options{c.membrane_degree});
  membrane::LoadSolver::Options lo;
  lo.quadrature_degree = c.membrane_degree;
  lo.cg_tolerance = c.load_tolerance;
  load_warm_start_ = c.load_warm_start;
  load_solver_ = std::make_unique<membrane::LoadSolver>(*mesh_, lo);
  if (c.bending_modulus > 0.0)
    bending_ = std::make_unique<membrane::BendingMechanics>(*mesh_, mesh_->nodes,
                                                            membrane::HelfrichBending(c.bending_modulus), lo);
  stokes::SingleLayerOptions so;
  so.regular_degree = c.regular_degree;
  so.duffy_order = c.duffy_order;
  so.far_degree = c.far_degree;
  so.far_radius = c.far_radius;
  so.precision = c.kernel_precision == "mixed" ? stokes::KernelPrecision::Mixed : stokes::KernelPrecision::Double;
  so.central_symmetry = c.central_symmetry;
  single_layer_ = std::make_unique<stokes::SingleLayer>(*mesh_, so);
  if (c.viscosity_ratio != 1.0) {  // λ = 1: no second-kind solve, v = f (the path of every committed result)
    stokes::SecondKindOptions ko;
    ko.tolerance = c.viscosity_tolerance;
    // The double layer integrates on the single layer's rules and symmetries, in its own precision
    // (numerics.double_layer_precision).
    stokes::SingleLayerOptions dl = single_layer_->options();
    dl.precision = c.double_layer_precision == "mixed" ? stokes::KernelPrecision::Mixed : stokes::KernelPrecision::Double;
    second_kind_ = std::make_unique<ViscosityContrast>(*mesh_, dl, c.viscosity_ratio, ko);
  }
  volume_correction_ = c.volume_correction;
}

CapsuleFlow::~CapsuleFlow() = default;

void CapsuleFlow::begin_step() {
  load_guess_ = false;
  if (second_kind_) second_kind_->begin_step();
}

void CapsuleFlow::set_second_kind_solve(std::unique_ptr<SecondKindSolve> solve) { second_kind_ = std::move(solve); }

membrane::MembraneState CapsuleFlow::elastic_force(const Eigen::Matrix3Xd& x, LoadSymmetry& symmetry) {
  const auto t0 = std::chrono::steady_clock::now();
  // The symmetries x has (to the boundary integral's position tolerance) and the case uses: the mirror x3 → −x3,
  // which the boundary integral uses whenever x and q have it (unless its symmetry is Off), and the point
  // reflection with numerics.central_symmetry. The forces are computed on one element of each orbit of their
  // group (MembraneMechanics::evaluate_symmetric) and the load solved for one node of each orbit
  // (LoadSolver::compute_load_symmetric).
  const stokes::SingleLayerOptions& so = single_layer_->options();
  symmetry.central = so.central_symmetry && mesh::is_centrally_symmetric(*mesh_, x, so.symmetry_tol);
  symmetry.mirror = so.symmetry != stokes::Symmetry::Off && mesh::is_mirror_symmetric(*mesh_, x, so.symmetry_tol);
  membrane::MembraneState s = mechanics_->evaluate_symmetric(x, /*with_energy=*/false, symmetry.mirror, symmetry.central);
  timings_.membrane_s += seconds_since(t0);
  return s;
}

void CapsuleFlow::bending_force(const Eigen::Matrix3Xd& x) {
  const auto t0 = std::chrono::steady_clock::now();
  bending_state_ = bending_->evaluate(x, *load_solver_);
  timings_.bending_s += seconds_since(t0);
}

void CapsuleFlow::solve_load(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& R, Eigen::Matrix3Xd& q, bool warm,
                             LoadMatrix matrix, LoadSymmetry symmetry) {
  const auto t0 = std::chrono::steady_clock::now();
  try {
    switch (matrix) {
      case LoadMatrix::Factorised: load_solver_->solve(R, q, warm); break;
      case LoadMatrix::AssembleSymmetric:
        load_solver_->compute_load_symmetric(x, R, q, warm, symmetry.mirror, symmetry.central);
        break;
      case LoadMatrix::Assemble: load_solver_->compute_load(x, R, q, warm); break;
    }
  } catch (const std::runtime_error& e) {
    throw membrane::DegenerateSurface(e.what());
  }
  timings_.load_s += seconds_since(t0);
}

membrane::MembraneState CapsuleFlow::membrane_load(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& q) {
  return membrane_load(x, q, false);
}

membrane::MembraneState CapsuleFlow::membrane_load(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& q, bool warm) {
  LoadSymmetry symmetry;
  const membrane::MembraneState s = elastic_force(x, symmetry);
  if (!bending_) {
    solve_load(x, s.internal_force, q, warm, LoadMatrix::AssembleSymmetric, symmetry);
    return s;
  }
  // With bending: its evaluation factorises the mass matrix on x (its two mass solves need it), and the load
  // solve reuses that factorisation for M q = R_elastic + R_b (on the full mesh: the bending evaluation has no
  // reduced form).
  bending_force(x);
  solve_load(x, s.internal_force + bending_state_.internal_force, q, warm, LoadMatrix::Factorised, LoadSymmetry{});
  return s;
}

membrane::MembraneState CapsuleFlow::elastic_load(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& q) {
  LoadSymmetry symmetry;
  const membrane::MembraneState s = elastic_force(x, symmetry);
  solve_load(x, s.internal_force, q, false, LoadMatrix::AssembleSymmetric, symmetry);
  return s;
}

const membrane::BendingState& CapsuleFlow::bending_load(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& q) {
  if (!bending_) {
    bending_state_ = membrane::BendingState{};
    q.setZero(3, x.cols());
    return bending_state_;
  }
  bending_force(x);
  solve_load(x, bending_state_.internal_force, q, false, LoadMatrix::Factorised, LoadSymmetry{});
  return bending_state_;
}

FlowEvaluation CapsuleFlow::velocity(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, Eigen::Matrix3Xd* load) {
  // q_ holds the previous evaluation's load (a valid one only while load_guess_): the warm start's guess.
  const bool warm = load_warm_start_ && load_guess_;
  load_guess_ = false;  // until this solve has succeeded
  const membrane::MembraneState s = membrane_load(x, q_, warm);
  load_guess_ = true;
  FlowEvaluation out = boundary_velocity(x, q_, v);
  out.tau_min = s.tau_min;
  out.tau_max = s.tau_max;
  out.bending_energy = bending_state_.energy;
  out.max_bending_moment = bending_state_.max_moment;
  if (load) *load = q_;
  ++timings_.evaluations;
  return out;
}

FlowEvaluation CapsuleFlow::boundary_velocity(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q,
                                              Eigen::Matrix3Xd& v) {
  FlowEvaluation out;
  auto t0 = std::chrono::steady_clock::now();
  single_layer_->apply(x, q, u_);
  timings_.stokes_s += seconds_since(t0);
  const stokes::SingleLayerStats& st = single_layer_->last_stats();
  out.used_symmetry = st.used_symmetry;
  out.used_central = st.used_central;
  timings_.layout_s += st.build_s;
  timings_.regular_s += st.regular_s;
  timings_.far_s += st.far_s;
  timings_.singular_s += st.singular_s;
  timings_.near_s += st.near_s;
  t0 = std::chrono::steady_clock::now();

  // v = v∞ − u/(8π Ca): the membrane pushes the fluid with −q (solver/README.md §3).
  const double factor = -1.0 / (8.0 * std::numbers::pi * Ca_);
  // With a viscosity contrast this is f, the right-hand side of the second-kind solve, and v its solution.
  Eigen::Matrix3Xd& f = second_kind_ ? f_ : v;
  f = factor * u_;
  if (!second_kind_) out.max_speed = f.colwise().norm().maxCoeff();  // with one: of the solution, below
  if (background_flow_) f.row(0) += x.row(1);
  if (second_kind_) {
    timings_.volume_s += seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    second_kind_->solve(x, f_, v);
    timings_.second_kind_s += seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    u_ = v;  // max |v − v∞| of the solution
    if (background_flow_) u_.row(0) -= x.row(1);
    out.max_speed = u_.colwise().norm().maxCoeff();
  }
  // Discrete flux of v and of the node normals through the P2 surface, Σ_i v_i · m_i with the nodes' flux moments
  // (exact for P2 fields); remove the spurious part.
  mesh::node_normals_and_flux_moments(*mesh_, x, normals_, flux_moments_, flux_scratch_);
  double flux_v = 0.0, flux_n = 0.0;
  for (Eigen::Index i = 0; i < x.cols(); ++i) {
    flux_v += v.col(i).dot(flux_moments_.col(i));
    flux_n += normals_.col(i).dot(flux_moments_.col(i));
  }
  out.volume_flux = flux_v;
  if (volume_correction_) v -= (flux_v / flux_n) * normals_;
  timings_.volume_s += seconds_since(t0);
  return out;
}

namespace {
double stable_time_step(double h_min, double capillary_number, double factor) {
  return factor * capillary_number * h_min / (1.0 + kLargeCaCoefficient * capillary_number);
}

/// The spectral radius RKC chooses its stages for on the reference shape (no prestress), safety included.
double reference_spectral_radius(const config::CaseConfig& config, double h_min) {
  return config.rkc_safety * membrane_spectral_radius(h_min, config.capillary_number, 0.0, config.bending_modulus,
                                                      config.viscosity_ratio);
}
}  // namespace

double automatic_time_step(const mesh::SurfaceMesh& mesh, double capillary_number, double factor) {
  return stable_time_step(mesh::min_node_spacing(mesh, mesh.nodes), capillary_number, factor);
}

double automatic_time_step(const config::CaseConfig& config, const mesh::SurfaceMesh& mesh) {
  return automatic_time_step(config, mesh::min_node_spacing(mesh, mesh.nodes));
}

double automatic_time_step(const config::CaseConfig& config, double h_min) {
  // A viscosity ratio scales the stiffness (viscosity_stiffness_factor; exactly 1 at λ = 1).
  double stable = stable_time_step(h_min, config.capillary_number, config.dt_factor) /
                  viscosity_stiffness_factor(config.viscosity_ratio);
  if (config.bending_modulus <= 0.0) return config.scheme == config::TimeScheme::Rkc ? std::max(config.dt_accuracy, stable) : stable;
  stable /= 1.0 + bending_stiffness_ratio(config.bending_modulus, h_min);
  if (config.scheme != config::TimeScheme::Rkc) return stable;
  // A stiff bending membrane on a fine mesh can need more stages than RKC allows at the accuracy step
  // (level 4, κ_b = 0.1: ≈ 600): cap dt so the reference state needs at most half of them, leaving room for
  // the prestress and the shrinking h_min of the deformed states.
  const RkcIntegrator::Options rkc;
  const double cap =
      RkcIntegrator::stability_boundary(rkc.max_stages / 2, rkc.damping) / reference_spectral_radius(config, h_min);
  return std::min(std::max(config.dt_accuracy, stable), cap);
}

double evaluations_per_unit_time(const config::CaseConfig& config, double h_min) {
  const double dt = config.dt ? *config.dt : automatic_time_step(config, h_min);
  if (config.scheme != config::TimeScheme::Rkc) return 2.0 / dt;
  return RkcIntegrator::stages_for(dt * reference_spectral_radius(config, h_min), RkcIntegrator::Options{}.damping) /
         dt;
}

}  // namespace capsim::dynamics
