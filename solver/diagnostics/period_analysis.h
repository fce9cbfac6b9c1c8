#pragma once
/// @file
/// @brief Periodic-regime analysis of the diagnostics time series: period, min D12, max τmin, mean D12 over
/// the last full period, the regime (tumbling / swinging / steady), and the stopping test of solver/README.md §4.
///
/// What "period" means here. The capsule (a spheroid, centrally symmetric) in linear shear keeps its central
/// symmetry x → −x, so its shape repeats after half a material revolution: a tumbling capsule's long axis
/// turns by π, a swinging capsule's membrane turns by half a turn. `period` is that shape period, which is
/// the period of D12(t), θ(t) mod π and τmin(t) (each has one minimum and one maximum per period). The
/// material point P needs two shape periods to come back: the seed's "period" of figure 1 (drawn over "one
/// half period") is `revolution_period` = 2 · period. For a rigid tumbling ellipse (Jeffery orbit) the
/// revolution period is 2π (r + 1/r) and `period` is π (r + 1/r). min D12 and max τmin over one shape
/// period equal those over a revolution, so they are the seed's min D12 (eq. 12) and max τmin (eq. 13).
///
/// Cost: O(number of samples) per call; call it every few tenths of a time unit, not at every step.

#include <cstddef>
#include <limits>
#include <span>
#include <string_view>
#include <vector>

#include "solver/diagnostics/time_series.h"

