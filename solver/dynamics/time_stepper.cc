#include "solver/dynamics/time_stepper.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "solver/mesh/mesh.h"

namespace capsim::dynamics {

StepInfo Rk2Integrator::step(CapsuleFlow& flow, Eigen::Matrix3Xd& x, double dt, StartFields* start) {
  StepInfo info;
  info.start = flow.velocity(x, k1_, start ? &start->load : nullptr);
  if (start) start->velocity = k1_;
  stage_ = x + dt * k1_;
  flow.velocity(stage_, k2_);
  stage_ = 0.5 * dt * (k1_ + k2_);
  info.max_displacement = stage_.colwise().norm().maxCoeff();
  info.max_distortion = max_element_distortion(flow.mesh(), stage_);
  info.evaluations = 2;
  info.stages = 2;
  x += stage_;
  return info;
}

namespace {

// Chebyshev polynomials T_j(w) and their first two derivatives, j = 0..s.
struct Chebyshev {
  std::vector<double> T, dT, ddT;
  Chebyshev(int s, double w) : T(s + 1), dT(s + 1), ddT(s + 1) {
    T[0] = 1.0, dT[0] = 0.0, ddT[0] = 0.0;
    T[1] = w, dT[1] = 1.0, ddT[1] = 0.0;
    for (int j = 2; j <= s; ++j) {
      T[j] = 2.0 * w * T[j - 1] - T[j - 2];
      dT[j] = 2.0 * T[j - 1] + 2.0 * w * dT[j - 1] - dT[j - 2];
      ddT[j] = 4.0 * dT[j - 1] + 2.0 * w * ddT[j - 1] - ddT[j - 2];
    }
  }
};

}  // namespace

RkcCoefficients rkc_coefficients(int s, double damping) {
  if (s < 2) throw std::invalid_argument("RKC needs at least 2 stages");
  RkcCoefficients k;
  k.stages = s;
  k.w0 = 1.0 + damping / (double(s) * s);
  const Chebyshev c(s, k.w0);
  k.w1 = c.dT[s] / c.ddT[s];
  std::vector<double> b(s + 1);
  for (int j = 2; j <= s; ++j) b[j] = c.ddT[j] / (c.dT[j] * c.dT[j]);
  b[0] = b[1] = b[2];
  k.mu.assign(s + 1, 0.0);
  k.nu.assign(s + 1, 0.0);
  k.mu_tilde.assign(s + 1, 0.0);
  k.gamma_tilde.assign(s + 1, 0.0);
  k.mu_tilde[1] = b[1] * k.w1;
  for (int j = 2; j <= s; ++j) {
    k.mu[j] = 2.0 * b[j] * k.w0 / b[j - 1];
    k.nu[j] = -b[j] / b[j - 2];
    k.mu_tilde[j] = 2.0 * b[j] * k.w1 / b[j - 1];
    k.gamma_tilde[j] = -(1.0 - b[j - 1] * c.T[j - 1]) * k.mu_tilde[j];
  }
  return k;
}

double RkcIntegrator::stability_boundary(int s, double damping) {
  const double w0 = 1.0 + damping / (double(s) * s);
  const Chebyshev c(s, w0);
  return (1.0 + w0) * c.ddT[s] / c.dT[s];
}

int RkcIntegrator::stages_for(double dt_rho, double damping) {
  // β(s) ≈ 0.653 s² for ε = 2/13: start just below the estimate, then walk up.
  int s = std::max(2, static_cast<int>(std::sqrt(std::max(dt_rho, 0.0) / 0.7)));
  while (s > 2 && stability_boundary(s - 1, damping) >= dt_rho) --s;
  while (stability_boundary(s, damping) < dt_rho) ++s;
  return s;
}

StepInfo RkcIntegrator::step(CapsuleFlow& flow, Eigen::Matrix3Xd& x, double dt, StartFields* start) {
  StepInfo info;
  info.start = flow.velocity(x, f0_, start ? &start->load : nullptr);
  if (start) start->velocity = f0_;
  const double rho = options_.safety * membrane_spectral_radius(flow.mesh(), x, flow.capillary_number(),
                                                                info.start.tau_max, flow.bending_modulus(),
                                                                flow.viscosity_ratio());
  last_rho_ = rho;
  const int s = stages_for(dt * rho, options_.damping);
  if (s > options_.max_stages)
    throw StepRejected("RKC: dt = " + std::to_string(dt) + " needs " + std::to_string(s) +
                             " stages (spectral radius " + std::to_string(rho) + "); lower time.dt");

  const RkcCoefficients k = rkc_coefficients(s, options_.damping);
  // Y_{j-2} = y_prev2_, Y_{j-1} = y_prev_, Y_j = y_ (rotated by swaps).
  y_prev2_ = x;
  y_prev_ = x + (k.mu_tilde[1] * dt) * f0_;
  for (int j = 2; j <= s; ++j) {
    flow.velocity(y_prev_, f_);
    y_ = (1.0 - k.mu[j] - k.nu[j]) * x + k.mu[j] * y_prev_ + k.nu[j] * y_prev2_ + (k.mu_tilde[j] * dt) * f_ +
         (k.gamma_tilde[j] * dt) * f0_;
    std::swap(y_prev2_, y_prev_);
    std::swap(y_prev_, y_);
  }
  // y_prev_ holds Y_s.
  y_ = y_prev_ - x;
  info.max_displacement = y_.colwise().norm().maxCoeff();
  info.max_distortion = max_element_distortion(flow.mesh(), y_);
  info.evaluations = s;
  info.stages = s;
  x = y_prev_;
  return info;
}

double max_element_distortion(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& dx) {
  static constexpr int pairs[6][2] = {{0, 3}, {3, 1}, {1, 4}, {4, 2}, {2, 5}, {5, 0}};
  double worst = 0.0;
  for (const auto& el : mesh.elements)
    for (const auto& p : pairs) worst = std::max(worst, (dx.col(el[p[0]]) - dx.col(el[p[1]])).squaredNorm());
  return std::sqrt(worst);
}

std::unique_ptr<TimeIntegrator> make_integrator(config::TimeScheme scheme, double rkc_safety) {
  switch (scheme) {
    case config::TimeScheme::Rk2: return std::make_unique<Rk2Integrator>();
    case config::TimeScheme::Rkc: {
      RkcIntegrator::Options options;
      options.safety = rkc_safety;
      return std::make_unique<RkcIntegrator>(options);
    }
  }
  throw std::invalid_argument("make_integrator: not a time.scheme value");
}

double membrane_spectral_radius(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, double capillary_number,
                                double tau_max, double bending_modulus, double viscosity_ratio) {
  return membrane_spectral_radius(mesh::min_node_spacing(mesh, x), capillary_number, tau_max, bending_modulus,
                                  viscosity_ratio);
}

double estimate_spectral_radius(CapsuleFlow& flow, const Eigen::Matrix3Xd& x, int iterations) {
  // On a mirror-symmetric x the iterate is projected onto the symmetric fields (mesh::symmetrise, the driver's
  // projection of a state), so that the estimate is over the modes a symmetric run can excite.
  const bool symmetric = mesh::is_mirror_symmetric(flow.mesh(), x, 1e-12);
  auto symmetrise = [&](Eigen::Matrix3Xd& z) {
    if (symmetric) mesh::symmetrise(flow.mesh(), z);
  };
  Eigen::Matrix3Xd v0, v1, z(3, x.cols());
  flow.velocity(x, v0);
  std::mt19937 rng(12345);
  std::normal_distribution<double> normal;
  for (int i = 0; i < z.cols(); ++i)
    for (int d = 0; d < 3; ++d) z(d, i) = normal(rng);
  symmetrise(z);
  z /= z.norm();
  double rho = 0.0;
  const double eps = 1e-7 * std::max(1.0, x.norm());
  for (int it = 0; it < iterations; ++it) {
    flow.velocity(x + eps * z, v1);
    z = (v1 - v0) / eps;
    symmetrise(z);
    rho = z.norm();
    z /= rho;
  }
  return rho;
}

}  // namespace capsim::dynamics
