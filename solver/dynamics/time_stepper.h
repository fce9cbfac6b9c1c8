#pragma once
/// @file
/// @brief Explicit time integrators on dx/dt = v(x) (solver/README.md §4), selected by `time.scheme`:
///  - "rk2": Heun, k1 = v(x_n), k2 = v(x_n + dt k1), x_{n+1} = x_n + dt/2 (k1 + k2). Second order, two flow
///    evaluations per step, stable for dt ρ ≤ 2 on the (nearly real, negative) membrane spectrum, i.e.
///    dt of about Ca h_min / 3: see automatic_time_step.
///  - "rkc": the damped second-order Runge–Kutta–Chebyshev method (van der Houwen & Sommeijer 1980;
///    Verwer 1996; Sommeijer, Shampine & Verwer 1998, J. Comput. Appl. Math. 88, 315). s stages, s flow
///    evaluations per step, second order for every s, real stability interval β(s) ≈ 0.653 s² (damping
///    ε = 2/13). s is chosen per step from the spectral radius ρ(x_n) (membrane_spectral_radius) so that
///    dt ρ ≤ β(s): the cost per unit time grows like sqrt(ρ/dt) instead of ρ, and dt follows accuracy.
///
/// rkc is the default: on the stiff small-Ca cases it needs several times fewer flow evaluations per unit
/// time than rk2 at an error far below the period-to-period spread; on level 2 rk2 stays the cheaper scheme
/// for Ca ≳ 1, where the stiffness is mild and rkc's conservative ρ bound makes it take 3 stages at the rk2
/// dt. On level 3 rkc's accuracy dt (0.02) is above rk2's stable dt up to Ca = 0.9 at least, and rkc takes
/// its 2-stage minimum (where rk2, with the same stability interval, could only match it) only at dt ≈ 0.005.
/// The measurements (evaluations per unit time, errors against rk2 at half its dt, volume drift) are in
/// results/benchmarks.md, "Time integration" and "Evaluations per unit time".

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "solver/dynamics/capsule_flow.h"

namespace capsim::dynamics {

/// @brief What one step saw at its start x_n (first stage), used by the diagnostics.
struct StepInfo {
  FlowEvaluation start;        ///< evaluation at x_n: τmin(t_n), max speed
  double max_displacement = 0; ///< max |x_{n+1} − x_n| over nodes
  /// max |Δx_a − Δx_b| over neighbouring nodes a, b of an element (Δx = x_{n+1} − x_n): how much one step
  /// distorts the mesh. Smooth motion gives ≈ dt |∇v| h ≪ h; an instability gives its own amplitude. Unlike
  /// max_displacement it does not grow with dt for a capsule advected by the shear, so it is the blow-up
  /// test that suits both schemes.
  double max_distortion = 0;
  int evaluations = 0;         ///< flow evaluations this step used
  int stages = 0;              ///< Runge–Kutta stages of this step
};

/// @brief An integrator refuses a step because dt is far too large for the stiffness of the state (RKC
/// would need more than Options::max_stages stages). A numerical outcome like a blow-up: the driver reports
/// the case as unstable with what() as its reason, not as an error.
class StepRejected : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// @brief The velocity and membrane load on x_n, the state a step starts from (its first stage), for
/// output that needs them (snapshots) without another flow evaluation.
struct StartFields {
  Eigen::Matrix3Xd velocity;  ///< v(x_n)
  Eigen::Matrix3Xd load;      ///< q(x_n)
};

/// @brief One explicit step of dx/dt = v(x) with a given dt. Integrators keep only work arrays between
/// steps (no history), so a run resumed from a checkpoint continues exactly.
class TimeIntegrator {
 public:
  virtual ~TimeIntegrator() = default;
  /// @brief Advance x by dt in place. With @p start, also return v and q on the initial x (from the first
  /// stage, which every scheme evaluates there: no extra flow evaluation).
  /// @throws membrane::DegenerateSurface if a stage meets a collapsed surface; StepRejected if the scheme
  /// cannot take dt. x is then unchanged (@p start is filled if the first stage succeeded).
  virtual StepInfo step(CapsuleFlow& flow, Eigen::Matrix3Xd& x, double dt, StartFields* start = nullptr) = 0;
  [[nodiscard]] virtual std::string name() const = 0;
};

/// @brief Default safety factor of the RKC stage choice (time.rkc_safety; case_keys.def has the same default).
/// Measured (results/time_steps): along runs of three level-2 cases (Ca = 0.02–0.9, a/b = 0.5 and
/// 2, both laws) membrane_spectral_radius is 1.17–1.49 × the power-iteration ρ, so with 1.25 the stages cover
/// ρ 1.46–1.86 times. Safety 1.0 saves 8–11% of the evaluations on the level-3 cases (a) and (b) and changed
/// D12 by < 1e-6; it is not the default because the level-3 comparison (where the spheroid calibration
/// above found ρ Ca h_min up to 6.1 against K = 6.5, a 7% margin) and a stability sweep were not done.
/// Then (results/benchmarks.md, "The main command over time"): the main preset's 103 cases (Table 1
/// grid, levels 2–3, κ_b = 0, Ca 0.01–3.5, both laws) all ran stably with 1.0, 10.8% / 9.2% fewer
/// evaluations on levels 2 / 3, every answer within 2.5e-4 of its error; table1_mf_mixed.toml now sets 1.0.
/// The default stays 1.25: changing it would change the identity of every committed case, and bending and
/// level 4 were not swept.
inline constexpr double kRkcSafety = 1.25;

/// @brief Heun's method with preallocated stage arrays.
class Rk2Integrator final : public TimeIntegrator {
 public:
  StepInfo step(CapsuleFlow& flow, Eigen::Matrix3Xd& x, double dt, StartFields* start = nullptr) override;
  [[nodiscard]] std::string name() const override { return std::string(config::word_of(config::TimeScheme::Rk2)); }

