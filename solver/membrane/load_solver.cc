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

namespace {
bool all_finite(const double* v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}
}  // namespace

struct LoadSolver::Impl {
  Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Lower> cholmod;
  std::vector<double> inv_diag;                              // Jacobi preconditioner of the CG backend
  std::vector<double> r, z, p, t;                            // CG work arrays, node-major (K per node)
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
  }
}

LoadSolver::~LoadSolver() = default;

void LoadSolver::assemble(const Eigen::Matrix3Xd& x) { assemble_elements(x, nullptr); }

void LoadSolver::assemble_elements(const Eigen::Matrix3Xd& x, const mesh::ElementOrbits* orbits) {
  if (x.cols() != mesh_.num_nodes()) throw std::invalid_argument("LoadSolver: positions do not match the mesh");
  double* val = M_.valuePtr();
  std::fill(val, val + M_.nonZeros(), 0.0);
  const mesh::P2Tabulation& p2 = impl_->p2;
  const int nq = p2.size(), ne = mesh_.num_elements();
  // Element matrices in parallel, then added into M serially in element order: the same additions in the
  // same order as a serial loop, for any thread count.
  std::vector<double>& local = impl_->local;
  local.assign(static_cast<std::size_t>(ne) * 36, 0.0);
  const int count = orbits ? static_cast<int>(orbits->representatives.size()) : ne;
  const int* which = orbits ? orbits->representatives.data() : nullptr;
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
  if (orbits) {
    // The mass matrix is invariant under the symmetries: an image element's is its representative's, its nodes
    // permuted.
    for (const mesh::ElementOrbits::Image& im : orbits->images) {
      const double* from = local.data() + static_cast<std::size_t>(im.from) * 36;
      double* to = local.data() + static_cast<std::size_t>(im.element) * 36;
      for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) to[im.local[i] * 6 + im.local[j]] = from[i * 6 + j];
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
    last_iterations_ = 0;
    w.correction.resize(3, R.cols());
    solve_cg<3>(M_, w.inv_diag, w.residual.data(), static_cast<int>(R.cols()), w.correction.data(), reference2);
    q += w.correction;
  } else {
    last_iterations_ = 0;
    q.resize(3, R.cols());
    solve_cg<3>(M_, impl_->inv_diag, R.data(), static_cast<int>(R.cols()), q.data());
  }
}

