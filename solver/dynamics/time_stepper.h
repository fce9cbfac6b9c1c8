#pragma once
/// @file
/// @brief Explicit two-stage Runge-Kutta (Heun) on dx/dt = v(x) (DESIGN.md §4):
///   k1 = v(x_n),  k2 = v(x_n + dt k1),  x_{n+1} = x_n + dt/2 (k1 + k2).
/// Second order; two flow evaluations per step; stable for dt ≲ c Ca h (automatic_time_step).

#include <Eigen/Core>

#include "solver/dynamics/capsule_flow.h"

namespace capsim::dynamics {

/// @brief What one step saw at its start x_n (first stage), used by the diagnostics.
struct StepInfo {
  FlowEvaluation start;        ///< evaluation at x_n: τmin(t_n), max speed
  double max_displacement = 0; ///< max |x_{n+1} − x_n| over nodes
};

/// @brief Heun's method with preallocated stage arrays.
class Rk2Integrator {
 public:
  /// @brief Advance x by dt in place.
  /// @throws membrane::DegenerateSurface if a stage meets a collapsed surface; x is then unchanged.
  StepInfo step(CapsuleFlow& flow, Eigen::Matrix3Xd& x, double dt);

 private:
  Eigen::Matrix3Xd k1_, k2_, stage_;
};

}  // namespace capsim::dynamics
