#include "solver/membrane/load_solver.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

#include <Eigen/CholmodSupport>
#include <cmath>
#include <vector>

#include "solver/membrane/membrane_mechanics.h"  // DegenerateSurface
#include "solver/mesh/p2_element.h"
#include "solver/mesh/p2_tabulation.h"

namespace capsim::membrane {

struct LoadSolver::Impl {
  Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Lower> cholmod;
  std::vector<double> inv_diag;                              // Jacobi preconditioner of the CG backend
  std::vector<double> inv_diag_reduced;                      // the same for the reduced matrix
  Eigen::Matrix3Xd reduced_rhs, reduced_q;                   // the reduced system's right side and solution
  std::vector<double> r, z, p, t;                            // CG work arrays, node-major (3 per node)
  std::vector<double> local;                                 // element mass matrices of the last assembly
  std::vector<double> partial;                               // CG: per-block partial dot products
  Eigen::Matrix3Xd residual, correction;                     // warm start: R − M q0 and its solution δ
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
  } else {
    central_ = mesh::central_elements(mesh);
    if (!central_.empty()) build_reduced();
  }
}

void LoadSolver::build_reduced() {
  const int n = mesh_.num_nodes();
  const auto& image = mesh_.central_node;
  std::vector<int> reduced_of(static_cast<std::size_t>(n));
  std::vector<double> sign(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    if (i < image[i]) {
      reduced_of[i] = reduced_of[image[i]] = static_cast<int>(reduced_node_.size());
      sign[i] = 1.0;
      sign[image[i]] = -1.0;
      reduced_node_.push_back(i);
    }
  // Row k of M̃ (node i): Σ_j M_ij q_j with q_j = sign_j q̃_reduced(j). M is stored symmetric, so column i of the
  // compressed storage is row i.
  const int nr = static_cast<int>(reduced_node_.size());
  const int* outer = M_.outerIndexPtr();
  const int* inner = M_.innerIndexPtr();
  std::vector<std::vector<std::pair<int, int>>> entries(static_cast<std::size_t>(nr));  // (reduced col, M slot)
  std::vector<Eigen::Triplet<double>> trip;
  for (int k = 0; k < nr; ++k) {
    const int i = reduced_node_[k];
    for (int e = outer[i]; e < outer[i + 1]; ++e) {
      entries[k].emplace_back(reduced_of[inner[e]], e);
      trip.emplace_back(reduced_of[inner[e]], k, 1.0);
    }
  }
  Mr_.resize(nr, nr);
  Mr_.setFromTriplets(trip.begin(), trip.end());
  Mr_.makeCompressed();
  contrib_begin_.assign(static_cast<std::size_t>(Mr_.nonZeros()) + 1, 0);
  std::vector<std::vector<std::pair<int, double>>> per_slot(static_cast<std::size_t>(Mr_.nonZeros()));
  for (int k = 0; k < nr; ++k)
    for (const auto& [l, slot] : entries[k]) {
      const int* begin = Mr_.innerIndexPtr() + Mr_.outerIndexPtr()[k];
      const int* end = Mr_.innerIndexPtr() + Mr_.outerIndexPtr()[k + 1];
      const int s = static_cast<int>(std::lower_bound(begin, end, l) - Mr_.innerIndexPtr());
      per_slot[s].emplace_back(slot, sign[inner[slot]]);
    }
  for (std::size_t s = 0; s < per_slot.size(); ++s) {
    contrib_begin_[s + 1] = contrib_begin_[s] + static_cast<int>(per_slot[s].size());
    for (const auto& [slot, sg] : per_slot[s]) {
      contrib_slot_.push_back(slot);
      contrib_sign_.push_back(sg);
    }
  }
}

LoadSolver::~LoadSolver() = default;

void LoadSolver::assemble(const Eigen::Matrix3Xd& x) { assemble_elements(x, nullptr); }

void LoadSolver::assemble_elements(const Eigen::Matrix3Xd& x, const std::vector<int>* elements) {
  if (x.cols() != mesh_.num_nodes()) throw std::invalid_argument("LoadSolver: positions do not match the mesh");
  double* val = M_.valuePtr();
  std::fill(val, val + M_.nonZeros(), 0.0);
  const mesh::P2Tabulation& p2 = impl_->p2;
  const int nq = p2.size(), ne = mesh_.num_elements();
  // Element matrices in parallel, then added into M serially in element order: the same additions in the
  // same order as a serial loop, for any thread count.
  std::vector<double>& local = impl_->local;
  local.assign(static_cast<std::size_t>(ne) * 36, 0.0);
  const int count = elements ? static_cast<int>(elements->size()) : ne;
  const int* which = elements ? elements->data() : nullptr;
#pragma omp parallel for schedule(static)
  for (int k = 0; k < count; ++k) {
    const int e = which ? which[k] : k;
    const auto& el = mesh_.elements[e];
    double* le = local.data() + static_cast<std::size_t>(e) * 36;
    double X[6][3], C[6][3];
    for (int a = 0; a < 6; ++a)
      for (int c = 0; c < 3; ++c) X[a][c] = x(c, el[a]);
    mesh::p2_monomials3(X, C);
    for (int q = 0; q < nq; ++q) {
      double p[3], g1[3], g2[3];
      mesh::p2_monomial_geometry(C, p2[q].xi, p2[q].eta, p, g1, g2);
      const double nx = g1[1] * g2[2] - g1[2] * g2[1], ny = g1[2] * g2[0] - g1[0] * g2[2],
                   nz = g1[0] * g2[1] - g1[1] * g2[0];
      const double da = p2.weight(q) * std::sqrt(nx * nx + ny * ny + nz * nz);
      const double* N = p2[q].n;
      for (int i = 0; i < 6; ++i)  // the upper triangle; M_e is symmetric
        for (int j = i; j < 6; ++j) le[i * 6 + j] += da * N[i] * N[j];
    }
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < i; ++j) le[i * 6 + j] = le[j * 6 + i];
  }
  if (which) {
    // The mass matrix is even under x → −x: an image element's is the element's, its nodes permuted.
    for (int k = 0; k < count; ++k) {
      const int e = which[k], p = central_.image[e];
      const double* from = local.data() + static_cast<std::size_t>(e) * 36;
      double* to = local.data() + static_cast<std::size_t>(p) * 36;
      const auto& pi = central_.local[e];
      for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) to[pi[i] * 6 + pi[j]] = from[i * 6 + j];
    }
  }
  for (int e = 0; e < ne; ++e) {
    const int* slot = value_index_.data() + static_cast<std::size_t>(e) * 36;
    const double* le = local.data() + static_cast<std::size_t>(e) * 36;
    for (int k = 0; k < 36; ++k) val[slot[k]] += le[k];
  }
}

