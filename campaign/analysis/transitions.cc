#include "campaign/analysis/transitions.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "campaign/grid/decimal.h"

namespace capsim::campaign {

Transition analyse_group(Transition t, std::vector<Sample> samples, double thr) {
  std::sort(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.ca < b.ca; });
  t.d12_threshold = thr;
  t.n_samples = static_cast<int>(samples.size());
  t.ca_star_low = t.ca_star_high = t.ca_star_below = t.ca_star_above = t.ca_min_d12 = std::nullopt;
  t.ca_h = t.ca_h_low = t.ca_h_high = std::nullopt;
  t.ca_h_low_case.clear();
  t.ca_h_high_case.clear();
  std::vector<std::string> notes;

  // Ca*: the sampled Ca with min D12 < threshold.
  std::vector<const Sample*> d12;
  for (const auto& s : samples)
    if (s.min_d12) d12.push_back(&s);
  if (!d12.empty()) {
    const Sample* best = *std::min_element(d12.begin(), d12.end(),
                                           [](const Sample* a, const Sample* b) { return *a->min_d12 < *b->min_d12; });
    t.ca_min_d12 = best->ca;
    int first = -1, last = -1;
    for (int i = 0; i < static_cast<int>(d12.size()); ++i)
      if (*d12[i]->min_d12 < thr) {
        if (first < 0) first = i;
        last = i;
      }
    if (first >= 0) {
      t.ca_star_low = d12[first]->ca;
      t.ca_star_high = d12[last]->ca;
      if (first > 0) t.ca_star_below = d12[first - 1]->ca;
      if (last + 1 < static_cast<int>(d12.size())) t.ca_star_above = d12[last + 1]->ca;
      for (int i = first; i <= last; ++i)
        if (*d12[i]->min_d12 >= thr) {
          notes.push_back("Ca* samples not contiguous");
          break;
        }
      if (first == 0) notes.push_back("Ca* interval starts at the smallest sampled Ca");
      if (last + 1 == static_cast<int>(d12.size())) notes.push_back("Ca* interval ends at the largest sampled Ca");
    } else {
      notes.push_back("min_D12 never below " + canonical_double(thr) + " (smallest " +
                      canonical_double(*best->min_d12) + " at Ca=" + canonical_double(best->ca) + ")");
    }
  }

  // CaH: above the last sample with max tau_min >= 0, every sample has max tau_min < 0.
  std::vector<const Sample*> tau;
  for (const auto& s : samples)
    if (s.max_tau_min) tau.push_back(&s);
  if (!tau.empty()) {
    int last_pos = -1;
    for (int i = 0; i < static_cast<int>(tau.size()); ++i)
      if (*tau[i]->max_tau_min >= 0) last_pos = i;
    if (last_pos < 0) {
      notes.push_back("max_tau_min < 0 at every sampled Ca: CaH below " + canonical_double(tau.front()->ca));
      t.ca_h_high = tau.front()->ca;
      t.ca_h_high_case = tau.front()->case_id;
    } else if (last_pos + 1 == static_cast<int>(tau.size())) {
      notes.push_back("max_tau_min >= 0 at the largest sampled Ca: CaH above " + canonical_double(tau.back()->ca));
      t.ca_h_low = tau.back()->ca;
      t.ca_h_low_case = tau.back()->case_id;
    } else {
      const Sample& a = *tau[last_pos];
      const Sample& b = *tau[last_pos + 1];
      const double ya = *a.max_tau_min, yb = *b.max_tau_min;
      t.ca_h_low = a.ca;
      t.ca_h_high = b.ca;
      t.ca_h_low_case = a.case_id;
      t.ca_h_high_case = b.case_id;
      t.ca_h = ya == yb ? a.ca : a.ca + (b.ca - a.ca) * ya / (ya - yb);
    }
  }
  if (samples.empty()) notes.push_back("no finished case");
  t.note.clear();
  for (const auto& n : notes) t.note += (t.note.empty() ? "" : "; ") + n;
  return t;
}

namespace {
double quantise(double x, double tolerance) {
  // Round to a decimal quantum 10^-scale below tolerance/2, exactly (0.0275, not 0.027500000000000004).
  const int scale = std::max(0, static_cast<int>(-std::floor(std::log10(tolerance / 2))));
  return Decimal{static_cast<std::int64_t>(std::llround(x * std::pow(10.0, scale))), scale}.to_double();
}
}  // namespace

