#include "campaign/analysis/transitions.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <variant>

#include "campaign/analysis/group_key.h"
#include "campaign/analysis/refinement.h"
#include "campaign/grid/decimal.h"
#include "campaign/grid/precision.h"

namespace capsim::campaign {

namespace {

// "a" or "a to b": a range of sampled Ca as the notes print it.
std::string sampled_range(double a, double b) {
  return same_ca(a, b) ? format_sampled(a) : format_sampled(a) + " to " + format_sampled(b);
}

// Ca_TS of @p samples (sorted by Ca) into t.ca_ts_low, t.ca_ts_high and t.ca_ts_note (analyse_group's contract).
void regime_transition(const std::vector<Sample>& samples, Transition& t) {
  if (is_sphere(t)) return;  // a sphere does not tumble: no transition to read
  if (samples.empty()) {
    t.ca_ts_note = "no finished case";
    return;
  }
  const std::string_view tumbling = diagnostics::to_string(diagnostics::Regime::tumbling);
  const std::string_view swinging = diagnostics::to_string(diagnostics::Regime::swinging);
  std::vector<const Sample*> in_plane;  // tumbling or swinging, in Ca order
  std::vector<std::pair<std::string, std::string>> skipped;  // regime -> its Ca, in order of first appearance
  for (const auto& s : samples) {
    if (s.regime == tumbling || s.regime == swinging) {
      in_plane.push_back(&s);
      continue;
    }
    const std::string name = s.regime.empty() ? "no recorded regime" : s.regime;
    auto it = std::find_if(skipped.begin(), skipped.end(), [&](const auto& x) { return x.first == name; });
    if (it == skipped.end()) skipped.emplace_back(name, "Ca=" + format_sampled(s.ca));
    else it->second += ", " + format_sampled(s.ca);
  }
  std::vector<std::string> notes;
  const auto n = static_cast<int>(in_plane.size());
  int first_swinging = n, last_tumbling = -1;
  for (int i = 0; i < n; ++i) {
    if (in_plane[i]->regime == swinging && first_swinging == n) first_swinging = i;
    if (in_plane[i]->regime == tumbling) last_tumbling = i;
  }
  if (n == 0) {
    notes.push_back("no tumbling or swinging case");
  } else if (first_swinging == n) {
    notes.push_back("tumbles at every sampled Ca (" + sampled_range(in_plane.front()->ca, in_plane.back()->ca) + ")");
  } else if (last_tumbling < 0) {
    notes.push_back("swings from the smallest sampled Ca (" + format_sampled(in_plane.front()->ca) + ")");
  } else if (last_tumbling < first_swinging) {  // monotone: last_tumbling == first_swinging - 1
    t.ca_ts_low = in_plane[last_tumbling]->ca;
    t.ca_ts_high = in_plane[first_swinging]->ca;
  } else {
    std::string what = std::string(kRegimesNotMonotone) + ": tumbling at Ca=" +
                       format_sampled(in_plane[last_tumbling]->ca) + " above swinging at Ca=" +
                       format_sampled(in_plane[first_swinging]->ca);
    if (first_swinging > 0 && last_tumbling + 1 < n) {
      t.ca_ts_low = in_plane[first_swinging - 1]->ca;
      t.ca_ts_high = in_plane[last_tumbling + 1]->ca;
      what += "; the bracket is the outermost: every sample below it tumbles, every one above it swings";
    } else {
      what += first_swinging == 0 ? "; swinging at the smallest sampled Ca" : "; tumbling at the largest sampled Ca";
      what += ", so no bracket has tumbling below and swinging above";
    }
    notes.push_back(what);
  }
  for (const auto& [regime, cas] : skipped) notes.push_back("skipped " + regime + " at " + cas);
  for (const auto& x : notes) t.ca_ts_note += (t.ca_ts_note.empty() ? "" : "; ") + x;
}

}  // namespace

Transition analyse_group(Transition t, std::vector<Sample> samples, double thr) {
  std::sort(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.ca < b.ca; });
  t.d12_threshold = thr;
  t.n_samples = static_cast<int>(samples.size());
  t.ca_star_low = t.ca_star_high = t.ca_star_below = t.ca_star_above = t.ca_min_d12 = std::nullopt;
  t.ca_h = t.ca_h_low = t.ca_h_high = std::nullopt;
  t.ca_h_low_case.clear();
  t.ca_h_high_case.clear();
  t.ca_ts_low = t.ca_ts_high = std::nullopt;
  t.ca_ts_note.clear();
  std::vector<std::string> notes;