void LoadSolver::factorize() {
  if (options_.backend == Backend::Cholmod) {
    impl_->cholmod.factorize(M_);
    if (impl_->cholmod.info() != Eigen::Success)
      throw DegenerateSurface("CHOLMOD: the mass matrix is not positive definite (surface degenerated)");
  } else {
    const int n = static_cast<int>(M_.cols());
    impl_->inv_diag.resize(static_cast<std::size_t>(n));
    const Eigen::VectorXd d = M_.diagonal();
    for (int i = 0; i < n; ++i) impl_->inv_diag[i] = d[i] > 0.0 ? 1.0 / d[i] : 1.0;  // as Eigen's Jacobi
  }
}



void LoadSolver::solve(const Eigen::Matrix3Xd& R, Eigen::Matrix3Xd& q, bool warm) {
  if (options_.backend == Backend::Cholmod) {
    const Eigen::MatrixX3d rhs = R.transpose();  // CHOLMOD's layout (one column per component); CG reads R itself
    q = impl_->cholmod.solve(rhs).transpose();
    last_iterations_ = 0;
    // CHOLMOD's positive-definiteness test lets a NaN matrix through (NaN pivots compare false).
    if (!q.allFinite()) throw DegenerateSurface("CHOLMOD: non-finite load (surface degenerated)");
  } else if (warm && q.rows() == 3 && q.cols() == R.cols()) {
    // From the guess q0: CG from zero on the correction, M δ = R − M q0, stopped at the same residual
    // tolerance · |R_c| as a cold solve (the cold path below stays the plain loop, bitwise as before).
    double reference2[3];
    Impl& w = *impl_;
    w.residual.noalias() = R - q * M_;  // M is symmetric: (M q0ᵀ)ᵀ = q0 M
    for (int c = 0; c < 3; ++c) {
      reference2[c] = R.row(c).squaredNorm();
      if (reference2[c] == 0.0) {  // a zero component has the solution 0
        q.row(c).setZero();
        w.residual.row(c).setZero();
      }
    }
    solve_cg(M_, w.inv_diag, w.residual, w.correction, reference2);
    q += w.correction;
  } else {
    solve_cg(M_, impl_->inv_diag, R, q);
  }
}

