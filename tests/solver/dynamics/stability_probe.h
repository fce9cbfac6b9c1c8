#pragma once
/// @file
/// @brief The rk2 stability probe of the automatic time step, shared by time_stepper_test.cc (λ = 1) and
/// time_step_validation.cc (viscosity ratios): a perturbed reference that excites every mode, and the number of
/// steps before a blow-up by the driver's criteria.

#include <cmath>
#include <random>

#include "solver/config/case_config.h"
#include "solver/dynamics/capsule_flow.h"
#include "solver/dynamics/time_stepper.h"
#include "solver/dynamics/viscosity_contrast.h"
#include "solver/membrane/membrane_mechanics.h"
#include "solver/mesh/mesh.h"

namespace capsim::dynamics {

// Default factor of the automatic dt (time.dt_factor).
inline constexpr double kDefaultFactor = 0.25;

inline config::CaseConfig make_case(int level, double Ca, double aspect_ratio) {
  config::CaseConfig c;
  c.aspect_ratio = aspect_ratio;
  c.level = level;
  c.capillary_number = Ca;
  c.law = config::MembraneLawKind::Skalak;
  return c;
}

// 5% stretch along x1 (volume kept) plus 1e-6 h_min of deterministic noise on every node: excites every mode,
// including the stiffest, as the stability scans of automatic_time_step did.
inline Eigen::Matrix3Xd perturbed_reference(const CapsuleFlow& flow) {
  Eigen::Matrix3Xd x = flow.reference();
  x.row(0) *= 1.05;
  x.row(1) /= std::sqrt(1.05);
  x.row(2) /= std::sqrt(1.05);
  const double h = mesh::min_node_spacing(flow.mesh(), flow.reference());
  std::mt19937 rng(1);
  std::normal_distribution<double> normal;
  for (int i = 0; i < x.cols(); ++i)
    for (int d = 0; d < 3; ++d) x(d, i) += 1e-6 * h * normal(rng);
  return x;
}

// The driver's blow-up criteria (case_driver.cc): collapsed element, NaN, a node moving more than h_min/2 in
// one step (neighbouring nodes relative to each other), volume change beyond 5%. Returns the number of steps done before a blow-up (steps if none).
inline int steps_until_blow_up(TimeIntegrator& integrator, CapsuleFlow& flow, Eigen::Matrix3Xd x, double dt, int steps) {
  const double h = mesh::min_node_spacing(flow.mesh(), flow.reference());
  const double V0 = membrane::area_and_volume(flow.mesh(), flow.reference()).volume;
  for (int n = 0; n < steps; ++n) {
    StepInfo info;
    try {
      info = integrator.step(flow, x, dt);
    } catch (const membrane::DegenerateSurface&) {
      return n;
    } catch (const SecondKindNotConverged&) {  // a blown-up state the viscosity-ratio solve cannot follow
      return n;
    }
    const double V = membrane::area_and_volume(flow.mesh(), x).volume;
    if (!x.allFinite() || info.max_distortion > 0.5 * h || std::abs(V - V0) > 0.05 * V0) return n;
  }
  return steps;
}

}  // namespace capsim::dynamics
