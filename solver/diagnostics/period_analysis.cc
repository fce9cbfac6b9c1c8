#include "solver/diagnostics/period_analysis.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>

namespace capsim::diagnostics {
namespace {

constexpr double kPi = std::numbers::pi;

// Time of the vertex of the parabola through samples i−1, i, i+1 (refines a sampled minimum's time to
// well below a step for a smooth minimum); clamped to the neighbours, so a kink (D12 → 0 with a V shape)
// is still located within one step.
double refined_time(std::span<const double> t, std::span<const double> y, std::size_t i) {
  if (i == 0 || i + 1 >= y.size()) return t[i];
  const double t0 = t[i - 1], t1 = t[i], t2 = t[i + 1];
  const double y0 = y[i - 1], y1 = y[i], y2 = y[i + 1];
  const double num = (t1 - t0) * (t1 - t0) * (y1 - y2) - (t1 - t2) * (t1 - t2) * (y1 - y0);
  const double den = (t1 - t0) * (y1 - y2) - (t1 - t2) * (y1 - y0);
  if (den == 0 || !std::isfinite(num / den)) return t1;
  return std::clamp(t1 - 0.5 * num / den, t0, t2);
}

// An axis inclination (defined modulo π) brought into (−π/2, π/2].
double wrap_axis_angle(double a) {
  double w = std::remainder(a, kPi);
  if (w <= -0.5 * kPi) w += kPi;
  return w;
}

// Trapezoidal time mean of y over the samples [i0, i1] (y[i0] when they span no time).
double time_mean(std::span<const double> t, std::span<const double> y, std::size_t i0, std::size_t i1) {
  double span = 0, sum = 0;
  for (std::size_t i = i0; i < i1; ++i) {
    span += t[i + 1] - t[i];
    sum += 0.5 * (t[i + 1] - t[i]) * (y[i] + y[i + 1]);
  }
  return span > 0 ? sum / span : y[i0];
}

// Statistics of the samples [i0, i1] (time bounds tb, te already set in w).
void fill_window(PeriodWindow& w, std::span<const double> t, std::span<const double> D12,
                 std::span<const double> theta_u, std::span<const double> tau_min) {
  const std::size_t i0 = w.i_begin, i1 = w.i_end;
  w.min_D12 = *std::min_element(D12.begin() + i0, D12.begin() + i1 + 1);
  w.max_D12 = *std::max_element(D12.begin() + i0, D12.begin() + i1 + 1);
  const auto [tau_lo, tau_hi] = std::minmax_element(tau_min.begin() + i0, tau_min.begin() + i1 + 1);
  w.max_tau_min = *tau_hi;
  w.min_tau_min = *tau_lo;
  const auto [th_lo, th_hi] = std::minmax_element(theta_u.begin() + i0, theta_u.begin() + i1 + 1);
  w.theta_amplitude = 0.5 * (*th_hi - *th_lo);
  w.theta_sweep = theta_u[i1] - theta_u[i0];
  w.mean_D12 = time_mean(t, D12, i0, i1);
  // Unwrapped θ carries the multiples of π picked up on the way (e.g. from the noisy θ of a sphere at
  // rest); the mean axis is reported in (−π/2, π/2] like θ itself.
  w.theta_mean = wrap_axis_angle(time_mean(t, theta_u, i0, i1));
  w.mean_tau_min = time_mean(t, tau_min, i0, i1);
}

// Periods of a tumbling axis: back from the last sample, each window ends where the previous one began and
// begins where unwrapped θ has turned by π more (interpolated). Returns the windows, most recent first.
std::vector<PeriodWindow> tumbling_windows(std::span<const double> t, std::span<const double> theta_u,
                                           int max_periods) {
  std::vector<PeriodWindow> out;
  const std::size_t n = t.size();
  if (n < 2) return out;
  // Going back in time a tumbling θ (decreasing for the clockwise shear vorticity) increases: direction s.
  const double s = theta_u.front() >= theta_u.back() ? 1.0 : -1.0;
  double level = theta_u.back();
  double t_end = t.back();
  std::size_t i_end = n - 1;
  while (static_cast<int>(out.size()) < max_periods) {
    // Latest sample j < i_end at which θ is π (or more) beyond the window's end level.
    std::size_t j = i_end;
    bool found = false;
    while (j > 0) {
      --j;
      if (s * (theta_u[j] - level) >= kPi) {
        found = true;
        break;
      }
    }
    if (!found) break;
    const double target = level + s * kPi;
    // Crossing between j and j + 1 (θ_u[j+1] is short of the target by construction).
    const double a = theta_u[j], b = theta_u[j + 1];
    const double f = (a == b) ? 0.0 : std::clamp((target - a) / (b - a), 0.0, 1.0);
    PeriodWindow w;
    w.t_begin = t[j] + f * (t[j + 1] - t[j]);
    w.t_end = t_end;
    w.i_begin = j;  // one sample beyond the crossing: never miss an extremum at the bound
    w.i_end = i_end;
    out.push_back(w);
    level = target;
    t_end = w.t_begin;
    i_end = j + 1 < i_end ? j + 1 : j;
  }
  return out;
}

}  // namespace

std::string_view to_string(Regime regime) {
  switch (regime) {
    case Regime::steady: return "steady";
    case Regime::tumbling: return "tumbling";
    case Regime::swinging: return "swinging";
    case Regime::rolling: return "rolling";
    case Regime::wobbling: return "wobbling";
    case Regime::kayaking: return "kayaking";
    case Regime::oscillating_swinging: return "oscillating-swinging";
    case Regime::unknown: break;
  }
  return "unknown";
}

std::vector<double> unwrap_axis_angle(std::span<const double> theta) {
  std::vector<double> u(theta.begin(), theta.end());
  double offset = 0;
  for (std::size_t i = 1; i < u.size(); ++i) {
    const double jump = theta[i] - theta[i - 1];
    // An axis angle is defined modulo π: remove the multiple of π that brings the jump into [−π/2, π/2].
    offset -= kPi * std::round(jump / kPi);
    u[i] = theta[i] + offset;
  }
  return u;
}

std::vector<std::size_t> significant_minima(std::span<const double> y, double prominence) {
  // Hysteresis peak detection (Billauer's peakdet): alternate between looking for a maximum and a minimum;
  // an extremum is confirmed once the signal has moved away from it by `prominence`.
  std::vector<std::size_t> minima;
  if (y.size() < 3) return minima;
  double mn = y[0], mx = y[0];
  std::size_t mn_at = 0;
  bool look_for_max = true;
  bool seen_max = false;  // a minimum must follow a confirmed maximum (not the record's first sample)
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double v = y[i];
    if (v > mx) mx = v;
    if (v < mn) mn = v, mn_at = i;
    if (look_for_max) {
      if (v < mx - prominence) {
        seen_max = true;
        look_for_max = false;
        mn = v;
        mn_at = i;
      }
    } else if (v > mn + prominence) {
      if (seen_max && mn_at > 0) minima.push_back(mn_at);
      look_for_max = true;
      mx = v;
    }
  }
  return minima;
}

