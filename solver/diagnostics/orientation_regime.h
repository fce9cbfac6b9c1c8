#pragma once
/// @file
/// @brief The regime of a capsule in any orientation, and the growth rate of its tilt out of the shear plane
/// (solver/README.md §5, "Regimes in any orientation"; the published names of Dupont, Salsac & Barthès-Biesel,
/// JFM 2013, and Dupont et al., JFM 2016).
///
/// Both are free functions of the time series and of the in-plane analysis of the same series
/// (analyse_periods): the in-plane classifier names what the shape's projection on the shear plane does (its
/// D12 and θ), these functions add what the material axis does out of the plane (StepRecord::axis_tilt). They
/// never change the in-plane answer of a case whose axis stays in the plane: classify_regime returns the
/// in-plane regime itself whenever the tilt stays within OrientationOptions::in_plane_tilt over the last
/// period (every seed case has axis_tilt = 0 exactly).
///
/// Cost: O(number of samples) per call.

#include <limits>

#include "solver/diagnostics/period_analysis.h"
#include "solver/diagnostics/time_series.h"

namespace capsim::diagnostics {

/// @brief Thresholds of classify_regime, in degrees of axis_tilt (the angle of the material axis out of the
/// shear plane, [0, 90]). The published papers name the regimes by eye on animations and plots; these numbers
/// are this code's choices, documented (with why) in solver/README.md §5.
struct OrientationOptions {
  /// The axis is "in the plane" over the last period when its tilt never exceeds this: the in-plane answer
  /// stands (tumbling, swinging, steady). Larger tilts are off-plane motion, however small the growth.
  double in_plane_tilt = 1.0;
  /// The axis is "along the vorticity" (rolling) when its tilt never falls below 90 − this.
  double along_vorticity = 2.0;
  /// A precessing or oscillating axis is wobbling (a rolling capsule whose axis circles about the vorticity)
  /// when its tilt never falls below this, i.e. it stays nearer the vorticity than the shear plane; below it
  /// the motion is kayaking (a tumbling projection) or oscillating-swinging (a swinging projection).
  double wobbling_min_tilt = 45.0;
  /// A steady shape off the plane is steady only when the axis tilt moves by at most this over the
  /// stationary window (else the axis still moves while the shape does not: unknown).
  double steady_tilt_spread = 1.0;
};

/// @brief The axis tilt over the last period of the in-plane analysis (periods.front(), the stationary window
/// of a steady regime): time mean (diagnostics::final_tilt), smallest and largest sample. All NaN when the
/// analysis found no period or a sample of the window has no finite tilt (a mesh without pole nodes).
struct TiltStatistics {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double mean = kNaN, min = kNaN, max = kNaN;
};
TiltStatistics last_period_tilt(const TimeSeries& series, const PeriodAnalysis& in_plane);

/// @brief The regime of the case in the published names, from @p in_plane = analyse_periods(series, ...) and
/// the tilt over its last period (last_period_tilt). Rules, in order:
/// 1. no period found (in_plane.regime unknown), or no finite tilt: in_plane.regime, unchanged;
/// 2. max tilt ≤ in_plane_tilt: in_plane.regime, unchanged (tumbling, swinging or steady in the plane);
/// 3. min tilt ≥ 90 − along_vorticity: rolling (the axis stays along the vorticity x3);
/// 4. in-plane steady (a stationary shape): steady if max − min tilt ≤ steady_tilt_spread, else unknown;
/// 5. min tilt ≥ wobbling_min_tilt: wobbling (the axis moves, nearer the vorticity than the plane);
/// 6. in-plane tumbling (the projection turns with the vorticity): kayaking; in-plane swinging (the
///    projection oscillates about a mean inclination): oscillating_swinging.
/// @throws std::invalid_argument if the series is not consistent (TimeSeries::consistent).
Regime classify_regime(const TimeSeries& series, const PeriodAnalysis& in_plane,
                       const OrientationOptions& options = {});

/// @brief Tunables of tilt_growth_rate.
struct TiltGrowthOptions {
  /// Only periods whose mean tilt is at most this (degrees) enter the fit: exponential growth or decay is the
  /// linearised motion about the plane, which a tilt of a few tens of degrees has left.
  double linear_tilt_limit = 20.0;
};

/// @brief Growth rate σ of the tilt out of the shear plane, per unit γ̇t: tilt ∝ exp(σ t). Negative: the capsule
/// returns to the plane (the in-plane regime is stable); positive: it leaves it.
struct TiltGrowth {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double rate = kNaN;   ///< σ, the least-squares slope of ln(mean tilt of a period) against its mid-time
  double error = kNaN;  ///< standard error of the slope (needs ≥ 3 periods; NaN with 2)
  int periods = 0;      ///< periods that entered the fit (0 or 1: rate NaN)
};

/// @brief The growth rate of the tilt over the periods of @p analysis (analyse_periods of the same series):
/// for each period whose time-mean tilt (diagnostics::final_tilt over it) is finite, > 0 and ≤
/// options.linear_tilt_limit, the point (its mid-time, ln of that mean); σ is the least-squares slope through
/// them and its error the slope's standard error, sqrt(Σ residual² / (n − 2) / Σ (t − t̄)²). The mean over a
/// whole period removes the tilt's oscillation within the period (a precessing or tank-treading axis), so a
/// tilt A(t) · f(t) with f of the period gives exactly the rate of A. An in-plane case (tilt 0) has no rate (NaN).
TiltGrowth tilt_growth_rate(const TimeSeries& series, const PeriodAnalysis& analysis,
                            const TiltGrowthOptions& options = {});

/// @brief The off-plane part of the stop test: true when the last @p periods (≥ 2) periods of @p analysis have
/// the same regime by classify_regime (each classified on its own window) and their time-mean tilts agree
/// pairwise to @p tol_tilt degrees; for a steady analysis, the mean tilts of the two halves of the stationary
/// window agree to @p tol_tilt. Always true when the tilt is 0 (or not finite) over those periods, so the stop of an
/// in-plane case is that of periodic_regime_converged alone; false when there are fewer periods.
bool orientation_converged(const TimeSeries& series, const PeriodAnalysis& analysis, double tol_tilt, int periods = 2,
                           const OrientationOptions& options = {});

}  // namespace capsim::diagnostics