 private:
  Eigen::Matrix3Xd k1_, k2_, stage_;
};

/// @brief Coefficients of the s-stage damped second-order RKC (index j = 0..s; entries 0 unused, μ̃ also at 1).
struct RkcCoefficients {
  int stages = 0;
  double w0 = 0, w1 = 0;
  std::vector<double> mu, nu, mu_tilde, gamma_tilde;
  /// @brief β(s) = (1 + w0)/w1: the real stability interval is [−β, 0].
  [[nodiscard]] double stability_boundary() const { return (1.0 + w0) / w1; }
};
/// @brief RKC coefficients for s ≥ 2 stages and damping ε (SSV 1998).
RkcCoefficients rkc_coefficients(int stages, double damping);

/// @brief Damped second-order RKC (SSV 1998, eq. (2.5)–(2.8)):
///   Y0 = x_n,  Y1 = Y0 + μ̃1 dt F0,
///   Yj = (1 − μj − νj) Y0 + μj Y_{j−1} + νj Y_{j−2} + μ̃j dt F(Y_{j−1}) + γ̃j dt F0   (j = 2..s),
///   x_{n+1} = Ys,
/// with w0 = 1 + ε/s², w1 = T's(w0)/T''s(w0), bj = T''j(w0)/T'j(w0)² (b0 = b1 = b2), aj = 1 − bj Tj(w0),
/// μ̃1 = b1 w1, μj = 2 bj w0/b_{j−1}, νj = −bj/b_{j−2}, μ̃j = 2 bj w1/b_{j−1}, γ̃j = −a_{j−1} μ̃j.
/// The stage count is the smallest s ≥ 2 with β(s) ≥ dt · safety · ρ(x_n).
class RkcIntegrator final : public TimeIntegrator {
 public:
  struct Options {
    double damping = 2.0 / 13.0;  ///< ε of w0 = 1 + ε/s² (SSV's value: β(s) ≈ 0.653 s², strong damping)
    double safety = kRkcSafety;   ///< ρ used = safety × membrane_spectral_radius (which is itself an upper fit)
    int max_stages = 400;         ///< refuse (StepRejected) beyond: dt far too large for the problem
  };
  RkcIntegrator() : RkcIntegrator(Options{}) {}
  explicit RkcIntegrator(Options options) : options_(options) {}
  StepInfo step(CapsuleFlow& flow, Eigen::Matrix3Xd& x, double dt, StartFields* start = nullptr) override;
  [[nodiscard]] std::string name() const override { return std::string(config::word_of(config::TimeScheme::Rkc)); }

  /// @brief β(s) = (1 + w0)/w1: the real stability interval [−β, 0] of the s-stage damped RKC.
  static double stability_boundary(int stages, double damping);
  /// @brief Smallest s ≥ 2 with stability_boundary(s) ≥ dt_rho.
  static int stages_for(double dt_rho, double damping);
  /// @brief The spectral radius the last step used (safety included).
  [[nodiscard]] double last_spectral_radius() const { return last_rho_; }

