#pragma once
/// @file
/// @brief One capsule case end to end, in the phases of the method: set up (mesh, law, operators, time
/// step, blow-up thresholds), restore from a checkpoint or start from the reference shape, march in time
/// (the integrator of `time.scheme`, RKC by default, on dx/dt = v(x)) with per-step diagnostics and blow-up
/// tests, stop on a converged periodic regime, a blow-up, an interrupt or t_end, finish (final analysis)
/// and output (HDF5 time series, snapshots, checkpoint, the case summary as attributes).
///
/// Blow-up tests, each on the state it concerns: a collapsed element or a step the integrator refuses
/// (dt too large for the stiffness), a runaway disturbance velocity of x_n, non-finite x_{n+1}, a step that
/// moves neighbouring nodes apart by more than h_min/2 (h_min of the reference mesh, so a resumed run has
/// the threshold of the uninterrupted one), a volume of x_{n+1} outside time.volume_tolerance. A state is
/// accepted only after passing them: the last good state, kept in the checkpoint and the last snapshot,
/// never broke a tolerance.

#include <atomic>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>

#include "solver/config/case_config.h"
#include "solver/diagnostics/period_analysis.h"
#include "solver/diagnostics/wrinkle.h"

namespace capsim::driver {

/// @brief Progress report, sent about once per second of wall time.
struct Progress {
  double t = 0, t_end = 0;
  long step = 0;
  double D12 = 0, tau_min = 0;
  double wall_s = 0;
};

/// @brief How to run (not what: that is the CaseConfig).
struct RunOptions {
  std::filesystem::path out_dir = ".";      ///< case.h5, case.xmf, checkpoint.h5 go here
  bool resume = false;                      ///< continue from out_dir/checkpoint.h5 if it exists
  std::function<void(const Progress&)> progress;  ///< optional
  const std::atomic<bool>* stop_requested = nullptr;  ///< set asynchronously (signals): checkpoint and return
  long stop_after_steps = 0;  ///< > 0: behave as if interrupted after this many steps of this invocation
};

/// @brief Outcome of a case. `status`: "done" (t_end reached or periodic regime converged), "unstable"
/// (numerical blow-up; `reason` says which test fired and at which t, the last good state is in the case
/// file and the checkpoint, t_final and steps are its), "interrupted" (stop requested; the checkpoint lets
/// `resume` continue exactly). CaseSummary (case_summary.h) is what a case reports of it.
struct CaseResult {
  std::string status;
  std::string reason;
  bool converged = false;            ///< periodic (or steady) regime reached before t_end
  diagnostics::PeriodAnalysis analysis;
  double volume_drift = 0;           ///< (V(t_final) − V0)/V0
  /// Wrinkle indicators (diagnostics/wrinkle.h) of the final state, and their largest values sampled
  /// every time unit over the run (carried through checkpoints). In wrinkle_max the area fraction, the
  /// roughness and the amplitude are maxima; its wrinkle_wavelength is not a maximum but the λ of the
  /// most wrinkled sample (the one with the largest amplitude).
  diagnostics::WrinkleIndicators wrinkle_final, wrinkle_max;
  long steps = 0;
  /// Cost of the case: a resumed case counts every invocation (the checkpoint carries the totals so far), in
  /// flow_evaluations, wall_s and the phase times alike. (Older checkpoints carry no phase
  /// times: a case resumed from one reports the phases of its later invocations only.)
  long flow_evaluations = 0;        ///< velocity evaluations of the time steps (snapshots reuse a step's own)
  double dt = 0;
  double t_final = 0;
  double wall_s = 0;
  double membrane_s = 0, load_s = 0, stokes_s = 0;  ///< wall time of the phases (membrane: elastic + bending)
  /// GMRES iterations per flow evaluation of the viscosity-ratio solve (flow.viscosity_ratio ≠ 1), mean and
  /// maximum over the case (all invocations); 0 at λ = 1.
  double gmres_iterations_mean = 0;
  int gmres_iterations_max = 0;
  /// Tilt of the material axis out of the shear plane (degrees, diagnostics::final_tilt): its time mean over the
  /// last period found, else its last value. 0 for every in-plane case (the mirror keeps the axis in the plane).
  double final_tilt = 0;
  /// Growth rate of the tilt per unit γ̇t and its standard error (diagnostics::tilt_growth_rate over the periods
  /// of the final analysis): < 0, the capsule returns to the shear plane; NaN in the plane (tilt 0) or with fewer
  /// than two periods (the error: fewer than three).
  double tilt_growth_rate = std::numeric_limits<double>::quiet_NaN();
  double tilt_growth_rate_error = std::numeric_limits<double>::quiet_NaN();
  /// Mean rate of the membrane's spin about the material axis over the last period found (units of γ̇: radians per
  /// 1/γ̇; diagnostics::final_spin_rate, membrane_spin.h), positive counter-clockwise about the axis; NaN when no
  /// period was found.
  double final_spin_rate = std::numeric_limits<double>::quiet_NaN();
  std::filesystem::path case_file;
};

/// @brief Run one case.
/// @throws config::ConfigError for bad input (e.g. a checkpoint of another case or a corrupt one),
/// io::IoError when output cannot be written (folder not creatable, disk full, permissions). Numerical
/// blow-ups are results (status "unstable"), not exceptions.
CaseResult run_case(const config::CaseConfig& config, const RunOptions& options);

}  // namespace capsim::driver
