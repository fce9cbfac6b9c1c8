#include "campaign/analysis/refinement.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "campaign/grid/decimal.h"

namespace capsim::campaign {

double quantise_ca(double x, double tolerance) {
  // Round to a decimal quantum 10^-scale below tolerance/2, exactly (0.0275, not 0.027500000000000004).
  const int scale = std::max(0, static_cast<int>(-std::floor(std::log10(tolerance / 2))));
  return Decimal{static_cast<std::int64_t>(std::llround(x * std::pow(10.0, scale))), scale}.to_double();
}

std::vector<double> propose_refinement(const Transition& t, std::vector<Sample> samples, double tol,
                                       const std::vector<double>& existing) {
  return propose_refinement(t, std::move(samples), tol, BracketTolerances{tol, tol, tol}, existing);
}

std::vector<double> propose_refinement(const Transition& t, std::vector<Sample> samples, double tol,
                                       const BracketTolerances& per, const std::vector<double>& existing) {
  std::sort(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.ca < b.ca; });
  std::vector<double> out;
  auto add = [&](double x) {
    x = quantise_ca(x, tol);
    if (!(x > 0)) return;
    auto same = [x](double y) { return same_ca(y, x); };
    for (const auto& s : samples)
      if (same(s.ca)) return;
    // A case at this Ca exists already (queued, unstable or failed): proposing it adds nothing.
    if (std::any_of(existing.begin(), existing.end(), same)) return;
    if (std::any_of(out.begin(), out.end(), same)) return;
    out.push_back(x);
  };
  // Ca* edges: bisect between the last sample above the threshold and the first below it (both sides).
  if (t.ca_star_low && t.ca_star_below && *t.ca_star_low - *t.ca_star_below > std::max(tol, per.ca_star_low))
    add(0.5 * (*t.ca_star_low + *t.ca_star_below));
  if (t.ca_star_high && t.ca_star_above && *t.ca_star_above - *t.ca_star_high > std::max(tol, per.ca_star_high))
    add(0.5 * (*t.ca_star_high + *t.ca_star_above));
  // No sample below the threshold yet: bracket the minimum of min D12 more finely around the best sample.
  if (!t.ca_star_low && t.ca_min_d12 && per.bracket_minimum && !is_sphere(t)) {
    auto it = std::find_if(samples.begin(), samples.end(), [&](const Sample& s) { return s.ca == *t.ca_min_d12; });
    if (it != samples.end()) {
      if (it != samples.begin() && it->ca - std::prev(it)->ca > tol) add(0.5 * (it->ca + std::prev(it)->ca));
      if (std::next(it) != samples.end() && std::next(it)->ca - it->ca > tol) add(0.5 * (it->ca + std::next(it)->ca));
    }
  }
  // CaH: false position clamped to the middle half of the bracket, so the bracket shrinks every round.
  if (t.ca_h && t.ca_h_low && t.ca_h_high && *t.ca_h_high - *t.ca_h_low > std::max(tol, per.ca_h)) {
    const double lo = *t.ca_h_low, hi = *t.ca_h_high, w = hi - lo;
    add(std::clamp(*t.ca_h, lo + 0.25 * w, hi - 0.25 * w));
  }
  return out;
}

std::vector<CaseParams> refinement_round(const std::vector<SampleGroup>& groups, double thr, double tol,
                                         int budget) {
  std::vector<CaseParams> add;
  for (const auto& g : groups) {
    const Transition t = analyse_group(g.key, g.samples, thr);
    for (double ca : propose_refinement(t, g.samples, tol, g.case_ca)) {
      if (budget <= 0) return add;
      CaseParams p = g.base;
      p.set("flow.capillary_number", ca);
      add.push_back(std::move(p));
      --budget;
    }
  }
  return add;
}

}  // namespace capsim::campaign