PeriodAnalysis analyse_periods(std::span<const double> t, std::span<const double> D12,
                               std::span<const double> theta, std::span<const double> tau_min,
                               const PeriodOptions& options) {
  const std::size_t n = t.size();
  if (D12.size() != n || theta.size() != n || tau_min.size() != n)
    throw std::invalid_argument("analyse_periods: t, D12, theta and tau_min differ in length");
  PeriodAnalysis res;
  if (n < 3) return res;
  const std::vector<double> theta_u = unwrap_axis_angle(theta);

  auto finish = [&](Regime regime, std::vector<PeriodWindow> windows) {
    res.regime = regime;
    res.periods = std::move(windows);
    for (auto& w : res.periods) fill_window(w, t, D12, theta_u, tau_min);
    const PeriodWindow& last = res.periods.front();
    res.period = last.period();
    res.revolution_period = 2.0 * res.period;
    res.min_D12 = last.min_D12;
    res.max_tau_min = last.max_tau_min;
    res.mean_D12 = last.mean_D12;
    res.theta_mean = last.theta_mean;
    res.theta_amplitude = last.theta_amplitude;
    res.min_tau_min = last.min_tau_min;
    res.mean_tau_min = last.mean_tau_min;
    res.tau_min_spread = last.max_tau_min - last.min_tau_min;
    if (res.periods.size() >= 2) {
      const std::size_t m = std::min<std::size_t>(res.periods.size(), PeriodAnalysis::kSpreadPeriods);
      double d_lo = last.min_D12, d_hi = d_lo, t_lo = last.max_tau_min, t_hi = t_lo;
      for (std::size_t k = 1; k < m; ++k) {
        d_lo = std::min(d_lo, res.periods[k].min_D12);
        d_hi = std::max(d_hi, res.periods[k].min_D12);
        t_lo = std::min(t_lo, res.periods[k].max_tau_min);
        t_hi = std::max(t_hi, res.periods[k].max_tau_min);
      }
      res.min_D12_period_spread = d_hi - d_lo;
      res.max_tau_min_period_spread = t_hi - t_lo;
    }
    return res;
  };

  // The trailing steady window [i0, n − 1] and the spreads of D12 and θ over it.
  struct Trailing {
    std::size_t i0;
    double d_lo, d_hi, th_spread;
  };
  auto trailing = [&]() -> std::optional<Trailing> {
    if (t.back() - t.front() < options.steady_window) return std::nullopt;
    std::size_t i0 = n - 1;
    while (i0 > 0 && t[i0 - 1] >= t.back() - options.steady_window) --i0;
    const auto [d_lo, d_hi] = std::minmax_element(D12.begin() + i0, D12.end());
    const auto [th_lo, th_hi] = std::minmax_element(theta_u.begin() + i0, theta_u.end());
    return Trailing{i0, *d_lo, *d_hi, *th_hi - *th_lo};
  };
  auto steady = [&](const Trailing& w) {
    PeriodWindow win;
    win.t_begin = t[w.i0];
    win.t_end = t.back();
    win.i_begin = w.i0;
    win.i_end = n - 1;
    finish(Regime::steady, {win});
    res.period = 0;
    res.revolution_period = 0;
    // The period-to-period spread of a steady state: the same statistics on the two halves of the window.
    const std::size_t mid = (w.i0 + n - 1) / 2;
    if (mid > w.i0 && mid < n - 1) {
      const auto d_a = *std::min_element(D12.begin() + w.i0, D12.begin() + mid + 1);
      const auto d_b = *std::min_element(D12.begin() + mid, D12.end());
      const auto t_a = *std::max_element(tau_min.begin() + w.i0, tau_min.begin() + mid + 1);
      const auto t_b = *std::max_element(tau_min.begin() + mid, tau_min.end());
      res.min_D12_period_spread = std::abs(d_a - d_b);
      res.max_tau_min_period_spread = std::abs(t_a - t_b);
    }
    return res;
  };
  const std::optional<Trailing> tail = trailing();

  // 1. Settled: D12 and θ stationary to the strict tolerances (PeriodOptions says why two tests).
  if (tail) {
    const bool circular = tail->d_hi <= options.settled_tol_D12;
    if (tail->d_hi - tail->d_lo <= options.settled_tol_D12 && (circular || tail->th_spread <= options.settled_tol_theta))
      return steady(*tail);
  }
  // 1b. Stationary to the final-analysis tolerance (rule 2 of PeriodOptions). Before the periodic rules: the
  // flicker of a wrinkling membrane makes "significant" D12 minima of its own, which are no swinging.
  // 2 D12 Δθ ≤ tol is written without dividing so that a circular section (D12 = 0) passes.
  if (tail && options.stationary_tolerance > 0) {
    const double tol = options.stationary_tolerance;
    const double shape = 2.0 * std::abs(tail->d_hi);  // boundary displacement per radian of θ
    const std::size_t mid = (tail->i0 + n - 1) / 2;
    const double drift_D12 = time_mean(t, D12, mid, n - 1) - time_mean(t, D12, tail->i0, mid);
    const double drift_theta = time_mean(t, theta_u, mid, n - 1) - time_mean(t, theta_u, tail->i0, mid);
    const double bound = options.stationary_fluctuation * tol;
    if (std::abs(drift_D12) <= tol && shape * std::abs(drift_theta) <= tol && tail->d_hi - tail->d_lo <= bound &&
        shape * tail->th_spread <= bound)
      return steady(*tail);
  }

  // 2. Significant minima of D12, with a prominence scaled on the recent oscillation.
  const auto half = D12.begin() + static_cast<std::ptrdiff_t>(n / 2);
  const auto [lo, hi] = std::minmax_element(half, D12.end());
  const double prominence = std::max(options.min_prominence, options.prominence_fraction * (*hi - *lo));
  const std::vector<std::size_t> minima = significant_minima(D12, prominence);

  const auto tumbling = tumbling_windows(t, theta_u, options.max_periods);
  if (minima.size() >= 2) {
    const std::size_t a = minima[minima.size() - 2], b = minima.back();
    const bool turns = std::abs(theta_u[b] - theta_u[a]) > 0.5 * kPi;
    // θ-based periods of a tumbling axis end at the last sample and do not depend on locating D12 minima;
    // fall back to the minima only while θ has not yet turned by a full π.
    if (turns && !tumbling.empty()) return finish(Regime::tumbling, tumbling);
    const Regime regime = turns ? Regime::tumbling : Regime::swinging;
    std::vector<PeriodWindow> windows;
    for (std::size_t k = minima.size() - 1; k >= 1 && static_cast<int>(windows.size()) < options.max_periods;
         --k) {
      PeriodWindow w;
      w.i_begin = minima[k - 1];
      w.i_end = minima[k];
      w.t_begin = refined_time(t, D12, w.i_begin);
      w.t_end = refined_time(t, D12, w.i_end);
      windows.push_back(w);
    }
    return finish(regime, std::move(windows));
  }

  // 3. Quasi-rigid tumbling: θ turns by π with no significant D12 oscillation.
  if (!tumbling.empty()) return finish(Regime::tumbling, tumbling);

  return res;
}