std::vector<double> propose_refinement(const Transition& t, std::vector<Sample> samples, double tol) {
  std::sort(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.ca < b.ca; });
  std::vector<double> out;
  auto add = [&](double x) {
    x = quantise(x, tol);
    if (!(x > 0)) return;
    for (const auto& s : samples)
      if (std::fabs(s.ca - x) < 1e-12 * std::max(1.0, x)) return;
    for (double y : out)
      if (std::fabs(y - x) < 1e-12 * std::max(1.0, x)) return;
    out.push_back(x);
  };
  // Ca* edges: bisect between the last sample above the threshold and the first below it (both sides).
  if (t.ca_star_low && t.ca_star_below && *t.ca_star_low - *t.ca_star_below > tol)
    add(0.5 * (*t.ca_star_low + *t.ca_star_below));
  if (t.ca_star_high && t.ca_star_above && *t.ca_star_above - *t.ca_star_high > tol)
    add(0.5 * (*t.ca_star_high + *t.ca_star_above));
  // No sample below the threshold yet: bracket the minimum of min D12 more finely around the best sample.
  if (!t.ca_star_low && t.ca_min_d12) {
    auto it = std::find_if(samples.begin(), samples.end(), [&](const Sample& s) { return s.ca == *t.ca_min_d12; });
    if (it != samples.end()) {
      if (it != samples.begin() && it->ca - std::prev(it)->ca > tol) add(0.5 * (it->ca + std::prev(it)->ca));
      if (std::next(it) != samples.end() && std::next(it)->ca - it->ca > tol) add(0.5 * (it->ca + std::next(it)->ca));
    }
  }
  // CaH: false position clamped to the middle half of the bracket, so the bracket shrinks every round.
  if (t.ca_h && t.ca_h_low && t.ca_h_high && *t.ca_h_high - *t.ca_h_low > tol) {
    const double lo = *t.ca_h_low, hi = *t.ca_h_high, w = hi - lo;
    add(std::clamp(*t.ca_h, lo + 0.25 * w, hi - 0.25 * w));
  }
  return out;
}

std::vector<SampleGroup> load_groups(Db& db, std::int64_t campaign_id) {
  Stmt s(db,
         "SELECT c.law, c.aspect_ratio, coalesce(c.skalak_C,-1), c.mesh_level, c.capillary_number, c.case_id, "
         "r.min_D12, r.max_tau_min, c.status "
         "FROM cases c JOIN campaign_cases cc ON cc.case_id=c.case_id LEFT JOIN results r ON r.case_id=c.case_id "
         "WHERE cc.campaign_id=? ORDER BY c.law, c.aspect_ratio, 3, c.mesh_level, c.capillary_number");
  s.bind(1, campaign_id);
  std::map<std::tuple<std::string, double, double, int>, SampleGroup> groups;
  std::vector<std::tuple<std::string, double, double, int>> order;
  while (s.step()) {
    auto key = std::make_tuple(s.text(0), *s.real(1), *s.real(2), static_cast<int>(s.integer(3)));
    auto [it, inserted] = groups.try_emplace(key);
    if (inserted) {
      order.push_back(key);
      it->second.key.law = s.text(0);
      it->second.key.aspect_ratio = *s.real(1);
      it->second.key.skalak_C = *s.real(2);
      it->second.key.mesh_level = static_cast<int>(s.integer(3));
      it->second.some_case_id = s.text(5);
    }
    if (s.text(8) == "done") it->second.samples.push_back({*s.real(4), s.real(6), s.real(7), s.text(5)});
  }
  std::vector<SampleGroup> out;
  for (const auto& k : order) out.push_back(std::move(groups[k]));
  return out;
}

std::vector<Transition> analyse_campaign(Store& store, std::int64_t campaign_id, double thr,
                                         const std::string& method) {
  std::vector<Transition> rows;
  for (auto& g : load_groups(store.db(), campaign_id)) {
    Transition key = g.key;
    key.method = method;
    rows.push_back(analyse_group(key, g.samples, thr));
  }
  store.save_transitions(campaign_id, rows);
  return rows;
}

}  // namespace capsim::campaign
