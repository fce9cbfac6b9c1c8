#pragma once
/// @file
/// @brief Indicators of membrane wrinkling and mesh-scale noise.
///
/// A capsule membrane without bending stiffness cannot carry compression: where the smaller principal
/// tension τ2 is negative the continuum problem is ill posed and the discrete one buckles at the mesh scale
/// (the seed discusses the same for its small-Ca oblate cases). Two numbers tell a user whether a run is in
/// that situation:
///  - the compressed area fraction: the share of the current surface where τ2 < 0;
///  - the load roughness: RMS over the nodes of (q·n)_i minus its average over the node's mesh neighbours,
///    divided by the RMS of q·n. For a smooth load the difference is O(h²) (a discrete Laplacian), so the
///    roughness falls like h² (about 4× per mesh level); mesh-scale oscillations (wrinkles, an incipient instability) make
///    it O(1).
/// With bending stiffness the wrinkles get a length of their own; a third number measures it:
///  - the wrinkle wavelength λ = 2π / k of the surface's short-wave relief: the positions high-pass filtered
///    on the current surface, H = (t Ks (M + t Ks)⁻¹)^m applied to each coordinate (M, Ks the P2 mass and
///    Laplace–Beltrami stiffness matrices on x; the response to a surface wave of wavenumber k is
///    (t k² / (1 + t k²))^m), their normal component u = n·H x with its mean removed, and
///    k² = ∫ |∇s u|² dS / ∫ u² dS. Only nodal positions and first derivatives enter, so it converges under
///    refinement (a second derivative, e.g. of the weak curvature, carries O(1) mesh-scale noise on a C⁰
///    surface). With the defaults (filter length √t = 0.2, order m = 6) a wave at k = 12 passes with 0.41
///    of its amplitude and the capsule's own l = 2 shape with 2e-4, so wrinkles a twentieth of the
///    deformation's size dominate it; waves longer than λ ≈ 1.3 (k ≲ 5) are filtered out, so a surface
///    without wrinkles gives λ ≈ 1–2.6 (what is left of its shape), mesh-scale noise (the wrinkles of a
///    membrane without bending) λ of a few node spacings, and the discretisation's own relief of a sphere
///    (≈ 1e-6 of its size) a mesh-scale λ too: the number means something where the relief is well above
///    that. On a sphere the normal part of a componentwise vector filter sees the curvature term 2/R²
///    besides k² (≲ 1 % in λ for k ≥ 9).
///    Predicted for a curved membrane (classical shell buckling: bending κ_b k⁴ against the curvature
///    stiffness E_s / R², E_s = 3 Gs for both laws at small strain): λ = 2π (κ_b R² / E_s)^{1/4} — ∝ κ_b^{1/4}
///    and independent of the mesh once resolved (results/bending/README.md compares).

#include <limits>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "solver/mesh/mesh.h"
#include "solver/mesh/p2_tabulation.h"

namespace capsim::diagnostics {

/// @brief Wrinkle indicators of one state.
struct WrinkleIndicators {
  double compressed_area_fraction = 0;  ///< share of the area with τ2 < 0 (0 … 1)
  double load_roughness = 0;            ///< RMS(q·n − neighbour mean) / RMS(q·n) (0 for a uniform q·n)
  double wrinkle_wavelength = std::numeric_limits<double>::quiet_NaN();  ///< λ (WrinkleWavelength); NaN: none
  double wrinkle_amplitude = std::numeric_limits<double>::quiet_NaN();   ///< RMS of the filtered relief u
};

/// @brief Share of the current area where the smaller principal tension is negative.
/// @param tensions principal tensions (τ1, τ2) at every quadrature point, element-major, as returned by
///        membrane::MembraneMechanics::principal_tensions with the rule of `degree`.
/// @param degree the triangle rule of those points (4, 5 or 6), whose weights the area is summed with.
/// @throws std::invalid_argument if the sizes do not match the mesh and the rule.
double compressed_area_fraction(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x,
                                std::span<const std::array<double, 2>> tensions, int degree);

/// @brief Roughness of the normal load q·n (see the file comment). Returns 0 when q·n vanishes everywhere.
/// @throws std::invalid_argument if x or q do not have one column per node.
double load_roughness(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q);

/// @brief The wrinkle wavelength of a surface (see the file comment), on one mesh.
///
/// Contract: every evaluation assembles Ks on x and takes M from membrane::LoadSolver (quadrature degree 6),
/// and solves (M + t Ks) y = t Ks y' m times for the three coordinates by Jacobi-preconditioned CG
/// (relative residual 1e-10); about as much work as a few load solves. Deterministic; thread-safe (no cached
/// state).
class WrinkleWavelength {
 public:
  struct Options {
    double filter_length = 0.2;   ///< √t, in units of ℓ: waves much longer than it are removed
    int filter_order = 6;         ///< m
    [[nodiscard]] bool valid() const { return filter_length > 0 && filter_order >= 1 && filter_order <= 16; }
  };
  /// @throws std::invalid_argument unless options.valid().
  WrinkleWavelength(const mesh::SurfaceMesh& mesh, Options options);
  explicit WrinkleWavelength(const mesh::SurfaceMesh& mesh);
  /// @brief The wavelength and the amplitude of the relief it measures.
  struct Relief {
    double wavelength = std::numeric_limits<double>::quiet_NaN();  ///< λ = 2π / k
    double amplitude = std::numeric_limits<double>::quiet_NaN();   ///< RMS of u over the area (units of ℓ)
  };
  /// @brief λ and the RMS relief on x; NaN if the filtered relief vanishes or an element of x is collapsed.
  /// The amplitude tells wrinkles from nothing: a wave of amplitude A and wavenumber k shows as
  /// A (t k²/(1 + t k²))^m, the filtered remains of a smooth shape and the discretisation's own relief are
  /// orders smaller (measured in results/bending/README.md), and λ of a relief that small is the mesh's.
  /// @throws std::invalid_argument if x does not have one column per node.
  [[nodiscard]] Relief measure(const Eigen::Matrix3Xd& x) const;
  /// @brief measure(x).wavelength.
  [[nodiscard]] double operator()(const Eigen::Matrix3Xd& x) const { return measure(x).wavelength; }

 private:
  const mesh::SurfaceMesh& mesh_;
  Options options_;
  mesh::P2Tabulation p2_;
};

}  // namespace capsim::diagnostics
