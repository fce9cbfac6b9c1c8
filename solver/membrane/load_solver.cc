#include "solver/membrane/load_solver.h"

#include <array>
#include <stdexcept>
#include <string>

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>

#include "solver/membrane/membrane_mechanics.h"  // DegenerateSurface
#include "solver/mesh/p2_tabulation.h"

namespace capsim::membrane {

struct LoadSolver::Impl {
  Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Lower> cholmod;
  // One CG per load component, so the three solves run side by side in one parallel region (below).
  std::array<Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper>, 3> cg;
  mesh::P2Tabulation p2;                                     // the rule's points
};

LoadSolver::LoadSolver(const mesh::SurfaceMesh& mesh, Options options)
    : mesh_(mesh), options_(options), impl_(std::make_unique<Impl>()) {
  impl_->p2 = mesh::P2Tabulation::of_degree(options.quadrature_degree);
  // Pattern from connectivity: every pair of nodes sharing an element.
  const int n = mesh.num_nodes();
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(static_cast<std::size_t>(mesh.num_elements()) * 36);
  for (const auto& el : mesh.elements)
    for (int a : el)
      for (int b : el) trip.emplace_back(a, b, 1.0);
  M_.resize(n, n);
  M_.setFromTriplets(trip.begin(), trip.end());
  M_.makeCompressed();
  // Map element-local entries to their slot in the compressed storage, so assembly writes values directly.
  value_index_.resize(static_cast<std::size_t>(mesh.num_elements()) * 36);
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const auto& el = mesh.elements[e];
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) {
        const int col = el[j], row = el[i];
        const int* begin = M_.innerIndexPtr() + M_.outerIndexPtr()[col];
        const int* end = M_.innerIndexPtr() + M_.outerIndexPtr()[col + 1];
        const int* it = std::lower_bound(begin, end, row);
        value_index_[static_cast<std::size_t>(e) * 36 + i * 6 + j] = static_cast<int>(it - M_.innerIndexPtr());
      }
  }
  if (options_.backend == Backend::Cholmod) {
    impl_->cholmod.analyzePattern(M_);
    if (impl_->cholmod.info() != Eigen::Success) throw std::runtime_error("CHOLMOD: symbolic analysis failed");
  }
}

LoadSolver::~LoadSolver() = default;

void LoadSolver::assemble(const Eigen::Matrix3Xd& x) {
  if (x.cols() != mesh_.num_nodes()) throw std::invalid_argument("LoadSolver: positions do not match the mesh");
  double* val = M_.valuePtr();
  std::fill(val, val + M_.nonZeros(), 0.0);
  const mesh::P2Tabulation& p2 = impl_->p2;
  const int nq = p2.size();
  for (int e = 0; e < mesh_.num_elements(); ++e) {
    const auto& el = mesh_.elements[e];
    double local[36] = {};
    for (int q = 0; q < nq; ++q) {
      const double da = p2.weight(q) * p2.area_element(x, el, q);
      const double* N = p2[q].n;
      for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) local[i * 6 + j] += da * N[i] * N[j];
    }
    const int* slot = value_index_.data() + static_cast<std::size_t>(e) * 36;
    for (int k = 0; k < 36; ++k) val[slot[k]] += local[k];
  }
}

void LoadSolver::factorize() {
  if (options_.backend == Backend::Cholmod) {
    impl_->cholmod.factorize(M_);
    if (impl_->cholmod.info() != Eigen::Success)
      throw DegenerateSurface("CHOLMOD: the mass matrix is not positive definite (surface degenerated)");
  } else {
    for (auto& cg : impl_->cg) {
      cg.setTolerance(options_.cg_tolerance);
      cg.compute(M_);
    }
  }
}

void LoadSolver::solve(const Eigen::Matrix3Xd& R, Eigen::Matrix3Xd& q) {
  const Eigen::MatrixX3d rhs = R.transpose();
  if (options_.backend == Backend::Cholmod) {
    q = impl_->cholmod.solve(rhs).transpose();
    last_iterations_ = 0;
    // CHOLMOD's positive-definiteness test lets a NaN matrix through (NaN pivots compare false).
    if (!q.allFinite()) throw DegenerateSurface("CHOLMOD: non-finite load (surface degenerated)");
  } else {
    // The three components are independent solves: one parallel region for all of them, each CG serial
    // inside it (Eigen's own parallel product is skipped in a nested region). Left to Eigen, every CG
    // iteration opens its own parallel region for one sparse product (≈ 80 tiny regions per load solve); with
    // OpenMP's spin-waiting those regions collapse when another process shares the cores (issue 12 item 13,
    // results/benchmarks.md). A row of the product is summed in the same order either way, so q is bitwise
    // the same as with Eigen's threaded product, for any thread count.
    Eigen::MatrixX3d sol(R.cols(), 3);
    int iterations[3] = {0, 0, 0};
    bool converged[3] = {false, false, false};
#pragma omp parallel for schedule(static, 1)
    for (int c = 0; c < 3; ++c) {
      sol.col(c) = impl_->cg[c].solve(rhs.col(c));
      iterations[c] = static_cast<int>(impl_->cg[c].iterations());
      converged[c] = impl_->cg[c].info() == Eigen::Success && sol.col(c).allFinite();
    }
    last_iterations_ = iterations[0] + iterations[1] + iterations[2];
    // M is SPD with a condition number bounded independently of h on any valid surface, so CG converges in
    // a few dozen iterations; not converging means M is not SPD (a NaN position, a collapsed surface).
    // (Thrown here, not inside the parallel region, which an exception must not leave.)
    for (int c = 0; c < 3; ++c)
      if (!converged[c])
        throw DegenerateSurface("CG: the load solve did not converge (residual " + std::to_string(impl_->cg[c].error()) +
                                " after " + std::to_string(impl_->cg[c].iterations()) +
                                " iterations): the mass matrix is not positive definite (surface degenerated)");
    q = sol.transpose();
  }
}

void LoadSolver::compute_load(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& R, Eigen::Matrix3Xd& q) {
  assemble(x);
  factorize();
  solve(R, q);
}

}  // namespace capsim::membrane