void LoadSolver::solve_cg(const Eigen::SparseMatrix<double>& A, const std::vector<double>& inv_diag,
                          const Eigen::Matrix3Xd& R, Eigen::Matrix3Xd& q, const double* reference2) {
  // Jacobi-preconditioned CG from a zero guess on the three load components side by side: three independent
  // CGs (each with its own α, β and stopping test |r_c| < tol |R_c|, Eigen's criterion) that share every
  // pass over M. A component that has converged is frozen.
  //
  // Two sweeps over the rows per iteration (the textbook loop makes four): the product is carried as
  // t ← M z + β t, so that p and t are updated row by row in one sweep once z is complete:
  //   sweep 1: x += α p, r −= α t, z = D⁻¹ r; |r|², r·z          (β = (r·z)_new / (r·z)_old)
  //   sweep 2: p = z + β p, t = M z + β t; p·t                   (α = r·z / p·t)
  // Serial on purpose: the solve streams M and five vectors through memory twice per iteration and is bound
  // by memory bandwidth; split between two threads (rows per thread, two barriers per iteration) it ran
  // slower, 14.2 against 9.1 ms at level 4 and 2.7 against 2.3 ms at level 3 (results/benchmarks.md,
  // "Flow evaluation by phase"). The dot products are summed per block of kBlock rows and the block sums in
  // block order (the layout a parallel version would need), and q does not depend on the thread count.
  constexpr int kBlock = 256;
  const int n = static_cast<int>(R.cols());
  const int nb = (n + kBlock - 1) / kBlock;
  const std::size_t m = 3 * static_cast<std::size_t>(n);
  Impl& w = *impl_;
  for (auto* v : {&w.r, &w.z, &w.p, &w.t}) v->resize(m);
  w.partial.assign(static_cast<std::size_t>(nb) * 9, 0.0);
  q.setZero(3, n);
  double* x = q.data();
  double *r = w.r.data(), *z = w.z.data(), *p = w.p.data(), *t = w.t.data();
  double* part_rr = w.partial.data();           // |r|² per block (and |b|² at the start)
  double* part_rz = part_rr + 3 * nb;           // r·z per block
  double* part_pt = part_rz + 3 * nb;           // p·t per block
  const double* d = inv_diag.data();
  const double* b = R.data();
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* val = A.valuePtr();
  // M is SPD with a condition number bounded independently of h on any valid surface, so CG converges in a
  // few dozen iterations; the cap (twice the unknowns, as Eigen's) is reached only if M is not SPD.
  const int max_iterations = 2 * n;
  double threshold[3] = {0, 0, 0}, residual2[3] = {0, 0, 0};
  bool active[3] = {false, false, false};
  int iterations[3] = {0, 0, 0};
  auto total = [nb](const double* part, int c) {  // Σ over blocks in block order
    double s = 0.0;
    for (int k = 0; k < nb; ++k) s += part[3 * k + c];
    return s;
  };
  // (M y)_i for row i, three components.
  auto row_product = [&](const double* y, int i, double out[3]) {
    double a0 = 0.0, a1 = 0.0, a2 = 0.0;
    for (int e = outer[i]; e < outer[i + 1]; ++e) {
      const double mv = val[e];
      const double* yj = y + 3 * inner[e];
      a0 += mv * yj[0];
      a1 += mv * yj[1];
      a2 += mv * yj[2];
    }
    out[0] = a0;
    out[1] = a1;
    out[2] = a2;
  };
  {
    double th[3], rz[3], alpha[3], res[3] = {0, 0, 0};
    bool act[3];
    int its[3] = {0, 0, 0};
    // Start: r = b, z = D⁻¹ r, p = z; |b|², r·z.
    for (int k = 0; k < nb; ++k) {
      double bb[3] = {0, 0, 0}, s[3] = {0, 0, 0};
      for (int i = k * kBlock; i < std::min(n, (k + 1) * kBlock); ++i)
        for (int c = 0; c < 3; ++c) {
          const double bi = b[3 * i + c];
          r[3 * i + c] = bi;
          z[3 * i + c] = d[i] * bi;
          p[3 * i + c] = z[3 * i + c];
          bb[c] += bi * bi;
          s[c] += bi * z[3 * i + c];
        }
      for (int c = 0; c < 3; ++c) {
        part_rr[3 * k + c] = bb[c];
        part_rz[3 * k + c] = s[c];
      }
    }
    for (int c = 0; c < 3; ++c) {
      const double bb = total(part_rr, c);
      th[c] = options_.cg_tolerance * options_.cg_tolerance * (reference2 ? reference2[c] : bb);
      rz[c] = total(part_rz, c);
      act[c] = bb > 0.0;  // a zero component has the solution 0
    }
    // t = M p, p·t.
    for (int k = 0; k < nb; ++k) {
      double pt[3] = {0, 0, 0};
      for (int i = k * kBlock; i < std::min(n, (k + 1) * kBlock); ++i) {
        row_product(p, i, t + 3 * i);
        for (int c = 0; c < 3; ++c) pt[c] += p[3 * i + c] * t[3 * i + c];
      }
      for (int c = 0; c < 3; ++c) part_pt[3 * k + c] = pt[c];
    }
    for (int c = 0; c < 3; ++c) alpha[c] = act[c] ? rz[c] / total(part_pt, c) : 0.0;
    for (int it = 0; it < max_iterations && (act[0] || act[1] || act[2]); ++it) {
      // Sweep 1 (the frozen components keep x and r; their z and sums are computed but unused).
      for (int k = 0; k < nb; ++k) {
        double rr[3] = {0, 0, 0}, s[3] = {0, 0, 0};
        for (int i = k * kBlock; i < std::min(n, (k + 1) * kBlock); ++i)
          for (int c = 0; c < 3; ++c) {
            x[3 * i + c] += alpha[c] * p[3 * i + c];
            r[3 * i + c] -= alpha[c] * t[3 * i + c];
            z[3 * i + c] = d[i] * r[3 * i + c];
            rr[c] += r[3 * i + c] * r[3 * i + c];
            s[c] += r[3 * i + c] * z[3 * i + c];
          }
        for (int c = 0; c < 3; ++c) {
          part_rr[3 * k + c] = rr[c];
          part_rz[3 * k + c] = s[c];
        }
      }
      double beta[3] = {0, 0, 0};
      for (int c = 0; c < 3; ++c) {
        if (!act[c]) continue;
        ++its[c];
        res[c] = total(part_rr, c);
        if (!(res[c] >= th[c])) {  // converged (or NaN: caught below)
          act[c] = false;
          alpha[c] = 0.0;
          continue;
        }
        const double s = total(part_rz, c);
        beta[c] = s / rz[c];
        rz[c] = s;
      }
      if (!(act[0] || act[1] || act[2])) break;
      // Sweep 2.
      for (int k = 0; k < nb; ++k) {
        double pt[3] = {0, 0, 0};
        for (int i = k * kBlock; i < std::min(n, (k + 1) * kBlock); ++i) {
          double mz[3];
          row_product(z, i, mz);
          for (int c = 0; c < 3; ++c) {
            if (!act[c]) continue;
            p[3 * i + c] = z[3 * i + c] + beta[c] * p[3 * i + c];
            t[3 * i + c] = mz[c] + beta[c] * t[3 * i + c];
            pt[c] += p[3 * i + c] * t[3 * i + c];
          }
        }
        for (int c = 0; c < 3; ++c) part_pt[3 * k + c] = pt[c];
      }
      for (int c = 0; c < 3; ++c) alpha[c] = act[c] ? rz[c] / total(part_pt, c) : 0.0;
    }
    for (int c = 0; c < 3; ++c) {
      threshold[c] = th[c];
      residual2[c] = res[c];
      active[c] = act[c];
      iterations[c] = its[c];
    }
  }
  last_iterations_ = iterations[0] + iterations[1] + iterations[2];
  // Not converging, or a NaN anywhere, means M is not SPD (a NaN position, a collapsed surface).
  for (int c = 0; c < 3; ++c)
    if (active[c] || !std::isfinite(residual2[c]) || !q.row(c).allFinite())
      throw DegenerateSurface("CG: the load solve did not converge (relative residual " +
                              std::to_string(std::sqrt(residual2[c] / std::max(threshold[c], 1e-300)) *
                                             options_.cg_tolerance) +
                              " after " + std::to_string(iterations[c]) +
                              " iterations): the mass matrix is not positive definite (surface degenerated)");
}

