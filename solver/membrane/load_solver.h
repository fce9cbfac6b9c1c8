#pragma once
/// @file
/// @brief The membrane load q from the weak equilibrium M q = R (solver/README.md §2), where
/// M_ab = ∫_S φ_a φ_b dS is the P2 mass matrix on the *deformed* surface and R = ∂W/∂x.
/// q is the load the fluids exert on the membrane (∇s·τ + q = 0): outward on an inflated sphere.

#include <array>
#include <memory>
#include <vector>

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
  /// @brief compute_load for x symmetric under the mirror x3 → −x3 (mesh.mirror_node) and/or the point reflection
  /// x → −x (mesh.central_node), and R equivariant with it (R_g(i) = S_g R_i, S_g the signs mesh::kMirrorSigns,
  /// kCentralSigns; to round-off — the caller checks x: CapsuleFlow). q is then equivariant too, so M q = R is
  /// solved on the symmetric loads only: with B the map from one value per orbit of the group (its smallest node,
  /// the representative) to all nodes (q_g(r) = S_g q_r; a component that a symmetry fixing r flips is 0 there, e.g.
  /// q3 on the mirror plane), the Galerkin system Bᵀ M B q̂ = Bᵀ R, scaled symmetrically by the orbit sizes
  /// (W = diag(|O|/|G|)): A' = W^{−1/2} Bᵀ M B W^{−1/2} / |G|, b' = W^{−1/2} Bᵀ R / |G| = sqrt(|O|/|G|) R_r. A' is SPD,
  /// and |b' − A' q'|² = |R − M q|² / |G| for equivariant fields, so the CG's relative residual test is the full
  /// solve's. Components with the same signs under every group element share one A' (mirror: q1, q2 | q3; x → −x:
  /// all three; both: q1, q2 | q3) and are solved side by side. Element mass matrices are computed for one element
  /// of each orbit (mesh::element_orbits; an image's is its representative's, permuted). One unknown per orbit: half the unknowns
  /// with one symmetry, a quarter with both. q agrees with compute_load's to the CG tolerance and is exactly
  /// equivariant. CG backend only; otherwise, or without the maps the symmetries need, it is compute_load.
  void compute_load_symmetric(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& R, Eigen::Matrix3Xd& q, bool warm,
                              bool mirror, bool central);
  /// @brief compute_load_symmetric with the point reflection alone (numerics.central_symmetry without the mirror).
  void compute_load_centrally_symmetric(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& R, Eigen::Matrix3Xd& q,
                                        bool warm = false);

  /// @brief The last assembled mass matrix (lower and upper parts stored).
  [[nodiscard]] const Eigen::SparseMatrix<double>& mass_matrix() const { return M_; }
  /// @brief CG iterations of the last solve (0 for Cholmod).
  [[nodiscard]] int last_iterations() const { return last_iterations_; }

 private:
  // The reduced systems of one symmetry group (compute_load_symmetric), built on first use.
  struct Reduction {
    struct Class {
      std::vector<int> components;   // the load components solved side by side (1 to 3)
      std::vector<int> orbit;        // unknown → orbit
      std::vector<int> unknown_of;   // orbit → unknown (−1: the components are 0 on that orbit)
      std::vector<double> scale;     // per unknown sqrt(|O| / |G|)
      Eigen::SparseMatrix<double> A;  // A' (pattern built once, values per solve)
      std::vector<int> diagonal_slot;  // per unknown, its diagonal entry in A
      // Each value of A' as Σ coefficient · (value of M): slot k's terms are [contrib_begin[k], contrib_begin[k+1]).
      std::vector<int> contrib_begin, contrib_slot;
      std::vector<double> contrib_coef;
      std::vector<double> inv_diag, rhs, solution;  // per solve
    };
    std::vector<int> representative;                 // orbit → its smallest node
    std::vector<int> orbit_of;                       // node → orbit
    std::vector<std::array<double, 3>> node_sign;    // node → S_g of the g mapping its representative onto it
    std::vector<Class> classes;
    mesh::ElementOrbits elements;                    // the elements under the group (assembly on representatives)
  };
  Reduction build_reduction(bool mirror, bool central) const;
  template <int K>
  void solve_class(Reduction::Class& cl, const Reduction& red, const Eigen::Matrix3Xd& b, const double* reference2,
                   Eigen::Matrix3Xd& out);
  // CG on the matrix A with Jacobi preconditioner inv_diag from zero for K components (b and x are K × n,
  // column-major), stopped at |r_c|² < cg_tolerance² · reference2[c] (nullptr: |b_c|²); adds its iterations to
  // last_iterations_.
  template <int K>
  void solve_cg(const Eigen::SparseMatrix<double>& A, const std::vector<double>& inv_diag, const double* b, int n,
                double* x, const double* reference2 = nullptr);
  // Element mass matrices (every element, or the representatives of `orbits` and their images), summed into M.
  void assemble_elements(const Eigen::Matrix3Xd& x, const mesh::ElementOrbits* orbits);
  struct Impl;
  const mesh::SurfaceMesh& mesh_;
  Options options_;
  Eigen::SparseMatrix<double> M_;
  std::vector<int> value_index_;  // element-major 6×6 → position in M_.valuePtr()
  std::unique_ptr<Reduction> reductions_[3];  // mirror, x → −x, both
  std::unique_ptr<Impl> impl_;
  int last_iterations_ = 0;
};

}  // namespace capsim::membrane