template <int K>
void LoadSolver::solve_cg(const Eigen::SparseMatrix<double>& A, const std::vector<double>& inv_diag, const double* b,
                          int n, double* x, const double* reference2) {
  // Jacobi-preconditioned CG from a zero guess on K load components side by side (K = 3, or the 1 or 2 components
  // of one class of a symmetry-reduced solve): K independent CGs (each with its own α, β and stopping test |r_c| < tol |R_c|, Eigen's criterion) that share every
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
  const int nb = (n + kBlock - 1) / kBlock;
  const std::size_t m = K * static_cast<std::size_t>(n);
  Impl& w = *impl_;
  for (auto* v : {&w.r, &w.z, &w.p, &w.t}) v->resize(m);
  w.partial.assign(static_cast<std::size_t>(nb) * 3 * K, 0.0);
  std::fill(x, x + m, 0.0);
  double *r = w.r.data(), *z = w.z.data(), *p = w.p.data(), *t = w.t.data();
  double* part_rr = w.partial.data();           // |r|² per block (and |b|² at the start)
  double* part_rz = part_rr + K * nb;           // r·z per block
  double* part_pt = part_rz + K * nb;           // p·t per block
  const double* d = inv_diag.data();
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* val = A.valuePtr();
  // M is SPD with a condition number bounded independently of h on any valid surface, so CG converges in a
  // few dozen iterations; the cap (twice the unknowns, as Eigen's) is reached only if M is not SPD.
  const int max_iterations = 2 * n;
  double threshold[K] = {}, residual2[K] = {};
  bool active[K] = {};
  int iterations[K] = {};
  auto any_active = [](const bool* a) {
    bool any = false;
    for (int c = 0; c < K; ++c) any = any || a[c];
    return any;
  };
  auto total = [nb](const double* part, int c) {  // Σ over blocks in block order
    double s = 0.0;
    for (int k = 0; k < nb; ++k) s += part[K * k + c];
    return s;
  };
  // (M y)_i for row i, K components.
  auto row_product = [&](const double* y, int i, double out[K]) {
    double acc[K] = {};
    for (int e = outer[i]; e < outer[i + 1]; ++e) {
      const double mv = val[e];
      const double* yj = y + K * inner[e];
      for (int c = 0; c < K; ++c) acc[c] += mv * yj[c];
    }
    for (int c = 0; c < K; ++c) out[c] = acc[c];
  };
  {
    double th[K], rz[K], alpha[K], res[K] = {};
    bool act[K];
    int its[K] = {};
    // Start: r = b, z = D⁻¹ r, p = z; |b|², r·z.
    for (int k = 0; k < nb; ++k) {
      double bb[K] = {}, s[K] = {};
      for (int i = k * kBlock; i < std::min(n, (k + 1) * kBlock); ++i)
        for (int c = 0; c < K; ++c) {
          const double bi = b[K * i + c];
          r[K * i + c] = bi;
          z[K * i + c] = d[i] * bi;
          p[K * i + c] = z[K * i + c];
          bb[c] += bi * bi;
          s[c] += bi * z[K * i + c];
        }
      for (int c = 0; c < K; ++c) {
        part_rr[K * k + c] = bb[c];
        part_rz[K * k + c] = s[c];
      }
    }
    for (int c = 0; c < K; ++c) {
      const double bb = total(part_rr, c);
      th[c] = options_.cg_tolerance * options_.cg_tolerance * (reference2 ? reference2[c] : bb);
      rz[c] = total(part_rz, c);
      act[c] = bb > 0.0;  // a zero component has the solution 0
    }
    // t = M p, p·t.
    for (int k = 0; k < nb; ++k) {
      double pt[K] = {};
      for (int i = k * kBlock; i < std::min(n, (k + 1) * kBlock); ++i) {
        row_product(p, i, t + K * i);
        for (int c = 0; c < K; ++c) pt[c] += p[K * i + c] * t[K * i + c];
      }
      for (int c = 0; c < K; ++c) part_pt[K * k + c] = pt[c];
    }
    for (int c = 0; c < K; ++c) alpha[c] = act[c] ? rz[c] / total(part_pt, c) : 0.0;
    for (int it = 0; it < max_iterations && any_active(act); ++it) {
      // Sweep 1 (the frozen components keep x and r; their z and sums are computed but unused).
      for (int k = 0; k < nb; ++k) {
        double rr[K] = {}, s[K] = {};
        for (int i = k * kBlock; i < std::min(n, (k + 1) * kBlock); ++i)
          for (int c = 0; c < K; ++c) {
            x[K * i + c] += alpha[c] * p[K * i + c];
            r[K * i + c] -= alpha[c] * t[K * i + c];
            z[K * i + c] = d[i] * r[K * i + c];
            rr[c] += r[K * i + c] * r[K * i + c];
            s[c] += r[K * i + c] * z[K * i + c];
          }
        for (int c = 0; c < K; ++c) {
          part_rr[K * k + c] = rr[c];
          part_rz[K * k + c] = s[c];
        }
      }
      double beta[K] = {};
      for (int c = 0; c < K; ++c) {
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
      if (!any_active(act)) break;
      // Sweep 2.
      for (int k = 0; k < nb; ++k) {
        double pt[K] = {};
        for (int i = k * kBlock; i < std::min(n, (k + 1) * kBlock); ++i) {
          double mz[K];
          row_product(z, i, mz);
          for (int c = 0; c < K; ++c) {
            if (!act[c]) continue;
            p[K * i + c] = z[K * i + c] + beta[c] * p[K * i + c];
            t[K * i + c] = mz[c] + beta[c] * t[K * i + c];
            pt[c] += p[K * i + c] * t[K * i + c];
          }
        }
        for (int c = 0; c < K; ++c) part_pt[K * k + c] = pt[c];
      }
      for (int c = 0; c < K; ++c) alpha[c] = act[c] ? rz[c] / total(part_pt, c) : 0.0;
    }
    for (int c = 0; c < K; ++c) {
      threshold[c] = th[c];
      residual2[c] = res[c];
      active[c] = act[c];
      iterations[c] = its[c];
    }
  }
  for (int c = 0; c < K; ++c) last_iterations_ += iterations[c];
  // Not converging, or a NaN anywhere, means M is not SPD (a NaN position, a collapsed surface).
  for (int c = 0; c < K; ++c)
    if (active[c] || !std::isfinite(residual2[c]) || !all_finite(x, m))
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
  compute_load_symmetric(x, R, q, warm, /*mirror=*/false, /*central=*/true);
}

LoadSolver::Reduction LoadSolver::build_reduction(bool mirror, bool central) const {
  // The group generated by the chosen symmetries (mesh::symmetry_group: its non-identity elements, each a node map
  // and the signs it puts on the load's components — the load is a vector field equivariant with the positions).
  const std::vector<mesh::NodeSymmetry> others = mesh::symmetry_group(mesh_, mirror, central);
  const int n = mesh_.num_nodes();
  // Orbits, each represented by its smallest node; the sign of every node relative to its representative per
  // group element that maps the representative onto it.
  Reduction red;
  red.elements = mesh::element_orbits(mesh_, mirror, central);
  red.orbit_of.assign(static_cast<std::size_t>(n), -1);
  std::vector<int> orbit_size, stabiliser_flips;  // per orbit: size; bit c set: some g fixing the rep flips c
  std::vector<std::array<double, 3>> node_sign(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    if (red.orbit_of[i] >= 0) continue;
    const int o = static_cast<int>(red.representative.size());
    red.representative.push_back(i);
    red.orbit_of[i] = o;
    node_sign[i] = {1.0, 1.0, 1.0};
    int size = 1, flips = 0;
    for (const mesh::NodeSymmetry& g : others) {
      const int j = g.map[i];
      if (j == i)
        for (int c = 0; c < 3; ++c)
          if (g.sign[c] < 0.0) flips |= 1 << c;
      if (red.orbit_of[j] < 0) {
        red.orbit_of[j] = o;
        node_sign[j] = g.sign;
        ++size;
      }
    }
    orbit_size.push_back(size);
    stabiliser_flips.push_back(flips);
  }
  red.node_sign = node_sign;
  // Components with the same signs under every group element share one reduced matrix (a class).
  for (int c = 0; c < 3; ++c) {
    bool placed = false;
    for (Reduction::Class& cl : red.classes) {
      bool same = true;
      for (const mesh::NodeSymmetry& g : others) same = same && g.sign[c] == g.sign[cl.components.front()];
      if (same) {
        cl.components.push_back(c);
        placed = true;
        break;
      }
    }
    if (!placed) {
      red.classes.emplace_back();
      red.classes.back().components = {c};
    }
  }
  const int norbits = static_cast<int>(red.representative.size());
  const double group_size = static_cast<double>(others.size() + 1);
  const int* outer = M_.outerIndexPtr();
  const int* inner = M_.innerIndexPtr();
  for (Reduction::Class& cl : red.classes) {
    const int c0 = cl.components.front();
    // Unknowns: the orbits whose representative's stabiliser keeps the class's sign (else the load is 0 there).
    std::vector<int>& unknown_of = cl.unknown_of;
    unknown_of.assign(static_cast<std::size_t>(norbits), -1);
    for (int o = 0; o < norbits; ++o)
      if (!(stabiliser_flips[o] & (1 << c0))) {
        unknown_of[o] = static_cast<int>(cl.orbit.size());
        cl.orbit.push_back(o);
        cl.scale.push_back(std::sqrt(orbit_size[o] / group_size));
      }
    // Row of unknown u (orbit O, representative r): A'_{O,O'} = sqrt(|O|/|O'|) Σ_{j ∈ O'} s_j M_{r j}, the Galerkin
    // matrix BᵀMB of the symmetric loads scaled symmetrically by the orbit sizes (see the header).
    const int nu = static_cast<int>(cl.orbit.size());
    std::vector<std::vector<std::pair<int, int>>> entries(static_cast<std::size_t>(nu));  // (column, M slot)
    std::vector<Eigen::Triplet<double>> trip;
    for (int u = 0; u < nu; ++u) {
      const int r = red.representative[cl.orbit[u]];
      for (int e = outer[r]; e < outer[r + 1]; ++e) {
        const int col = unknown_of[red.orbit_of[inner[e]]];
        if (col < 0) continue;  // a node whose load component is 0 by symmetry
        entries[u].emplace_back(col, e);
        trip.emplace_back(col, u, 1.0);
      }
    }
    cl.A.resize(nu, nu);
    cl.A.setFromTriplets(trip.begin(), trip.end());
    cl.A.makeCompressed();
    std::vector<std::vector<std::pair<int, double>>> per_slot(static_cast<std::size_t>(cl.A.nonZeros()));
    cl.diagonal_slot.assign(static_cast<std::size_t>(nu), -1);
    for (int u = 0; u < nu; ++u) {
      const int* begin = cl.A.innerIndexPtr() + cl.A.outerIndexPtr()[u];
      const int* end = cl.A.innerIndexPtr() + cl.A.outerIndexPtr()[u + 1];
      for (const auto& [col, slot] : entries[u]) {
        const int at = static_cast<int>(std::lower_bound(begin, end, col) - cl.A.innerIndexPtr());
        const int j = inner[slot];
        const double size_ratio = static_cast<double>(orbit_size[cl.orbit[u]]) / orbit_size[red.orbit_of[j]];
        per_slot[at].emplace_back(slot, node_sign[j][c0] * (size_ratio == 1.0 ? 1.0 : std::sqrt(size_ratio)));
      }
      cl.diagonal_slot[u] = static_cast<int>(std::lower_bound(begin, end, u) - cl.A.innerIndexPtr());
    }
    cl.contrib_begin.assign(per_slot.size() + 1, 0);
    for (std::size_t k = 0; k < per_slot.size(); ++k) {
      cl.contrib_begin[k + 1] = cl.contrib_begin[k] + static_cast<int>(per_slot[k].size());
      for (const auto& [slot, coef] : per_slot[k]) {
        cl.contrib_slot.push_back(slot);
        cl.contrib_coef.push_back(coef);
      }
    }
  }
  return red;
}

template <int K>
void LoadSolver::solve_class(Reduction::Class& cl, const Reduction& red, const Eigen::Matrix3Xd& b,
                             const double* reference2, Eigen::Matrix3Xd& out) {
  // A' from the assembled M, its Jacobi preconditioner, b' = sqrt(|O|/|G|) b_r, CG, then the loads of the
  // representatives q_r = q'_O / sqrt(|O|/|G|) and of their images by sign.
  const double* val = M_.valuePtr();
  double* av = cl.A.valuePtr();
  for (Eigen::Index k = 0; k < cl.A.nonZeros(); ++k) {
    double v = 0.0;
    for (int t = cl.contrib_begin[k]; t < cl.contrib_begin[k + 1]; ++t) v += cl.contrib_coef[t] * val[cl.contrib_slot[t]];
    av[k] = v;
  }
  const int nu = static_cast<int>(cl.orbit.size());
  cl.inv_diag.resize(static_cast<std::size_t>(nu));
  for (int u = 0; u < nu; ++u) {
    const double d = av[cl.diagonal_slot[u]];
    cl.inv_diag[u] = d > 0.0 ? 1.0 / d : 1.0;
  }
  cl.rhs.resize(static_cast<std::size_t>(K) * nu);
  cl.solution.resize(cl.rhs.size());
  for (int u = 0; u < nu; ++u) {
    const int r = red.representative[cl.orbit[u]];
    for (int k = 0; k < K; ++k) cl.rhs[K * u + k] = cl.scale[u] * b(cl.components[k], r);
  }
  double reference[K];
  if (reference2)
    for (int k = 0; k < K; ++k) reference[k] = reference2[cl.components[k]];
  solve_cg<K>(cl.A, cl.inv_diag, cl.rhs.data(), nu, cl.solution.data(), reference2 ? reference : nullptr);
  const int n = mesh_.num_nodes();
  for (int j = 0; j < n; ++j) {
    const int u = cl.unknown_of[red.orbit_of[j]];
    for (int k = 0; k < K; ++k) {
      const int c = cl.components[k];
      out(c, j) = u < 0 ? 0.0 : red.node_sign[j][c] * (cl.solution[K * u + k] / cl.scale[u]);
    }
  }
}

void LoadSolver::compute_load_symmetric(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& R, Eigen::Matrix3Xd& q,
                                        bool warm, bool mirror, bool central) {
  const bool have_mirror = mirror && static_cast<int>(mesh_.mirror_node.size()) == mesh_.num_nodes();
  const bool have_central = central && static_cast<int>(mesh_.central_node.size()) == mesh_.num_nodes();
  if (options_.backend != Backend::ConjugateGradient || !(have_mirror || have_central))
    return compute_load(x, R, q, warm);
  // Phases: assemble M (from half the elements under x → −x, the others their images); the reduced right side
  // (R, or for the warm start R − M q0, at the representatives); per class of components, A', CG and the loads.
  const int index = (have_mirror ? 1 : 0) + (have_central ? 2 : 0) - 1;
  if (!reductions_[index]) reductions_[index] = std::make_unique<Reduction>(build_reduction(have_mirror, have_central));
  Reduction& red = *reductions_[index];
  assemble_elements(x, red.elements.empty() ? nullptr : &red.elements);
  Impl& w = *impl_;
  const int n = mesh_.num_nodes();
  const bool from_guess = warm && q.rows() == 3 && q.cols() == R.cols();
  double reference2[3] = {0.0, 0.0, 0.0};
  const Eigen::Matrix3Xd* b = &R;
  if (from_guess) {
    // R − M q0 at the representatives only (the other rows follow by symmetry); the stopping reference is the
    // full |R_c|², in the reduced norm Σ_O (|O|/|G|) |R_r|², which the scaled reduced right side has.
    w.residual.resize(3, n);
    const int* outer = M_.outerIndexPtr();
    const int* inner = M_.innerIndexPtr();
    const double* val = M_.valuePtr();
    for (int r : red.representative) {
      double acc[3] = {0.0, 0.0, 0.0};
      for (int e = outer[r]; e < outer[r + 1]; ++e)
        for (int c = 0; c < 3; ++c) acc[c] += val[e] * q(c, inner[e]);
      for (int c = 0; c < 3; ++c) w.residual(c, r) = R(c, r) - acc[c];
    }
    for (const Reduction::Class& cl : red.classes)
      for (std::size_t u = 0; u < cl.orbit.size(); ++u) {
        const int r = red.representative[cl.orbit[u]];
        for (int c : cl.components) reference2[c] += cl.scale[u] * cl.scale[u] * R(c, r) * R(c, r);
      }
    for (int c = 0; c < 3; ++c)
      if (reference2[c] == 0.0) {  // a zero component has the solution 0 (as in solve())
        q.row(c).setZero();
        for (int r : red.representative) w.residual(c, r) = 0.0;
      }
    b = &w.residual;
  }
  last_iterations_ = 0;
  Eigen::Matrix3Xd& out = from_guess ? w.correction : q;
  out.resize(3, n);
  for (Reduction::Class& cl : red.classes) {
    const double* ref = from_guess ? reference2 : nullptr;
    switch (cl.components.size()) {
      case 1: solve_class<1>(cl, red, *b, ref, out); break;
      case 2: solve_class<2>(cl, red, *b, ref, out); break;
      default: solve_class<3>(cl, red, *b, ref, out); break;
    }
  }
  if (from_guess) {
    // q0 + δ at the representatives (0 where the symmetry says so), then the images by sign: q is exactly symmetric.
    for (const Reduction::Class& cl : red.classes)
      for (int c : cl.components)
        for (int o = 0; o < static_cast<int>(red.representative.size()); ++o) {
          const int r = red.representative[o];
          q(c, r) = cl.unknown_of[o] < 0 ? 0.0 : q(c, r) + w.correction(c, r);
        }
    for (int j = 0; j < n; ++j) {
      const int r = red.representative[red.orbit_of[j]];
      if (j != r)
        for (int c = 0; c < 3; ++c) q(c, j) = red.node_sign[j][c] * q(c, r);
    }
  }
}

}  // namespace capsim::membrane