void LoadSolver::compute_load(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& R, Eigen::Matrix3Xd& q,
                              bool warm) {
  assemble(x);
  factorize();
  solve(R, q, warm);
}

void LoadSolver::compute_load_centrally_symmetric(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& R,
                                                  Eigen::Matrix3Xd& q, bool warm) {
  if (central_.empty() || options_.backend != Backend::ConjugateGradient) return compute_load(x, R, q, warm);
  // Phases: assemble M from half the elements; M̃ and its Jacobi preconditioner; the reduced right side (R, or for
  // the warm start R − M q0); CG; q from the reduced solution and its negated images.
  assemble_elements(x, &central_.half);
  Impl& w = *impl_;
  const int nr = static_cast<int>(reduced_node_.size());
  const double* val = M_.valuePtr();
  double* rv = Mr_.valuePtr();
  for (Eigen::Index s = 0; s < Mr_.nonZeros(); ++s) {
    double v = 0.0;
    for (int c = contrib_begin_[s]; c < contrib_begin_[s + 1]; ++c) v += contrib_sign_[c] * val[contrib_slot_[c]];
    rv[s] = v;
  }
  w.inv_diag_reduced.resize(static_cast<std::size_t>(nr));
  const Eigen::VectorXd dr = Mr_.diagonal();
  for (int k = 0; k < nr; ++k) w.inv_diag_reduced[k] = dr[k] > 0.0 ? 1.0 / dr[k] : 1.0;
  const bool from_guess = warm && q.rows() == 3 && q.cols() == R.cols();
  w.reduced_rhs.resize(3, nr);
  double reference2[3] = {0.0, 0.0, 0.0};
  if (from_guess) w.residual.noalias() = R - q * M_;  // as solve(): M symmetric
  for (int k = 0; k < nr; ++k) {
    const int i = reduced_node_[k];
    if (from_guess)
      w.reduced_rhs.col(k) = w.residual.col(i);
    else
      w.reduced_rhs.col(k) = R.col(i);
    if (from_guess)  // the warm start's stopping reference |R_c|² (a cold solve takes it from its right side)
      for (int c = 0; c < 3; ++c) reference2[c] += R(c, i) * R(c, i);
  }
  if (from_guess)
    for (int c = 0; c < 3; ++c)
      if (reference2[c] == 0.0) {  // a zero component has the solution 0 (as in solve())
        q.row(c).setZero();
        w.reduced_rhs.row(c).setZero();
      }
  solve_cg(Mr_, w.inv_diag_reduced, w.reduced_rhs, w.reduced_q, from_guess ? reference2 : nullptr);
  if (!from_guess) q.setZero(3, R.cols());
  for (int k = 0; k < nr; ++k) {
    const int i = reduced_node_[k], p = mesh_.central_node[i];
    if (from_guess) {
      q.col(i) += w.reduced_q.col(k);
      q.col(p) = -q.col(i);
    } else {
      q.col(i) = w.reduced_q.col(k);
      q.col(p) = -w.reduced_q.col(k);
    }
  }
}

}  // namespace capsim::membrane
