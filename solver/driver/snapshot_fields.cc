#include "solver/driver/snapshot_fields.h"

#include <algorithm>
#include <stdexcept>

#include "solver/mesh/p2_element.h"
#include "solver/quadrature/triangle_rule.h"

namespace capsim::driver {

NodalTensions nodal_principal_tensions(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x,
                                       std::span<const std::array<double, 2>> tensions, int degree) {
  const auto& rule = quadrature::triangle_rule(degree);
  const int ne = mesh.num_elements(), nq = rule.size(), n = mesh.num_nodes();
  if (static_cast<long>(tensions.size()) != static_cast<long>(ne) * nq)
    throw std::invalid_argument("nodal_principal_tensions: expected one tension pair per quadrature point");
  if (x.cols() != n) throw std::invalid_argument("nodal_principal_tensions: x has the wrong size");
  std::vector<std::array<std::array<double, 6>, 2>> grad(static_cast<std::size_t>(nq));
  for (int k = 0; k < nq; ++k) grad[k] = mesh::p2_shape_gradients(rule.points[k][1], rule.points[k][2]);
  Eigen::VectorXd lo = Eigen::VectorXd::Zero(n), hi = Eigen::VectorXd::Zero(n), area = Eigen::VectorXd::Zero(n);
  for (int e = 0; e < ne; ++e) {
    const auto& el = mesh.elements[e];
    double dA_sum = 0, lo_sum = 0, hi_sum = 0;
    for (int k = 0; k < nq; ++k) {
      Eigen::Vector3d t1 = Eigen::Vector3d::Zero(), t2 = Eigen::Vector3d::Zero();
      for (int a = 0; a < 6; ++a) {
        t1 += grad[k][0][a] * x.col(el[a]);
        t2 += grad[k][1][a] * x.col(el[a]);
      }
      const double dA = 0.5 * rule.weights[k] * t1.cross(t2).norm();
      const auto& tau = tensions[static_cast<std::size_t>(e) * nq + k];
      dA_sum += dA;
      lo_sum += dA * std::min(tau[0], tau[1]);
      hi_sum += dA * std::max(tau[0], tau[1]);
    }
    for (int a : el) {
      area[a] += dA_sum;
      lo[a] += lo_sum;
      hi[a] += hi_sum;
    }
  }
  return {lo.cwiseQuotient(area), hi.cwiseQuotient(area)};
}

std::vector<io::NodeField> snapshot_fields(const mesh::SurfaceMesh& mesh, const membrane::MembraneMechanics& mechanics,
                                           const Eigen::Matrix3Xd& x, const dynamics::StartFields& start,
                                           int membrane_degree) {
  const Eigen::Matrix3Xd n = mesh::node_normals(mesh, x);
  const Eigen::VectorXd qn = (start.load.array() * n.array()).colwise().sum().transpose();
  const NodalTensions tau = nodal_principal_tensions(mesh, x, mechanics.principal_tensions(x), membrane_degree);
  return {io::NodeField::scalar("q_n", qn), io::NodeField::vector("q", start.load),
          io::NodeField::vector("velocity", start.velocity), io::NodeField::scalar("tau_min", tau.tau_min),
          io::NodeField::scalar("tau_max", tau.tau_max)};
}

}  // namespace capsim::driver
