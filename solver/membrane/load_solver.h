#pragma once
/// @file
/// @brief The membrane load q from the weak equilibrium M q = R (solver/README.md §2), where
/// M_ab = ∫_S φ_a φ_b dS is the P2 mass matrix on the *deformed* surface and R = ∂W/∂x.
/// q is the load the fluids exert on the membrane (∇s·τ + q = 0): outward on an inflated sphere.

#include <memory>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "solver/mesh/mesh.h"

namespace capsim::membrane {

/// @brief Solves M(x) q = R for the three load components at once.
///
/// Contract (Ceres style): the sparsity pattern of M is that of the mesh connectivity, built and analysed
/// (fill-reducing ordering, symbolic factorisation) once in the constructor; every `solve` only refills the
/// values on the current positions and refactorises numerically. Positions passed later must belong to the
/// same mesh. Not thread-safe (the factorisation is cached state).
class LoadSolver {
 public:
  /// @brief Linear-solver backend for the mass matrix.
  enum class Backend {
    Cholmod,            ///< sparse Cholesky (SuiteSparse CHOLMOD), symbolic analysis cached
    ConjugateGradient,  ///< Jacobi-preconditioned CG from a zero initial guess, or on the correction to
                        ///< the caller's guess (solve's `warm`); deterministic either way
  };
  /// The default is CG: a mass matrix has a condition number bounded independently of h, so CG needs the
  /// same few dozen iterations at every level and is several times faster than CHOLMOD's numeric
  /// factorisation + solves with Debian's reference BLAS (tests/benchmarks/membrane_bench.cc; the numbers are
  /// in results/benchmarks.md).
  struct Options {
    Backend backend = Backend::ConjugateGradient;
    int quadrature_degree = 6;      ///< exact for P2×P2 on flat elements
    double cg_tolerance = 1e-12;    ///< relative residual |R − M q| / |R| of the CG backend
                                    ///< (numerics.load_tolerance)
  };

  LoadSolver(const mesh::SurfaceMesh& mesh, Options options);
  explicit LoadSolver(const mesh::SurfaceMesh& mesh) : LoadSolver(mesh, Options{}) {}
  ~LoadSolver();
  LoadSolver(const LoadSolver&) = delete;
  LoadSolver& operator=(const LoadSolver&) = delete;

  /// @brief Assembles M on positions x (values only, cached pattern).
  void assemble(const Eigen::Matrix3Xd& x);
  /// @brief Numeric factorisation (Cholmod) or preconditioner update (CG) of the last assembled M.
  void factorize();
  /// @brief q = M⁻¹ R for the last factorised M (columns are nodes).
  /// @param warm CG only: start from q's current values (a load of the same mesh, e.g. the previous stage's:
  ///        the iterations then only remove the change, to the same relative residual cg_tolerance · |R|)
  ///        instead of zero. Ignored by Cholmod, and when q is not 3 × nodes.
  void solve(const Eigen::Matrix3Xd& R, Eigen::Matrix3Xd& q, bool warm = false);
  /// @brief assemble(x), factorize(), solve(R, q, warm) in one call.
  void compute_load(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& R, Eigen::Matrix3Xd& q, bool warm = false);
  /// @brief The same for x centrally symmetric and R odd under x → −x (x_P(i) = −x_i, R_P(i) = −R_i to round-off;
  /// the caller checks — CapsuleFlow with numerics.central_symmetry): q is odd too, so with q_P(i) = −q_i the
  /// system is solved for one node of each pair {i, P(i)}, the reduced matrix M̃_ij = M_ij − M_i,P(j) (symmetric
  /// positive definite: M restricted to the odd loads), half the unknowns; element mass matrices are computed for
  /// half the elements (an element's is its image's, permuted). The residual test is the same relative one (the
  /// full residual is the reduced one and its negated image). q agrees with compute_load's to the CG tolerance,
  /// and is exactly odd. CG backend only; otherwise, or without a central map, it is compute_load.
  void compute_load_centrally_symmetric(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& R, Eigen::Matrix3Xd& q,
                                        bool warm = false);

  /// @brief The last assembled mass matrix (lower and upper parts stored).
  [[nodiscard]] const Eigen::SparseMatrix<double>& mass_matrix() const { return M_; }
  /// @brief CG iterations of the last solve (0 for Cholmod).
  [[nodiscard]] int last_iterations() const { return last_iterations_; }

 private:
  // CG on the matrix A with Jacobi preconditioner inv_diag from zero, stopped at |r_c|² < cg_tolerance² ·
  // reference2[c] (nullptr: |R_c|²).
  void solve_cg(const Eigen::SparseMatrix<double>& A, const std::vector<double>& inv_diag, const Eigen::Matrix3Xd& R,
                Eigen::Matrix3Xd& q, const double* reference2 = nullptr);
  // Element mass matrices (of `elements`, all when null, the others as their images), summed into M.
  void assemble_elements(const Eigen::Matrix3Xd& x, const std::vector<int>* elements);
  // The reduced system of compute_load_centrally_symmetric, built once (constructor).
  void build_reduced();
  struct Impl;
  const mesh::SurfaceMesh& mesh_;
  Options options_;
  Eigen::SparseMatrix<double> M_;
  std::vector<int> value_index_;  // element-major 6×6 → position in M_.valuePtr()
  mesh::CentralElements central_;  // x → −x on elements (empty: no reduced solve)
  std::vector<int> reduced_node_;  // reduced unknown → its node (the smaller index of each pair {i, P(i)})
  Eigen::SparseMatrix<double> Mr_;  // the reduced matrix M̃ (pattern built once)
  // Each value of M̃ as Σ sign · (value of M): the contributions of slot s are [contrib_begin_[s], contrib_begin_[s+1]).
  std::vector<int> contrib_begin_, contrib_slot_;
  std::vector<double> contrib_sign_;
  std::unique_ptr<Impl> impl_;
  int last_iterations_ = 0;
};

}  // namespace capsim::membrane
