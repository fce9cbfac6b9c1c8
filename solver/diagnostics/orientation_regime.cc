#include "solver/diagnostics/orientation_regime.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace capsim::diagnostics {
namespace {

// The tilt statistics over one period window (sample bounds for the extrema, time bounds for the mean).
TiltStatistics window_tilt(const TimeSeries& s, const PeriodWindow& w) {
  TiltStatistics out;
  if (w.i_end >= s.size() || w.i_begin > w.i_end) return out;
  double lo = s.axis_tilt[w.i_begin], hi = lo;
  for (std::size_t i = w.i_begin; i <= w.i_end; ++i) {
    const double a = s.axis_tilt[i];
    if (!std::isfinite(a)) return out;
    lo = std::min(lo, a);
    hi = std::max(hi, a);
  }
  out.min = lo;
  out.max = hi;
  out.mean = final_tilt(s, w.t_begin, w.t_end);
  return out;
}

// Rules 2–6 of classify_regime for one window whose in-plane regime is @p in_plane (not unknown).
Regime classify_window(Regime in_plane, const TiltStatistics& tilt, const OrientationOptions& o) {
  if (!std::isfinite(tilt.min) || !std::isfinite(tilt.max)) return in_plane;
  if (tilt.max <= o.in_plane_tilt) return in_plane;
  if (tilt.min >= 90.0 - o.along_vorticity) return Regime::rolling;
  if (in_plane == Regime::steady) return tilt.max - tilt.min <= o.steady_tilt_spread ? Regime::steady : Regime::unknown;
  if (tilt.min >= o.wobbling_min_tilt) return Regime::wobbling;
  if (in_plane == Regime::tumbling) return Regime::kayaking;
  if (in_plane == Regime::swinging) return Regime::oscillating_swinging;
  return Regime::unknown;
}

void require_consistent(const TimeSeries& s, const char* who) {
  if (!s.consistent()) throw std::invalid_argument(std::string(who) + ": the time series' columns differ in length");
}

}  // namespace

TiltStatistics last_period_tilt(const TimeSeries& series, const PeriodAnalysis& in_plane) {
  if (in_plane.periods.empty() || series.empty()) return {};
  return window_tilt(series, in_plane.periods.front());
}

Regime classify_regime(const TimeSeries& series, const PeriodAnalysis& in_plane, const OrientationOptions& options) {
  require_consistent(series, "classify_regime");
  if (in_plane.regime == Regime::unknown || in_plane.periods.empty()) return in_plane.regime;
  return classify_window(in_plane.regime, last_period_tilt(series, in_plane), options);
}

TiltGrowth tilt_growth_rate(const TimeSeries& series, const PeriodAnalysis& analysis, const TiltGrowthOptions& options) {
  require_consistent(series, "tilt_growth_rate");
  TiltGrowth g;
  std::vector<double> t, y;
  for (const PeriodWindow& w : analysis.periods) {
    if (!(w.t_end > w.t_begin)) continue;
    const double mean = final_tilt(series, w.t_begin, w.t_end);
    if (!std::isfinite(mean) || !(mean > 0.0) || mean > options.linear_tilt_limit) continue;
    t.push_back(0.5 * (w.t_begin + w.t_end));
    y.push_back(std::log(mean));
  }
  g.periods = static_cast<int>(t.size());
  if (t.size() < 2) return g;
  const double n = static_cast<double>(t.size());
  double tm = 0, ym = 0;
  for (std::size_t k = 0; k < t.size(); ++k) tm += t[k], ym += y[k];
  tm /= n;
  ym /= n;
  double stt = 0, sty = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    stt += (t[k] - tm) * (t[k] - tm);
    sty += (t[k] - tm) * (y[k] - ym);
  }
  if (!(stt > 0)) return g;
  g.rate = sty / stt;
  if (t.size() >= 3) {
    double ss = 0;
    for (std::size_t k = 0; k < t.size(); ++k) {
      const double r = y[k] - (ym + g.rate * (t[k] - tm));
      ss += r * r;
    }
    g.error = std::sqrt(ss / (n - 2.0) / stt);
  }
  return g;
}

bool orientation_converged(const TimeSeries& series, const PeriodAnalysis& analysis, double tol_tilt, int periods,
                           const OrientationOptions& options) {
  require_consistent(series, "orientation_converged");
  if (analysis.regime == Regime::unknown || analysis.periods.empty()) return false;
  if (analysis.regime == Regime::steady) {
    // The two halves of the stationary window, as the steady rule compares D12 and θ.
    const PeriodWindow& w = analysis.periods.front();
    const double mid = 0.5 * (w.t_begin + w.t_end);
    const double a = final_tilt(series, w.t_begin, mid), b = final_tilt(series, mid, w.t_end);
    const TiltStatistics whole = window_tilt(series, w);
    if (!std::isfinite(whole.max) || whole.max == 0.0) return true;  // in the plane exactly, or no axis
    return std::abs(a - b) <= tol_tilt;
  }
  const std::size_t needed = static_cast<std::size_t>(std::max(periods, 2));
  if (analysis.periods.size() < needed) return false;
  std::vector<TiltStatistics> tilt;
  for (std::size_t k = 0; k < needed; ++k) tilt.push_back(window_tilt(series, analysis.periods[k]));
  if (std::all_of(tilt.begin(), tilt.end(),
                  [](const TiltStatistics& s) { return !std::isfinite(s.max) || s.max == 0.0; }))
    return true;  // in the plane exactly, or no axis: the in-plane stop test decides alone
  const Regime last = classify_window(analysis.regime, tilt[0], options);
  for (std::size_t k = 1; k < needed; ++k) {
    if (classify_window(analysis.regime, tilt[k], options) != last) return false;
    if (!(std::abs(tilt[k].mean - tilt[k - 1].mean) <= tol_tilt)) return false;
  }
  return true;
}

}  // namespace capsim::diagnostics