PeriodAnalysis analyse_periods(const TimeSeries& series, const PeriodOptions& options) {
  return analyse_periods(series.t, series.D12, series.theta, series.tau_min, options);
}

ConvergenceOptions stop_test_options(std::string_view stop_test, double tolerance) {
  constexpr double kUntested = std::numeric_limits<double>::infinity();
  ConvergenceOptions o;
  if (stop_test == kStopTestBoth) {
    o.tol_D12 = o.tol_tau_min = tolerance;
  } else if (stop_test == kStopTestMinD12) {
    o.tol_D12 = tolerance;
    o.tol_tau_min = kUntested;
  } else if (stop_test == kStopTestMaxTauMin) {
    o.tol_D12 = kUntested;
    o.tol_tau_min = tolerance;
  } else {
    throw std::invalid_argument("time.stop_test: unknown stop test '" + std::string(stop_test) + "'");
  }
  return o;
}

bool periodic_regime_converged(const PeriodAnalysis& analysis, const ConvergenceOptions& options) {
  if (analysis.regime == Regime::steady) return true;
  if (analysis.regime == Regime::unknown) return false;
  const int needed = std::max(options.periods, 2);
  if (static_cast<int>(analysis.periods.size()) < needed) return false;
  for (int k = 0; k + 1 < needed; ++k) {
    const PeriodWindow& a = analysis.periods[k];
    const PeriodWindow& b = analysis.periods[k + 1];
    if (std::abs(a.min_D12 - b.min_D12) > options.tol_D12) return false;
    if (std::abs(a.max_tau_min - b.max_tau_min) > options.tol_tau_min) return false;
    if (std::abs(a.period() - b.period()) > options.tol_period * std::max(a.period(), b.period())) return false;
  }
  return true;
}

}  // namespace capsim::diagnostics