 private:
  Options options_;
  double last_rho_ = 0.0;
  Eigen::Matrix3Xd f0_, f_, y_prev_, y_prev2_, y_;
};

/// @brief max |Δx_a − Δx_b| over the corner–mid-side node pairs of every element.
double max_element_distortion(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& dx);

/// @brief The integrator of time.scheme; @p rkc_safety is RkcIntegrator::Options::safety (time.rkc_safety).
std::unique_ptr<TimeIntegrator> make_integrator(config::TimeScheme scheme, double rkc_safety = kRkcSafety);

/// @brief Upper estimate of the spectral radius of ∂v/∂x on positions x, from the membrane relaxation:
///   ρ ≈ kSpectralRadiusConstant · (1 + kPrestressCoefficient · max(τmax, 0)) / (Ca · h_min(x)),
/// τmax the largest principal tension (units of Gs) on x, h_min(x) the current node spacing.
/// Calibrated by power iteration on dv/dx (estimate_spectral_radius): at the reference spheroids
/// a/b = 0.5, 1, 2 (5% stretch), ρ Ca h_min = 5.1–5.6 at level 2 and 5.8–6.1 at level 3, independent of
/// Ca; on sheared, prestressed states (level 2, γ̇t = 3) ρ Ca h_min(x) / (1 + 0.4 τmax) = 4.5–5.4 for
/// Ca = 0.3–1 (τmax = 0.65–3.3): the prestress stiffens the fast modes (geometric stiffness), which is
/// what lowers the explicit limit at large Ca. The constants bound every measurement from above.
///
/// With bending stiffness κ_b (solver/membrane/bending.h) a mode of wavelength ∝ h relaxes at a rate
/// ∝ κ_b/(Ca h³) (the load ∝ κ_b k⁴ against the Stokes mobility ∝ 1/k); the estimate adds
///   kBendingSpectralConstant · κ_b / (Ca · h_min(x)³),
/// calibrated by power iteration the same way (tests/solver/dynamics/spectral_radius_validation.cc).
///
/// With a viscosity ratio λ (flow.viscosity_ratio) the whole estimate is multiplied by
/// viscosity_stiffness_factor(λ) (below).
double membrane_spectral_radius(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, double capillary_number,
                                double tau_max, double bending_modulus = 0.0, double viscosity_ratio = 1.0);
inline constexpr double kSpectralRadiusConstant = 6.5;
inline constexpr double kPrestressCoefficient = 0.4;
inline constexpr double kBendingSpectralConstant = 45.0;

/// @brief How a viscosity ratio λ scales the membrane's stiffness: 2/(1 + λ) (exactly 1 at λ = 1).
///
/// Why: the fastest modes have the shortest wavelengths, on which the surface is locally flat; there the
/// double layer's principal value vanishes (T·n = 0 for r in the tangent plane) and the second-kind equation
/// reduces to (1 + λ)/2 · v = f: both fluids resist the membrane, and its relaxation rates are those of λ = 1
/// times 2/(1 + λ). Measured by power iteration on dv/dx (estimate_spectral_radius) at the reference
/// spheroids a/b = 0.5, 1, 2, level 2, Ca = 0.05 (results/validation/README.md, "Viscosity ratio", "Stiffness"):
/// ρ(λ)/ρ(1) = 1.77–1.79 at λ = 0.1 (2/(1 + λ) = 1.82) and 0.185–0.188 at λ = 10 (0.182), and the scaled
/// estimate keeps a margin of 1.24–1.41 over the power iteration (1.26–1.37 at λ = 1). The automatic rk2 dt is
/// divided by it and the RKC stages follow it (membrane_spectral_radius), so at λ = 10 a step costs the stages
/// of a membrane 5.5 times softer and at λ = 0.1 of one 1.8 times stiffer.
inline double viscosity_stiffness_factor(double viscosity_ratio) { return 2.0 / (1.0 + viscosity_ratio); }

/// @brief The estimate above for a smallest node spacing @p h_min: the one formula, which the mesh form
/// evaluates at h_min(x) and the campaign's cost estimate at the reference mesh's h_min.
inline double membrane_spectral_radius(double h_min, double capillary_number, double tau_max,
                                       double bending_modulus = 0.0, double viscosity_ratio = 1.0) {
  return viscosity_stiffness_factor(viscosity_ratio) *
         (kSpectralRadiusConstant * (1.0 + kPrestressCoefficient * (tau_max > 0.0 ? tau_max : 0.0)) /
              (capillary_number * h_min) +
          kBendingSpectralConstant * bending_modulus / (capillary_number * h_min * h_min * h_min));
}

/// @brief ρ_bending / ρ_elastic of the estimate above at node spacing h without prestress:
/// kBendingSpectralConstant κ_b / (kSpectralRadiusConstant h²). The one place the automatic dt and the
/// campaign's cost estimate take the bending stiffness from.
inline double bending_stiffness_ratio(double bending_modulus, double h) {
  return kBendingSpectralConstant * bending_modulus / (kSpectralRadiusConstant * h * h);
}

/// @brief Power-iteration estimate of the spectral radius of J = ∂v/∂x at x (finite differences of v,
/// `iterations` flow evaluations plus one). For tests and calibration; the mirror symmetry of a symmetric
/// scene is kept by symmetrising the iterate, so the estimate is over the modes the run can excite.
double estimate_spectral_radius(CapsuleFlow& flow, const Eigen::Matrix3Xd& x, int iterations = 60);

}  // namespace capsim::dynamics
