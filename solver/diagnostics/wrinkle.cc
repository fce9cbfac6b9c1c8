#include "solver/diagnostics/wrinkle.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "solver/mesh/p2_tabulation.h"

namespace capsim::diagnostics {

double compressed_area_fraction(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x,
                                std::span<const std::array<double, 2>> tensions, int degree) {
  const auto p2 = mesh::P2Tabulation::of_degree(degree);
  const int ne = mesh.num_elements(), nq = p2.size();
  if (static_cast<long>(tensions.size()) != static_cast<long>(ne) * nq)
    throw std::invalid_argument("compressed_area_fraction: expected one tension pair per quadrature point");
  if (x.cols() != mesh.num_nodes()) throw std::invalid_argument("compressed_area_fraction: x has the wrong size");
  double total = 0, compressed = 0;
  for (int e = 0; e < ne; ++e) {
    const auto& el = mesh.elements[e];
    for (int k = 0; k < nq; ++k) {
      // Current area element |∂x/∂ξ × ∂x/∂η| on the exact P2 geometry.
      const double dA = p2.weight(k) * p2.area_element(x, el, k);
      total += dA;
      if (tensions[static_cast<std::size_t>(e) * nq + k][1] < 0.0) compressed += dA;
    }
  }
  return total > 0 ? compressed / total : 0.0;
}

double load_roughness(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q) {
  const int n = mesh.num_nodes();
  if (x.cols() != n || q.cols() != n) throw std::invalid_argument("load_roughness: x and q need one column per node");
  const Eigen::Matrix3Xd normals = mesh::node_normals(mesh, x);
  Eigen::VectorXd qn(n);
  for (int i = 0; i < n; ++i) qn[i] = q.col(i).dot(normals.col(i));
  // Neighbours: the other nodes of the elements around each node (P2: vertices and mid-side nodes).
  std::vector<int> nb;
  double sum_d2 = 0, sum_q2 = 0;
  for (int i = 0; i < n; ++i) {
    nb.clear();
    for (int k = mesh.node_element_offsets[i]; k < mesh.node_element_offsets[i + 1]; ++k)
      for (int a : mesh.elements[mesh.node_elements[k]])
        if (a != i) nb.push_back(a);
    std::sort(nb.begin(), nb.end());
    nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
    double mean = 0;
    for (int j : nb) mean += qn[j];
    mean /= static_cast<double>(std::max<std::size_t>(nb.size(), 1));
    sum_d2 += (qn[i] - mean) * (qn[i] - mean);
    sum_q2 += qn[i] * qn[i];
  }
  return sum_q2 > 0 ? std::sqrt(sum_d2 / sum_q2) : 0.0;
}

}  // namespace capsim::diagnostics