namespace capsim::diagnostics {

/// @brief Motion regime of the capsule (seed §3.1–3.2; off the plane, Dupont et al. 2013, 2016).
/// analyse_periods names the first four from the shape's projection on the shear plane; the off-plane ones are
/// named by classify_regime (orientation_regime.h) from the material axis's tilt as well.
enum class Regime {
  unknown,   ///< not enough data for a full period or a stationary window
  steady,    ///< D12 and θ stationary (spherical capsule: steady deformed shape, tank-treading membrane)
  tumbling,  ///< the long axis keeps rotating with the vorticity: θ unwrapped turns through ±π/2 and beyond
  swinging,  ///< the long axis oscillates about a mean inclination while the membrane rotates
  rolling,   ///< the axis of revolution stays along the vorticity x3 (the membrane tank-treads about it)
  wobbling,  ///< the axis moves about the vorticity, staying nearer it than the shear plane
  kayaking,  ///< the axis precesses about the vorticity at an intermediate tilt (an off-plane tumbling)
  oscillating_swinging,  ///< the projection swings while the axis oscillates out of the shear plane
};

/// @brief "unknown" | "steady" | "tumbling" | "swinging" | "rolling" | "wobbling" | "kayaking" |
/// "oscillating-swinging".
std::string_view to_string(Regime regime);

/// @brief Tolerances of the stopping test.
struct ConvergenceOptions {
  double tol_D12 = 1e-3;      ///< absolute, on min D12 (D12 near the transition is ~0: no relative tol)
  double tol_tau_min = 1e-3;  ///< absolute, on max τmin (units of Gs)
  double tol_period = 0.02;   ///< relative, on the period
  int periods = 2;            ///< number of successive periods that must agree pairwise (≥ 2)
};

/// @brief The values of time.stop_test, named once (the key registry, solver/config/case_keys.def, accepts
/// exactly these; PeriodicConvergence.StopTestNamesAreTheRegistrysValues checks it).
inline constexpr std::string_view kStopTestBoth = "both", kStopTestMinD12 = "min_D12",
                                  kStopTestMaxTauMin = "max_tau_min";

/// @brief The stop test of a case: @p tolerance on the answers @p stop_test names (time.stop_test: "both",
/// "min_D12" or "max_tau_min"); the other one gets an infinite tolerance, i.e. is not compared (a Table 1
/// answer needs only one of them: a Ca* edge min D12, CaH max τmin). The period is compared in every case.
/// @throws std::invalid_argument for another name (the key registry admits none).
ConvergenceOptions stop_test_options(std::string_view stop_test, double tolerance);

/// @brief Tunables of analyse_periods.
struct PeriodOptions {
  /// A minimum of D12 is significant when D12 rises by at least max(min_prominence,
  /// prominence_fraction · (max − min of D12 over the second half of the record)) on both sides of it.
  /// Small wiggles (sampling noise, wrinkles) are thus not taken for periods.
  double prominence_fraction = 0.2;
  double min_prominence = 1e-4;
  /// Steady state (solver/README.md §4), recognised from the shape alone, by two tests of the trailing
  /// `steady_window` time units (1/γ̇). τmin is never tested: without bending stiffness a compressed membrane
  /// wrinkles at the mesh scale and τmin, a pointwise minimum over the surface, flickers by O(10⁻²) while
  /// the shape is stationary to 10⁻³.
  ///
  /// 1. Settled (rule 1, tried first, and the only one the stop test sees): the spread max − min of D12 is
  ///    ≤ settled_tol_D12 and that of the unwrapped θ ≤ settled_tol_theta (θ ignored when D12 ≤
  ///    settled_tol_D12: a circular section has no long axis). Strict on purpose: a steady state offers no
  ///    period-to-period comparison to confirm that the run has converged, so stopping a run early needs a
  ///    shape settled well below the period tolerance.
  /// 2. Stationary (tried next, before the periodic rules, and only where `stationary_tolerance` > 0 — the
  ///    driver sets it for the final analysis of a run, to time.period_tolerance): the time means of D12 over
  ///    the two halves of the window differ by ≤ stationary_tolerance (no drift), and so does the shape
  ///    change 2·D12·Δθ of the means of θ; the spread of D12 (and 2·D12 × the spread of θ) stays below
  ///    stationary_fluctuation × stationary_tolerance (flicker, not an oscillation of the shape). This
  ///    classifies what a run ended with (e.g. a sphere whose D12 flickers by a few 10⁻³ with the wrinkles,
  ///    run to its t_end) instead of leaving it `unknown` or taking the flicker's own D12 minima for a
  ///    swinging; the reported spreads say how steady it was.
  ///
  /// Why the stationary test. Its tolerance is the one the stop test puts on min D12 between successive
  /// periods: a steady state is a periodic one whose period has shrunk to nothing, held to the same accuracy,
  /// and the difference of the half-window means is what a drift (a transient still relaxing) changes, while
  /// zero-mean flicker does not. The fluctuation bound keeps real oscillations out: mesh-scale flicker of D12
  /// is a few 10⁻³ at level 3 (results/validation/steady_spheres), while a swinging or tumbling shape moves D12 by
  /// O(10⁻²) and more within any 5 time units (results/table1_paper). The θ terms convert a rotation into
  /// the boundary displacement it causes on an ellipse of Taylor parameter D (≈ 2 D δθ, against δD for a
  /// change of D12), so D12 and θ are held to the same shape accuracy; as D12 → 0 (a circular section, whose
  /// θ is noise) they relax by themselves. The window: the shape relaxes on the membrane
  /// time scale, O(1) in units of 1/γ̇ for the Ca of interest (0.1–1), and wrinkles flicker on much shorter
  /// scales, so 5 units covers several relaxation times (a transient with time constant τ ≲ 1 has decayed
  /// by e⁻⁵ across it if its spread passes) and many flicker cycles (so max/min/mean of τmin over it are
  /// meaningful statistics).
  double steady_window = 5.0;
  double settled_tol_D12 = 1e-4;
  double settled_tol_theta = 1e-3;
  double stationary_tolerance = 0.0;  ///< 0: the stationary rule is off (as during the march)
  double stationary_fluctuation = 5.0;
  /// At most this many most-recent periods are analysed.
  int max_periods = 16;
};

/// @brief One full shape period of the record.
struct PeriodWindow {
  double t_begin = 0, t_end = 0;        ///< period = t_end − t_begin (interpolated bounds)
  std::size_t i_begin = 0, i_end = 0;   ///< samples [i_begin, i_end] over which the extrema are taken
  double min_D12 = 0, max_D12 = 0, mean_D12 = 0;  ///< mean: trapezoidal time average
  double max_tau_min = 0;               ///< max over the window of τmin(t), seed eq. (13)
  double min_tau_min = 0, mean_tau_min = 0;  ///< min and time mean over the window of τmin(t)
  double theta_sweep = 0;               ///< θ(end) − θ(begin), unwrapped: ≈ −π tumbling, ≈ 0 swinging
  double theta_mean = 0, theta_amplitude = 0;  ///< time mean (in (−π/2, π/2]) and half range of unwrapped θ
  /// @brief Duration of the window.
  [[nodiscard]] double period() const { return t_end - t_begin; }
};

/// @brief Result of analyse_periods. The scalar results are those of the last full period (periods[0]);
/// NaN when unknown.
///
/// Steady regime: period = revolution_period = 0 and periods[0] is the stationary trailing window; the
/// scalars are its statistics. mean_D12 and theta_mean (time means) are the steady D12 and θ; min_D12 is
/// the smallest D12 in the window (the steady D12 to within the window's spread) and
/// max_tau_min the largest τmin(t) in it. These keep the meaning the Table 1 analysis gives them for a
/// periodic regime (extrema over the analysed window): Ca* needs min D12 < 0.05 somewhere, and CaH is
/// where max τmin < 0, i.e. where the membrane is compressed somewhere at every instant — with a
/// flickering τmin the window's maximum is the least compressed instant, so max_tau_min < 0 still means
/// "never free of compression", as it does over a period. min_tau_min, mean_tau_min and tau_min_spread
/// show how much of it is flicker.
struct PeriodAnalysis {
  Regime regime = Regime::unknown;
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double period = kNaN;             ///< shape period = period of D12(t) (see file comment); 0 when steady
  double revolution_period = kNaN;  ///< 2 · period: return time of the material point P
  double min_D12 = kNaN, max_tau_min = kNaN, mean_D12 = kNaN;
  double theta_mean = kNaN, theta_amplitude = kNaN;
  double min_tau_min = kNaN, mean_tau_min = kNaN;  ///< statistics of τmin(t) over the same window
  double tau_min_spread = kNaN;                    ///< max_tau_min − min_tau_min
  /// How much the answers move from period to period (the "periods" error of a Table 1 answer): max − min
  /// of min D12 and of max τmin over the last kSpreadPeriods = 2 full periods (the two the stopping test
  /// compares: an earlier one may still be in the start-up transient; NaN
  /// with one). Steady: the difference between the two halves of the stationary window (the same
  /// statistics taken on each half), i.e. how much the flicker moves them.
  double min_D12_period_spread = kNaN, max_tau_min_period_spread = kNaN;
  static constexpr int kSpreadPeriods = 2;
  /// Complete periods found, the most recent first. Tumbling: successive turns of θ by π back from the
  /// last sample. Swinging: between successive significant minima of D12. Steady: the one trailing window.
  std::vector<PeriodWindow> periods;
};

/// @brief Unwrap an axis inclination (defined modulo π): each jump of more than π/2 between samples is
/// taken as a wrap and removed, so a tumbling axis gives a monotone θ and a swinging one stays bounded.
std::vector<double> unwrap_axis_angle(std::span<const double> theta);

/// @brief Indices of the significant local minima of y (hysteresis peak detection): a minimum is reported
/// when y has fallen by at least `prominence` from a preceding maximum and rises by at least `prominence`
/// after it. The first and last samples are never reported.
std::vector<std::size_t> significant_minima(std::span<const double> y, double prominence);

/// @brief Analyse the record: regime, period, min D12, max τmin, mean D12 over the last full period.
///
/// Rules, in order:
/// 1. steady if D12 and θ have settled over the last steady_window (see PeriodOptions), whatever τmin does;
/// 2. with ≥ 2 significant minima of D12: the last interval between them is one period; tumbling if θ turns
///    there by more than π/2 (expected π), else swinging. Tumbling periods are then taken from θ (3);
///    swinging periods are the intervals between successive minima;
/// 3. tumbling without D12 oscillation (a quasi-rigid capsule at small Ca, D12 almost constant): θ has
///    turned by π at least once; each period is the time for θ to turn by π, counted back from the last
///    sample with linear interpolation;
/// 4. otherwise unknown.
/// All spans must have the same size and t must increase.
/// @throws std::invalid_argument on mismatched sizes.
PeriodAnalysis analyse_periods(std::span<const double> t, std::span<const double> D12,
                               std::span<const double> theta, std::span<const double> tau_min,
                               const PeriodOptions& options = {});

/// @brief Same, on a TimeSeries.
PeriodAnalysis analyse_periods(const TimeSeries& series, const PeriodOptions& options = {});

/// @brief The stopping test of solver/README.md §4: true when the regime is steady, or periodic (tumbling or
/// swinging) with the last `periods` full periods agreeing pairwise on min D12, max τmin and the period.
bool periodic_regime_converged(const PeriodAnalysis& analysis, const ConvergenceOptions& options = {});

}  // namespace capsim::diagnostics
