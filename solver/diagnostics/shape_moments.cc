#include "solver/diagnostics/shape_moments.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "solver/mesh/p2_tabulation.h"

namespace capsim::diagnostics {

ShapeMoments shape_moments(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, int rule_degree) {
  if (x.cols() != mesh.num_nodes())
    throw std::invalid_argument("shape_moments: positions have " + std::to_string(x.cols()) +
                                " columns, mesh has " + std::to_string(mesh.num_nodes()) + " nodes");
  const auto p2 = mesh::P2Tabulation::of_degree(rule_degree);
  const int nq = p2.size();

  // Shift to the node mean: the divergence-theorem integrals hold about any origin, and a local one keeps
  // ∫ x x^T − V c c^T free of cancellation for a capsule that has drifted from the origin.
  const Eigen::Vector3d origin = x.rowwise().mean();

  double three_volume = 0, area = 0;        // Σ x·n dS (= 3|V|), |S|
  Eigen::Vector3d first = Eigen::Vector3d::Zero();   // Σ x (x·n) dS   (= 4 ∫_V x dV)
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();  // Σ x x^T (x·n) dS (= 5 ∫_V x x^T dV)
  for (const auto& e : mesh.elements) {
    Eigen::Matrix<double, 3, 6> xe;
    for (int a = 0; a < 6; ++a) xe.col(a) = x.col(e[a]) - origin;
    for (int q = 0; q < nq; ++q) {
      const Eigen::Vector3d p = p2.interpolate(xe, q);
      const auto [t1, t2] = p2.tangents(xe, q);
      // n dS = (t1 × t2) dξ dη exactly; the weight is in dξ dη.
      const Eigen::Vector3d ndS = p2.weight(q) * t1.cross(t2);
      const double xn = p.dot(ndS);
      three_volume += xn;
      area += ndS.norm();
      first += xn * p;
      second.noalias() += xn * (p * p.transpose());
    }
  }

  ShapeMoments m;
  m.volume = three_volume / 3.0;
  m.area = area;
  const Eigen::Vector3d c_local = (first / 4.0) / m.volume;
  m.centroid = origin + c_local;
  m.second_moment = second / 5.0 - m.volume * (c_local * c_local.transpose());
  m.second_moment = 0.5 * (m.second_moment + m.second_moment.transpose()).eval();
  return m;
}

EllipsoidOfInertia ellipsoid_of_inertia(const ShapeMoments& moments) {
  const double V = moments.volume;
  if (!(V > 0)) throw std::invalid_argument("ellipsoid_of_inertia: volume is not positive");
  const auto& M = moments.second_moment;
  const double m11 = M(0, 0), m22 = M(1, 1), m12 = 0.5 * (M(0, 1) + M(1, 0));
  // Eigenvalues of the 2×2 block in closed form (no iteration, exact symmetric ordering).
  const double mean = 0.5 * (m11 + m22);
  const double radius = std::hypot(0.5 * (m11 - m22), m12);
  const double mu1 = mean + radius, mu2 = std::max(mean - radius, 0.0);
  EllipsoidOfInertia el;
  el.L1 = std::sqrt(5.0 * mu1 / V);
  el.L2 = std::sqrt(5.0 * mu2 / V);
  el.L3 = std::sqrt(5.0 * std::max(M(2, 2), 0.0) / V);
  el.D12 = (el.L1 - el.L2) / (el.L1 + el.L2);
  // Direction of the larger eigenvalue: angle 2θ of (M11 − M22, 2 M12); atan2 ∈ (−π, π] → θ ∈ (−π/2, π/2].
  el.theta = 0.5 * std::atan2(2.0 * m12, m11 - m22);
  // atan2(−0.0, x < 0) = −π: a long axis along x2 with a round-off negative zero M12 would give −π/2.
  if (el.theta <= -0.5 * std::numbers::pi) el.theta += std::numbers::pi;
  return el;
}

EllipsoidOfInertia3D ellipsoid_of_inertia_3d(const ShapeMoments& moments) {
  const double V = moments.volume;
  if (!(V > 0)) throw std::invalid_argument("ellipsoid_of_inertia_3d: volume is not positive");
  if (!moments.second_moment.allFinite()) throw std::invalid_argument("ellipsoid_of_inertia_3d: moments not finite");
  // Eigenvalues in increasing order, orthonormal eigenvectors as columns.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(moments.second_moment);
  EllipsoidOfInertia3D el;
  std::array<double, 3> L{};
  for (int k = 0; k < 3; ++k) {
    const int j = 2 - k;  // La is the largest eigenvalue
    L[k] = std::sqrt(5.0 * std::max(eig.eigenvalues()(j), 0.0) / V);
    Eigen::Vector3d e = eig.eigenvectors().col(j).normalized();
    // The first component that is not round-off decides the sign (the header says why 1e-9).
    constexpr double kZero = 1e-9;
    const double decider = std::abs(e.x()) > kZero ? e.x() : std::abs(e.y()) > kZero ? e.y() : e.z();
    if (decider < 0) e = -e;
    el.axes[k] = e;
  }
  el.La = L[0];
  el.Lb = L[1];
  el.Lc = L[2];
  return el;
}

}  // namespace capsim::diagnostics