  // Ca*: the sampled Ca with min D12 < threshold (not for a sphere: is_sphere says why).
  std::vector<const Sample*> d12;
  for (const auto& s : samples)
    if (s.min_d12) d12.push_back(&s);
  const Sample* best = d12.empty() ? nullptr
                                   : *std::min_element(d12.begin(), d12.end(), [](const Sample* a, const Sample* b) {
                                       return *a->min_d12 < *b->min_d12;
                                     });
  if (best) t.ca_min_d12 = best->ca;
  if (best && is_sphere(t)) {
    notes.push_back("a/b = 1: a sphere does not tumble, Ca* does not apply (smallest min_D12 " +
                    format_significant(*best->min_d12) + " at Ca=" + format_sampled(best->ca) + ")");
  } else if (best) {
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
      notes.push_back("min_D12 never below " + format_sampled(thr) + " (smallest " +
                      format_significant(*best->min_d12) + " at Ca=" + format_sampled(best->ca) + ")");
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
    if (last_pos < 0 && is_sphere(t)) {
      // A sphere is compressed below a lower critical number CaL as well as above CaH (Lac et al. 2004;
      // results/bending/README.md §6), so compression at the smallest sample bounds no CaH: the tension window
      // [CaL, CaH] may lie between two samples, or be gone (the NH sphere with kappa_b = 1e-2).
      notes.push_back("max_tau_min < 0 at every sampled Ca (" + format_sampled(tau.front()->ca) + " to " +
                      format_sampled(tau.back()->ca) +
                      "): no tension window [CaL, CaH] sampled, and a sphere is compressed below CaL too, so no bound "
                      "on CaH");
    } else if (last_pos < 0) {
      notes.push_back("max_tau_min < 0 at every sampled Ca: CaH below " + format_sampled(tau.front()->ca));
      t.ca_h_high = tau.front()->ca;
      t.ca_h_high_case = tau.front()->case_id;
    } else if (last_pos + 1 == static_cast<int>(tau.size())) {
      notes.push_back("max_tau_min >= 0 at the largest sampled Ca: CaH above " + format_sampled(tau.back()->ca));
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
  // Ca_TS: its own note (ca_ts_note), so that `note` stays what the Ca* and CaH analysis says.
  regime_transition(samples, t);
  if (samples.empty()) notes.push_back("no finished case");
  t.note.clear();
  for (const auto& n : notes) t.note += (t.note.empty() ? "" : "; ") + n;
  return t;
}

bool is_sphere(const Transition& t) { return std::abs(t.aspect_ratio - 1.0) < 1e-9; }

std::vector<SampleGroup> group_cases(const std::vector<CaseSample>& cases) {
  std::map<std::string, std::size_t> index;
  std::vector<std::vector<int>> sample_rank;  // per group, aligned with its samples (preference, see below)
  std::vector<SampleGroup> out;
  for (const auto& c : cases) {
    const std::string key = GroupKey::of(c.params).str();
    auto [it, inserted] = index.try_emplace(key, out.size());
    if (inserted) {
      SampleGroup g;
      g.key.group_key = key;
      g.key.law = c.params.law();
      g.key.aspect_ratio = c.params.aspect_ratio();
      g.key.skalak_C = c.params.law() == "neo-hookean" ? -1.0 : c.params.skalak_C();
      g.key.mesh_level = c.params.mesh_level();
      g.base = c.params;
      out.push_back(std::move(g));
      sample_rank.emplace_back();
    }
    SampleGroup& g = out[it->second];
    const double ca = c.params.capillary_number();
    g.case_ca.push_back(ca);
    if (c.status != "done") continue;
    const auto& values = c.params.values();
    auto text = [&](const char* key, std::string_view unset) {
      const auto v = values.find(key);
      const std::string* t = v == values.end() ? nullptr : std::get_if<std::string>(&v->second);
      return t ? *t : std::string(unset);
    };
    const std::string stop_test = text("time.stop_test", diagnostics::kStopTestBoth);
    const Sample sample{ca, c.min_d12, c.max_tau_min, c.case_id, c.min_d12_spread, c.max_tau_min_spread,
                        c.dt, stop_test, c.regime};
    // One sample per Ca: where a Ca was run in both precisions, the double one (the reference); then the one
    // whose stop waited for both answers.
    const int rank =
        2 * (text("numerics.kernel_precision", "double") == "double") + (stop_test == diagnostics::kStopTestBoth);
    auto& ranks = sample_rank[it->second];
    const auto same = std::find_if(g.samples.begin(), g.samples.end(), [&](const Sample& s) { return same_ca(s.ca, ca); });
    if (same == g.samples.end()) {
      g.samples.push_back(sample);
      ranks.push_back(rank);
    } else if (const auto k = static_cast<std::size_t>(same - g.samples.begin()); rank > ranks[k]) {
      *same = sample;
      ranks[k] = rank;
    }
  }
  return out;
}

std::vector<Transition> analyse_groups(const std::vector<SampleGroup>& groups, double thr, const std::string& method) {
  std::vector<Transition> rows;
  for (const auto& g : groups) {
    Transition key = g.key;
    key.method = method;
    rows.push_back(analyse_group(key, g.samples, thr));
  }
  return rows;
}

std::string level_answers_json(const std::map<std::string, std::map<int, double>>& answers) {
  if (answers.empty()) return "";
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [answer, by_level] : answers)
    for (const auto& [level, x] : by_level) j[answer][std::to_string(level)] = x;
  return j.dump();
}

std::map<std::string, std::map<int, double>> level_answers_from_json(const std::string& text) {
  std::map<std::string, std::map<int, double>> out;
  if (text.empty()) return out;
  const auto j = nlohmann::json::parse(text, nullptr, false);
  if (!j.is_object()) return out;  // written by save_transitions only; a hand-edited row reads as none
  for (const auto& [answer, by_level] : j.items())
    if (by_level.is_object())
      for (const auto& [level, x] : by_level.items())
        if (x.is_number() && !level.empty() && level.find_first_not_of("0123456789") == std::string::npos)
          out[answer][std::stoi(level)] = x.get<double>();
  return out;
}

}  // namespace capsim::campaign
