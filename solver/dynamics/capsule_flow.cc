#include "solver/dynamics/capsule_flow.h"

#include <algorithm>
#include <chrono>
#include <numbers>

namespace capsim::dynamics {
namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

CapsuleFlow::CapsuleFlow(const config::CaseConfig& c) : Ca_(c.capillary_number) {
  c.validate();
  mesh_ = std::make_unique<mesh::SurfaceMesh>(
      mesh::make_capsule_mesh(c.level, c.aspect_ratio, mesh::parse_spheroid_map(c.spheroid_map)));
  law_ = membrane::make_law(c.law, c.skalak_C);
  mechanics_ = std::make_unique<membrane::MembraneMechanics>(*mesh_, mesh_->nodes, *law_,
                                                             membrane::MembraneMechanics::Options{c.membrane_degree});
  membrane::LoadSolver::Options lo;
  lo.quadrature_degree = c.membrane_degree;
  load_solver_ = std::make_unique<membrane::LoadSolver>(*mesh_, lo);
  stokes::SingleLayerOptions so;
  so.regular_degree = c.regular_degree;
  so.duffy_order = c.duffy_order;
  single_layer_ = std::make_unique<stokes::SingleLayer>(*mesh_, so);
}

CapsuleFlow::~CapsuleFlow() = default;

FlowEvaluation CapsuleFlow::velocity(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, Eigen::Matrix3Xd* load) {
  FlowEvaluation out;
  auto t0 = std::chrono::steady_clock::now();
  const membrane::MembraneState s = mechanics_->evaluate(x);
  timings_.membrane_s += seconds_since(t0);
  out.tau_min = s.tau_min;
  out.tau_max = s.tau_max;

  t0 = std::chrono::steady_clock::now();
  try {
    load_solver_->compute_load(x, s.internal_force, q_);
  } catch (const std::runtime_error& e) {
    throw membrane::DegenerateSurface(e.what());
  }
  timings_.load_s += seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  single_layer_->apply(x, q_, u_);
  timings_.stokes_s += seconds_since(t0);
  out.used_symmetry = single_layer_->last_stats().used_symmetry;

  // v = v∞ − u/(8π Ca): the membrane pushes the fluid with −q (DESIGN.md §3).
  const double factor = -1.0 / (8.0 * std::numbers::pi * Ca_);
  v = factor * u_;
  out.max_speed = v.colwise().norm().maxCoeff();
  if (background_flow_) v.row(0) += x.row(1);
  if (load) *load = q_;
  ++timings_.evaluations;
  return out;
}

double automatic_time_step(const mesh::SurfaceMesh& mesh, double capillary_number, double factor) {
  return factor * capillary_number * mesh::min_node_spacing(mesh, mesh.nodes) /
         (1.0 + kLargeCaCoefficient * capillary_number);
}

double automatic_time_step(const config::CaseConfig& config, const mesh::SurfaceMesh& mesh) {
  const double stable = automatic_time_step(mesh, config.capillary_number, config.dt_factor);
  return config.scheme == "rkc" ? std::max(config.dt_accuracy, stable) : stable;
}

}  // namespace capsim::dynamics
