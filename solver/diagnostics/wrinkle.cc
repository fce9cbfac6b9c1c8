#include "solver/diagnostics/wrinkle.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>

#include "solver/membrane/load_solver.h"
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

WrinkleWavelength::WrinkleWavelength(const mesh::SurfaceMesh& mesh, Options options)
    : mesh_(mesh), options_(options), p2_(mesh::P2Tabulation::of_degree(6)) {
  if (!options.valid()) throw std::invalid_argument("WrinkleWavelength: filter_length > 0 and 1 <= filter_order <= 16");
}

WrinkleWavelength::WrinkleWavelength(const mesh::SurfaceMesh& mesh) : WrinkleWavelength(mesh, Options{}) {}

WrinkleWavelength::Relief WrinkleWavelength::measure(const Eigen::Matrix3Xd& x) const {
  const int ne = mesh_.num_elements(), nq = p2_.size(), nn = mesh_.num_nodes();
  if (x.cols() != nn) throw std::invalid_argument("WrinkleWavelength: x needs one column per node");
  // Ks_ab = ∫ ∇s φ_a · ∇s φ_b dS = Σ w J ∂_α φ_a g^{αβ} ∂_β φ_b; M is the load solver's P2 mass matrix on x.
  std::vector<Eigen::Triplet<double>> tk;
  tk.reserve(static_cast<std::size_t>(ne) * 36);
  for (int e = 0; e < ne; ++e) {
    const auto& el = mesh_.elements[e];
    double ke[6][6] = {};
    for (int q = 0; q < nq; ++q) {
      const auto t = p2_.tangents(x, el, q);
      const double g11 = t.g1.dot(t.g1), g12 = t.g1.dot(t.g2), g22 = t.g2.dot(t.g2);
      const double det = g11 * g22 - g12 * g12;
      if (!(det > 0.0) || !std::isfinite(det)) return {};  // collapsed: no wavelength
      const double w = p2_.weight(q) * std::sqrt(det);
      const mesh::P2Point& p = p2_[q];
      for (int a = 0; a < 6; ++a) {
        const double u1 = (g22 * p.dxi[a] - g12 * p.deta[a]) / det, u2 = (g11 * p.deta[a] - g12 * p.dxi[a]) / det;
        for (int b = 0; b < 6; ++b) ke[a][b] += w * (u1 * p.dxi[b] + u2 * p.deta[b]);
      }
    }
    for (int a = 0; a < 6; ++a)
      for (int b = 0; b < 6; ++b) tk.emplace_back(el[a], el[b], ke[a][b]);
  }
  Eigen::SparseMatrix<double> K(nn, nn);
  K.setFromTriplets(tk.begin(), tk.end());
  membrane::LoadSolver mass(mesh_, membrane::LoadSolver::Options{});  // degree 6, as Ks
  mass.assemble(x);
  const Eigen::SparseMatrix<double>& M = mass.mass_matrix();
  // High-pass: y ← (M + t Ks)⁻¹ t Ks y, m times (each coordinate).
  const double t = options_.filter_length * options_.filter_length;
  const Eigen::SparseMatrix<double> A = M + t * K;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> cg;
  cg.setTolerance(1e-10);
  cg.compute(A);
  Eigen::MatrixXd y = x.transpose();
  for (int k = 0; k < options_.filter_order; ++k) {
    const Eigen::MatrixXd rhs = t * (K * y);
    y = cg.solve(rhs);
    if (cg.info() != Eigen::Success) return {};
  }
  // Normal relief, mean removed; the Rayleigh quotient of −Δs.
  const Eigen::Matrix3Xd normals = mesh::node_normals(mesh_, x);
  Eigen::VectorXd u(nn);
  for (int i = 0; i < nn; ++i) u[i] = normals.col(i).dot(y.row(i).transpose());
  const Eigen::VectorXd m_ones = M * Eigen::VectorXd::Ones(nn);  // ∫ φ_a dS
  const double area = m_ones.sum();
  u.array() -= u.dot(m_ones) / area;
  const double a0 = u.dot(M * u), b0 = u.dot(K * u);
  // Relief below round-off of the positions (RMS under 1e-13 of the size): none to measure.
  const double size2 = (x.rowwise().maxCoeff() - x.rowwise().minCoeff()).squaredNorm();
  if (!(a0 > 1e-26 * area * size2) || !(b0 > 0)) return {};
  return {2.0 * std::numbers::pi * std::sqrt(a0 / b0), std::sqrt(a0 / area)};
}

}  // namespace capsim::diagnostics
