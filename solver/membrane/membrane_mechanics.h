#pragma once
/// @file
/// @brief Finite-element mechanics of the capsule membrane on P2 isoparametric triangles (solver/README.md §2).
///
/// The reference state X (the initial spheroid) is stress free. At each quadrature point the covariant
/// tangents G_α = ∂X/∂ξ_α and g_α = ∂x/∂ξ_α give the metrics G_αβ, g_αβ; the surface Cauchy-Green tensor
/// G^{-1}g has eigenvalues λ1², λ2²; I1 = tr(G^{-1}g) − 2, Js = sqrt(det g / det G).
/// The elastic energy is W = ∫_S0 ws(I1, Js) dS0 and the nodal internal force is its exact gradient
///   R_a = ∂W/∂x_a = Σ_q w_q √G  A^{αβ} (∂N_a/∂ξ_α) g_β,   A^{αβ} = 2 ∂ws/∂I1 G^{αβ} + ∂ws/∂Js Js g^{αβ}.

#include <span>
#include <vector>

#include <Eigen/Core>

#include "solver/membrane/membrane_law.h"
#include "solver/mesh/mesh.h"
#include "solver/mesh/p2_tabulation.h"

namespace capsim::membrane {

/// @brief Thrown when the current surface has a flipped or collapsed element (a numerical blow-up).
class DegenerateSurface : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// @brief Result of one membrane evaluation on the current positions.
struct MembraneState {
  Eigen::Matrix3Xd internal_force;  ///< R = ∂W/∂x, one column per node
  double energy = 0.0;              ///< W / (Gs ℓ²)
  double tau_min = 0.0;             ///< smallest principal tension over all quadrature points (τmin)
  double tau_max = 0.0;             ///< largest principal tension over all quadrature points
};

/// @brief Membrane kinematics, energy, forces and tensions for one mesh and one law.
///
/// Contract: the mesh connectivity and the reference positions are fixed at construction (reference
/// metrics are precomputed); the law is held by reference and must outlive this object. Evaluations are
/// const and thread-safe.
class MembraneMechanics {
 public:
  /// @brief Quadrature degree of the triangle rule (4, 5 or 6).
  struct Options {
    int quadrature_degree = 6;
  };

  /// @throws std::invalid_argument if an element of the reference surface is degenerate.
  MembraneMechanics(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& reference, const MembraneLaw& law,
                    Options options);
  MembraneMechanics(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& reference, const MembraneLaw& law)
      : MembraneMechanics(mesh, reference, law, Options{}) {}

  /// @brief Energy, internal forces and extreme tensions on positions x. Without @p with_energy the energy
  /// is not computed (MembraneState::energy is NaN): the flow evaluations need forces and tensions only, and
  /// the energy density (a logarithm or a power per quadrature point) was ≈ 2 % of a level-3 evaluation. The
  /// forces and tensions are the same either way.
  /// @throws DegenerateSurface if an element is flipped or collapsed.
  [[nodiscard]] MembraneState evaluate(const Eigen::Matrix3Xd& x, bool with_energy = true) const;

  /// @brief The same, for positions x symmetric under the mirror x3 → −x3 and/or the point reflection x → −x (to
  /// round-off): one element of each orbit of the group (mesh::element_orbits) is evaluated and its images get its
  /// forces with the group element's signs on the image nodes (R is equivariant, the tensions and energy are
  /// invariant): half the work with one symmetry, a quarter with both. Only for such x (the caller checks:
  /// CapsuleFlow); evaluate() if the mesh lacks the maps. Forces agree with evaluate() to round-off, not bitwise.
  [[nodiscard]] MembraneState evaluate_symmetric(const Eigen::Matrix3Xd& x, bool with_energy, bool mirror,
                                                 bool central) const;
  /// @brief evaluate_symmetric with the point reflection alone (numerics.central_symmetry).
  [[nodiscard]] MembraneState evaluate_centrally_symmetric(const Eigen::Matrix3Xd& x, bool with_energy = true) const;
  /// @brief Whether evaluate_centrally_symmetric can use the symmetry (the mesh has a central map that maps
  /// elements onto elements).
  [[nodiscard]] bool has_central_map() const { return !orbits_[1].empty(); }

  /// @brief Elastic energy W only (for finite-difference checks).
  [[nodiscard]] double energy(const Eigen::Matrix3Xd& x) const;

  /// @brief Principal tensions (τ1 ≥ τ2) at every quadrature point, element-major.
  [[nodiscard]] std::vector<std::array<double, 2>> principal_tensions(const Eigen::Matrix3Xd& x) const;

  /// @brief Principal stretches (λ1 ≥ λ2) at every quadrature point, element-major.
  [[nodiscard]] std::vector<std::array<double, 2>> principal_stretches(const Eigen::Matrix3Xd& x) const;

  [[nodiscard]] int num_quadrature_points() const { return static_cast<int>(ref_.size()); }
  [[nodiscard]] const MembraneLaw& law() const { return law_; }

 private:
  struct RefPoint {
    double Ginv[3];   // G^{11}, G^{12}, G^{22}
    double weight0;   // w_q · ½ · √det G (reference area element)
  };
  template <class Visit>
  void for_each_point(const Eigen::Matrix3Xd& x, Visit&& visit) const;
  // Both evaluations: every element (orbits null), or the representatives of `orbits` and their images.
  MembraneState evaluate_elements(const Eigen::Matrix3Xd& x, bool with_energy, const mesh::ElementOrbits* orbits) const;

  const mesh::SurfaceMesh& mesh_;
  const MembraneLaw& law_;
  mesh::P2Tabulation p2_;                                  // the rule's points
  std::vector<RefPoint> ref_;                              // element-major, per rule point
  mesh::ElementOrbits orbits_[3];                          // elements under the mirror, x → −x, both (empty: no map)
};

/// @brief Surface area ∫_S dS and enclosed volume (1/3)∫_S x·n dS of positions x on the exact P2 geometry.
struct AreaVolume {
  double area = 0.0;
  double volume = 0.0;
};
/// @brief Area and volume with a triangle rule of the given degree.
AreaVolume area_and_volume(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, int quadrature_degree = 6);

}  // namespace capsim::membrane
