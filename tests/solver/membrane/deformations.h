#pragma once
/// @file
/// @brief Test deformations and modes shared by the membrane tests (elastic laws and bending).

#include <cmath>

#include <Eigen/Core>

namespace capsim::membrane::testing {

/// @brief A smooth, large, non-affine deformation of the reference X, of size `amp`.
inline Eigen::Matrix3Xd smooth_deformation(const Eigen::Matrix3Xd& X, double amp) {
  Eigen::Matrix3Xd x = X;
  for (int i = 0; i < X.cols(); ++i) {
    const double a = X(0, i), b = X(1, i), c = X(2, i);
    x(0, i) += amp * (0.3 * a + std::sin(1.3 * b + 0.2) * c);
    x(1, i) += amp * (-0.2 * b + std::cos(0.7 * a) * 0.4);
    x(2, i) += amp * (0.25 * c * a + 0.1 * std::sin(2.0 * b));
  }
  return x;
}

/// @brief Legendre polynomial P_l(t) (three-term recurrence): axisymmetric spherical harmonics about any axis.
inline double legendre(int l, double t) {
  double p0 = 1.0, p1 = t;
  if (l == 0) return p0;
  for (int k = 2; k <= l; ++k) {
    const double p2 = ((2 * k - 1) * t * p1 - (k - 1) * p0) / k;
    p0 = p1;
    p1 = p2;
  }
  return p1;
}

}  // namespace capsim::membrane::testing
