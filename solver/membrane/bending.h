#pragma once
/// @file
/// @brief Bending stiffness of the capsule membrane (solver/README.md §2.4): a Helfrich energy
/// measured against the reference curvature, on the P2 surface, with its exact discrete gradient.
///
/// **Continuum model.** With c = κ1 + κ2 the total curvature (2/R on a sphere of radius R, outward normal)
/// and c0(X) the total curvature of the stress-free reference spheroid at the same material point,
///   W_b = (κ_b / 2) ∫_S (c − c0)² dS,     κ_b = Kb / (Gs ℓ²)  (capsule.bending_modulus).
/// W_b vanishes on the reference (to round-off, as the discrete c0 is the discrete c of the reference) and
/// under rigid motions (c and dS are invariant). The bending moment is m = κ_b (c − c0) (units Gs ℓ).
/// Two closed forms the tests check:
///  - an inflated unit sphere, x = R X: c = 2/R, W_b = 8π κ_b (1 − R)²;
///  - a perturbed unit sphere, x = X (1 + ε Y_l): c = 2 + ε (l − 1)(l + 2) Y_l + O(ε²), so
///    W_b = (κ_b/2) ε² (l − 1)² (l + 2)² ∫ Y_l² dS + O(ε³), and the load q (δW_b = ∫ q·δx dS, the same
///    definition as the elastic load: M q = R) is normal to first order,
///      q·n = κ_b (l − 1)² (l + 2)² ε Y_l,   q·t = O(ε²).
///    (l = 0 is the inflation above, l = 1 a translation: no load.)
///
/// **Discretisation.** The curvature vector comes from the weak Laplace–Beltrami identity on the P2 mesh,
///   ∫_S h·φ_a dS = −∫_S ∇s x : ∇s φ_a dS   ⇔   M(x) h = −K(x) x,    h = Δs x = −c n,
/// (M the P2 mass matrix, K the P2 Laplace–Beltrami stiffness, both on the current surface), and at each
/// quadrature point c = −h·n with h interpolated from the nodes and n the exact unit normal of the P2 map:
///   W_b = (κ_b / 2) Σ_e Σ_q w_q J_q (c_q − c0_q)²,   J_q = |g1 × g2|.
/// A mesh-scale wrinkle has a large nodal h (the weak Laplacian of an oscillation), so it is penalised, which
/// the smooth per-element curvature of a C⁰ P2 surface alone would not do (kinks carry no element curvature).
///
/// **Gradient (adjoint).** W_b depends on x directly and through h. With Λ the solution of the adjoint
/// mass problem M Λ = G, G_a = κ_b Σ_q w_q J_q (c_q − c0_q) n_q φ_a(q), the exact derivative is
///   R_b = ∂W_b/∂x|_h + ∂/∂x [ ∫ Λ·h dS + ∫ ∇s Λ : ∇s x dS ]|_{Λ, h},
/// every term a function of the tangents g1, g2 at the quadrature points (formulas in bending.cc). Cost:
/// K x and the two point loops, and two mass solves (3 right-hand sides each) with the factorisation the
/// load solve uses anyway.
///
/// Stiffness: a mode of wavelength ∝ h relaxes at a rate ∝ κ_b / (Ca h³) (∝ 1/(Ca h) for elasticity), which
/// the time stepper's spectral radius includes (dynamics::membrane_spectral_radius).

#include <Eigen/Core>

#include "solver/membrane/load_solver.h"
#include "solver/mesh/mesh.h"
#include "solver/mesh/p2_tabulation.h"

namespace capsim::membrane {

/// @brief The bending law: energy density per unit current area (κ_b/2)(c − c0)² and moment κ_b (c − c0).
class HelfrichBending {
 public:
  /// @throws std::invalid_argument unless modulus ≥ 0 and finite.
  explicit HelfrichBending(double modulus);
  [[nodiscard]] double modulus() const { return kb_; }
  /// @brief (κ_b/2)(c − c0)².
  [[nodiscard]] double energy_density(double c, double c0) const { return 0.5 * kb_ * (c - c0) * (c - c0); }
  /// @brief m = ∂w/∂c = κ_b (c − c0).
  [[nodiscard]] double moment(double c, double c0) const { return kb_ * (c - c0); }

 private:
  double kb_;
};

/// @brief Result of one bending evaluation.
struct BendingState {
  Eigen::Matrix3Xd internal_force;  ///< R_b = ∂W_b/∂x, one column per node
  double energy = 0.0;              ///< W_b / (Gs ℓ²)
  double max_moment = 0.0;          ///< max |m| = max κ_b |c − c0| over the quadrature points (Gs ℓ)
};

/// @brief Helfrich bending on one mesh, measured against the curvature of the reference positions.
///
/// Contract: connectivity and reference positions fixed at construction (the reference curvature c0 at
/// every quadrature point is computed then, with a load solver of the given options); the model is copied.
/// `solver` passed to the evaluations must belong to the same mesh; it is left factorised on x, so the
/// caller can solve M(x) q = R_elastic + R_b with it without assembling again. Not thread-safe (the
/// solver's cached state), deterministic for any thread count.
class BendingMechanics {
 public:
  /// @param solver_options those of the load solver the evaluations will be given: the energy and K x use
  /// its quadrature rule, so that ∫ Λ·h dS is exactly Λᵀ M h and the gradient is exact.
  /// @throws std::invalid_argument if the reference is degenerate or has the wrong size.
  BendingMechanics(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& reference, HelfrichBending model,
                   LoadSolver::Options solver_options);

  /// @brief Energy, forces and largest moment on x. Assembles and factorises @p solver on x.
  /// @throws DegenerateSurface if an element of x is collapsed.
  [[nodiscard]] BendingState evaluate(const Eigen::Matrix3Xd& x, LoadSolver& solver) const;
  /// @brief W_b only (for finite-difference checks). Assembles and factorises @p solver on x.
  [[nodiscard]] double energy(const Eigen::Matrix3Xd& x, LoadSolver& solver) const;
  /// @brief c = −h·n at every quadrature point, element-major (the discrete total curvature).
  [[nodiscard]] Eigen::VectorXd total_curvature(const Eigen::Matrix3Xd& x, LoadSolver& solver) const;
  /// @brief The reference curvature c0, element-major.
  [[nodiscard]] const Eigen::VectorXd& reference_curvature() const { return c0_; }
  [[nodiscard]] const HelfrichBending& model() const { return model_; }

 private:
  // Nodal curvature vector h = −M⁻¹ K x on x (solver assembled and factorised on x here).
  Eigen::Matrix3Xd curvature_vector(const Eigen::Matrix3Xd& x, LoadSolver& solver) const;
  Eigen::VectorXd curvature_at_points(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& h) const;

  const mesh::SurfaceMesh& mesh_;
  HelfrichBending model_;
  mesh::P2Tabulation p2_;
  Eigen::VectorXd c0_;
};

}  // namespace capsim::membrane
