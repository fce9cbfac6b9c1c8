#include "campaign/analysis/multi_fidelity.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "campaign/analysis/refinement.h"
#include "solver/diagnostics/period_analysis.h"

namespace capsim::campaign {

namespace {


// The group of the same cell as `like` at `level` with role `role`, or nullptr.
const SampleGroup* find_group(const std::vector<SampleGroup>& groups, const std::vector<std::string>& roles,
                              const SampleGroup& like, int level, const std::string& role, std::size_t* index = nullptr) {
  const std::string cell = cell_key(like.key.group_key);
  for (std::size_t i = 0; i < groups.size(); ++i)
    if (roles[i] == role && groups[i].key.mesh_level == level && cell_key(groups[i].key.group_key) == cell) {
      if (index) *index = i;
      return &groups[i];
    }
  return nullptr;
}

// Which answer a proposed case is for: what its periodic stop has to wait for with stop_for_answer (a bit
// set: a Ca that serves both answers waits for both).
enum Need : unsigned { kMinD12 = 1, kMaxTauMin = 2, kBoth = 3 };

// Collects new capillary numbers for one target group: positive, not among `existing`, not twice (a Ca
// proposed for both answers is proposed once, for both).
struct Proposals {
  const std::vector<double>& existing;
  std::vector<double> ca;
  std::vector<unsigned> need;  // aligned with ca
  void add(std::optional<double> x, unsigned for_answer) {
    if (!x || !(*x > 0)) return;
    auto same = [&](double y) { return same_ca(y, *x); };
    if (std::any_of(existing.begin(), existing.end(), same)) return;
    if (const auto it = std::find_if(ca.begin(), ca.end(), same); it != ca.end()) {
      need[static_cast<std::size_t>(it - ca.begin())] |= for_answer;
      return;
    }
    ca.push_back(*x);
    need.push_back(for_answer);
  }
};

// The stop test that waits for `need`, and back (time.stop_test; diagnostics names its values).
std::string_view stop_test_of(unsigned need) {
  return need == kMinD12 ? diagnostics::kStopTestMinD12
         : need == kMaxTauMin ? diagnostics::kStopTestMaxTauMin
                              : diagnostics::kStopTestBoth;
}
unsigned need_of(std::string_view stop_test) {
  return stop_test == diagnostics::kStopTestMinD12      ? kMinD12
         : stop_test == diagnostics::kStopTestMaxTauMin ? kMaxTauMin
                                                        : kBoth;
}

// time.stop_test of a new case for answer(s) `need` with stop_for_answer; without it the template's.
void set_stop_test(CaseParams& p, bool stop_for_answer, unsigned need) {
  if (!stop_for_answer) return;
  // The default ("both") is erased, not written: the identity of a case that never had the key.
  if (const std::string_view name = stop_test_of(need); name == diagnostics::kStopTestBoth)
    p.erase("time.stop_test");
  else
    p.set("time.stop_test", std::string(name));
}

// Appends the cases of `proposals` (template `base`, at `level`) within the budget; false once it is spent.
// `precision`: numerics.kernel_precision of the new cases ("": the base case's).
bool emit(const CaseParams& base, int level, const Proposals& proposals, const MultiFidelityOptions& o,
          std::vector<CaseParams>& out, int& budget, const std::string& precision = "") {
  for (std::size_t i = 0; i < proposals.ca.size(); ++i) {
    if (budget <= 0) return false;
    CaseParams p = base;
    p.set("mesh.level", std::int64_t{level});
    p.set("flow.capillary_number", proposals.ca[i]);
    if (!precision.empty()) p.set("numerics.kernel_precision", precision);
    set_stop_test(p, o.stop_for_answer, proposals.need[i]);
    out.push_back(std::move(p));
    --budget;
  }
  return true;
}

// The samples an answer rests on: both sides of each Ca* edge (min D12) and of the CaH bracket (max τmin).
void add_bracketing_ca(const Transition& t, Proposals& p) {
  for (const auto& x : {t.ca_star_below, t.ca_star_low, t.ca_star_high, t.ca_star_above}) p.add(x, kMinD12);
  for (const auto& x : {t.ca_h_low, t.ca_h_high}) p.add(x, kMaxTauMin);
}

// What a refinement proposal @p x of a group with transition @p t and samples @p samples is for: every answer
// whose bracket it falls in — a Ca* edge's, or without a band the neighbourhood of the smallest min D12 (min
// D12), the CaH bracket (max τmin), both where they overlap (or, defensively, neither). By where x lies, not
// by which bisection proposed it: once run, x is a sample of every bracket it lies in, whichever answer asked.
unsigned need_inside(const Transition& t, const std::vector<Sample>& samples, double x) {
  auto inside = [x](const std::optional<double>& a, const std::optional<double>& b) {
    return a && b && x > std::min(*a, *b) && x < std::max(*a, *b);
  };
  unsigned need = 0;
  if (inside(t.ca_star_below, t.ca_star_low) || inside(t.ca_star_high, t.ca_star_above)) need |= kMinD12;
  if (!t.ca_star_low && t.ca_min_d12) {
    std::optional<double> left, right;  // the samples next to the minimum
    for (const auto& s : samples) {
      if (s.ca < *t.ca_min_d12 && (!left || s.ca > *left)) left = s.ca;
      if (s.ca > *t.ca_min_d12 && (!right || s.ca < *right)) right = s.ca;
    }
    if (inside(left, t.ca_min_d12) || inside(t.ca_min_d12, right)) need |= kMinD12;
  }
  if (inside(t.ca_h_low, t.ca_h_high)) need |= kMaxTauMin;
  return need ? need : kBoth;
}

// Whether a group's smallest min D12 lies near enough the threshold (< 3×) that a band may hide between its
// samples: the rule of the answer level's bracketing of the minimum and of the scan's seeding of it.
bool minimum_near_threshold(double min_d12, double threshold) { return min_d12 < 3 * threshold; }

// The smallest sampled Ca when max τmin < 0 at every sample that has it (nullopt otherwise, or with none).
// analyse_group turns that into a CaH bound for a spheroid only (a sphere is compressed below a CaL as well),
// so the rounds read the samples themselves and treat both shapes alike.
std::optional<double> smallest_if_all_compressed(const std::vector<Sample>& samples) {
  std::optional<double> smallest;
  for (const auto& s : samples)
    if (s.max_tau_min) {
      if (*s.max_tau_min >= 0) return std::nullopt;
      if (!smallest || s.ca < *smallest) smallest = s.ca;
    }
  return smallest;
}

// Whether the cell of `answer` has a dt check case on its level (any Ca, any status): phase 5 has run there.
bool has_dt_check(const std::vector<SampleGroup>& groups, const std::vector<std::string>& roles,
                  const SampleGroup& answer) {
  const std::string cell = cell_key(answer.key.group_key);
  for (std::size_t j = 0; j < groups.size(); ++j)
    if (roles[j] == "dt_check" && groups[j].key.mesh_level == answer.key.mesh_level && !groups[j].case_ca.empty() &&
        cell_key(groups[j].key.group_key) == cell)
      return true;
  return false;
}

// The answer-level sample phase 5 re-runs with dt/2: the CaH-low case, else the Ca*-low case (nullptr: neither,
// or it has no recorded step).
const Sample* dt_check_sample(const Transition& t, const SampleGroup& answer) {
  const std::optional<double> ca = t.ca_h_low ? t.ca_h_low : t.ca_star_low;
  if (!ca) return nullptr;
  for (const auto& s : answer.samples)
    if (same_ca(s.ca, *ca) && s.dt) return &s;
  return nullptr;
}

std::vector<double> sampled_ca(const SampleGroup& g) {
  std::vector<double> ca;
  for (const auto& s : g.samples) ca.push_back(s.ca);
  std::sort(ca.begin(), ca.end());
  return ca;
}

}  // namespace

std::vector<CaseParams> answer_level_round(const std::vector<SampleGroup>& groups, const MultiFidelityOptions& o,
                                           int budget) {
  std::vector<CaseParams> out;
  if (o.levels.size() < 2) return out;
  const auto roles = group_roles(groups, ErrorOptions{o.levels});
  const int scan_level = o.levels[0], answer_level = o.levels[1];
  static const std::vector<double> kNone;
  for (std::size_t i = 0; i < groups.size(); ++i) {
    if (roles[i] != "scan" || groups[i].key.mesh_level != scan_level) continue;
    const SampleGroup& scan = groups[i];
    std::size_t ia = 0;
    const SampleGroup* answer = find_group(groups, roles, scan, answer_level, "answer", &ia);
    Proposals p{answer ? answer->case_ca : kNone, {}, {}};

    // Seed: the scan's brackets.
    const Transition ts = analyse_group(scan.key, scan.samples, o.d12_threshold);
    add_bracketing_ca(ts, p);
    p.add(smallest_if_all_compressed(scan.samples), kMaxTauMin);  // a spheroid's ca_h_high; a sphere has none
    if (!ts.ca_star_low && ts.ca_min_d12) {
      p.add(ts.ca_min_d12, kMinD12);
      // No band on the scan level, but a minimum near the threshold (< 3×, as the refinement's bracketing):
      // the band can lie between the minimum's scan neighbours (the oblate capsule with κ_b = 1e-3: 0.072 at
      // Ca 0.08 and 0.074 at 0.1 on level 2, a band ≈ 0.01 wide between them), so they seed the answer level
      // too instead of being reached by bisection from the far side.
      const std::vector<double> ca = sampled_ca(scan);
      const auto it = std::find_if(ca.begin(), ca.end(), [&](double c) { return same_ca(c, *ts.ca_min_d12); });
      double best = 1e300;
      for (const auto& s : scan.samples)
        if (s.min_d12 && same_ca(s.ca, *ts.ca_min_d12)) best = *s.min_d12;
      if (it != ca.end() && minimum_near_threshold(best, o.d12_threshold) && !is_sphere(ts)) {
        if (it != ca.begin()) p.add(*std::prev(it), kMinD12);
        if (std::next(it) != ca.end()) p.add(*std::next(it), kMinD12);
      }
    }

    if (answer && !answer->samples.empty()) {
      const Transition ta = analyse_group(answer->key, answer->samples, o.d12_threshold);
      // Re-bracket: the next scan Ca outwards (beyond the scan's range ×1.5 / ÷1.5, CaH only: Ca* edges at the
      // end of the scan's range stay there, as the grid's author chose the range).
      const std::vector<double> scan_ca = sampled_ca(scan);
      auto above = [&](double x, bool beyond) -> std::optional<double> {
        for (double c : scan_ca)
          if (c > x && !same_ca(c, x)) return c;
        return beyond ? std::optional<double>(quantise_ca(1.5 * x, o.ca_tolerance)) : std::nullopt;
      };
      auto below = [&](double x, bool beyond) -> std::optional<double> {
        for (auto it = scan_ca.rbegin(); it != scan_ca.rend(); ++it)
          if (*it < x && !same_ca(*it, x)) return *it;
        return beyond ? std::optional<double>(quantise_ca(x / 1.5, o.ca_tolerance)) : std::nullopt;
      };
      if (ta.ca_h_low && !ta.ca_h_high) p.add(above(*ta.ca_h_low, true), kMaxTauMin);
      if (const auto smallest_compressed = smallest_if_all_compressed(answer->samples)) {
        // max τmin < 0 at every answer-level sample is ambiguous: a membrane is compressed both above CaH
        // and below a lower critical number CaL (Lac et al. 2004; the NH sphere on level 3: τ < 0 at 0.4,
        // > 0 at 0.5, < 0 again above 0.62). So probe both ways: below the smallest sample, and the next
        // scan Ca above the largest one (within the scan's range: the grid's author chose it).
        // Below the scan's range by one step (÷1.5) at most: as Ca -> 0 the tensions vanish with Ca, so max
        // τmin may tend to 0 from below with no window of τ > 0 at all (the NH sphere with κ_b = 1e-2:
        // −0.022 at Ca 0.01, −0.14 at 0.12, −0.02 at 0.6; walking down by ÷1.5 spent 12 cases finding
        // nothing). Past that step the answer is "max τmin < 0 at every sampled Ca".
        const double smallest = *smallest_compressed;
        if (!scan_ca.empty() && (smallest > scan_ca.front() || same_ca(smallest, scan_ca.front())))
          p.add(below(smallest, true), kMaxTauMin);  // the next scan Ca below, or one step below the scan's range
        double largest = smallest;
        for (const auto& s : answer->samples)
          if (s.max_tau_min) largest = std::max(largest, s.ca);
        p.add(above(largest, false), kMaxTauMin);
      }
      if (ta.ca_star_low && !ta.ca_star_below) p.add(below(*ta.ca_star_low, false), kMinD12);
      if (ta.ca_star_high && !ta.ca_star_above) p.add(above(*ta.ca_star_high, false), kMinD12);
      // Refine: bisect, each bracket down to max(ca_tolerance, its numerical error) — with dt_check, once the
      // cell's dt check exists (where phase 5 has a case to re-run), so that the error has its dt part.
      const bool dt_pending = o.dt_check && !has_dt_check(groups, roles, *answer) && dt_check_sample(ta, *answer);
      if (o.adaptive && !dt_pending) {
        const GroupErrors e = answer_errors(ta, groups, roles, ia);
        // The minimum of min D12 is searched only near the threshold (< 3×): a sphere's 0.45 has no band to find.
        double best = 1e300;
        for (const auto& s : answer->samples)
          if (s.min_d12) best = std::min(best, *s.min_d12);
        const BracketTolerances tol{e.ca_star_low.numerical.value_or(0), e.ca_star_high.numerical.value_or(0),
                                    e.ca_h.numerical.value_or(0), minimum_near_threshold(best, o.d12_threshold)};
        for (double x : propose_refinement(ta, answer->samples, o.ca_tolerance, tol, answer->case_ca))
          p.add(x, need_inside(ta, answer->samples, x));
      }
    }
    if (!emit(answer ? answer->base : scan.base, answer_level, p, o, out, budget)) break;
  }
  return out;
}

int bisections_saved(const Transition& t, double ca_tolerance) {
  auto saved = [&](const std::optional<double>& a, const std::optional<double>& b) {
    if (!a || !b || !(ca_tolerance > 0)) return 0;
    const double width = std::abs(*b - *a);
    return width > ca_tolerance ? static_cast<int>(std::ceil(std::log2(width / ca_tolerance) - 1e-12)) : 0;
  };
  return saved(t.ca_star_below, t.ca_star_low) + saved(t.ca_star_high, t.ca_star_above) +
         saved(t.ca_h_low, t.ca_h_high);
}

std::vector<CaseParams> check_level_cases(const std::vector<SampleGroup>& groups, const MultiFidelityOptions& o,
                                          int budget) {
  std::vector<CaseParams> out;
  if (o.levels.size() < 3) return out;
  const auto roles = group_roles(groups, ErrorOptions{o.levels});
  static const std::vector<double> kNone;
  for (std::size_t i = 0; i < groups.size(); ++i) {
    if (roles[i] != "answer" || groups[i].key.mesh_level != o.levels[1]) continue;
    const SampleGroup& answer = groups[i];
    const SampleGroup* check = find_group(groups, roles, answer, o.levels[2], "mesh_check");
    Proposals p{check ? check->case_ca : kNone, {}, {}};
    const Transition t = analyse_group(answer.key, answer.samples, o.d12_threshold);
    add_bracketing_ca(t, p);
    if (check) {
      // Where the check level's values at a bracket lie on one side of the target (its answer is outside the
      // bracket), the answer level's next sample outwards, one at a time, until the check level brackets it
      // on its own (check_level_crossing); nothing while the check level's last such case is still to run.
      const std::vector<double> answer_ca = sampled_ca(answer);
      auto outwards = [&](bool of_ca_h, const std::optional<double>& a, const std::optional<double>& b) {
        if (!a || !b) return;
        const LevelCrossing c = check_level_crossing(*check, answer_ca, of_ca_h, *a, *b, o.d12_threshold);
        if (!c.extrapolated || !c.ca) return;
        // The first answer-level sample outwards at which the check level has no value yet.
        const bool up = *c.ca > std::max(*a, *b);
        const double edge = up ? std::max(*a, *b) : std::min(*a, *b);
        std::vector<double> beyond;
        for (double x : answer_ca)
          if (up ? x > edge && !same_ca(x, edge) : x < edge && !same_ca(x, edge)) beyond.push_back(x);
        if (!up) std::reverse(beyond.begin(), beyond.end());  // outwards (answer_ca is sorted)
        for (double x : beyond) {
          const auto same = [&](double y) { return same_ca(x, y); };
          bool valued = false;
          for (const auto& s : check->samples) valued |= same_ca(s.ca, x) && (of_ca_h ? s.max_tau_min : s.min_d12);
          if (valued) continue;
          // The next one to run; a check case there without a value yet (queued, running): wait for it.
          if (std::none_of(check->case_ca.begin(), check->case_ca.end(), same)) p.add(x, of_ca_h ? kMaxTauMin : kMinD12);
          return;
        }
      };
      outwards(true, t.ca_h_low, t.ca_h_high);
      outwards(false, t.ca_star_below, t.ca_star_low);
      outwards(false, t.ca_star_high, t.ca_star_above);
    }
    if (!emit(answer.base, o.levels[2], p, o, out, budget, o.check_precision)) break;
  }
  return out;
}

bool rounds_may_overlap(const MultiFidelityOptions& o, const std::vector<int>& unfinished_levels) {
  if (o.levels.size() < 3) return false;
  return std::all_of(unfinished_levels.begin(), unfinished_levels.end(),
                     [&](int level) { return level == o.levels[2]; });
}

std::vector<CaseParams> dt_check_cases(const std::vector<SampleGroup>& groups, const MultiFidelityOptions& o,
                                       int budget) {
  std::vector<CaseParams> out;
  if (o.levels.size() < 2) return out;
  const auto roles = group_roles(groups, ErrorOptions{o.levels});
  for (std::size_t i = 0; i < groups.size() && budget > 0; ++i) {
    if (roles[i] != "answer" || groups[i].key.mesh_level != o.levels[1]) continue;
    const SampleGroup& answer = groups[i];
    const Sample* c = dt_check_sample(analyse_group(answer.key, answer.samples, o.d12_threshold), answer);
    if (!c || has_dt_check(groups, roles, answer)) continue;
    CaseParams p = answer.base;
    p.set("flow.capillary_number", c->ca);
    p.set("time.dt", 0.5 * *c->dt);
    // The same stop as the case it halves the step of: the pair then differs by the step, not by what it waited for.
    set_stop_test(p, o.stop_for_answer, need_of(c->stop_test));
    out.push_back(std::move(p));
    --budget;
  }
  return out;
}

}  // namespace capsim::campaign
