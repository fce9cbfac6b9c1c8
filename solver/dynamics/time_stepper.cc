#include "solver/dynamics/time_stepper.h"

namespace capsim::dynamics {

StepInfo Rk2Integrator::step(CapsuleFlow& flow, Eigen::Matrix3Xd& x, double dt) {
  StepInfo info;
  info.start = flow.velocity(x, k1_);
  stage_ = x + dt * k1_;
  flow.velocity(stage_, k2_);
  stage_ = 0.5 * dt * (k1_ + k2_);
  info.max_displacement = stage_.colwise().norm().maxCoeff();
  x += stage_;
  return info;
}

}  // namespace capsim::dynamics
