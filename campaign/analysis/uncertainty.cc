#include "campaign/analysis/uncertainty.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "campaign/analysis/refinement.h"
#include "campaign/grid/precision.h"

namespace capsim::campaign {

namespace {

// The two quantities the answers are made of.
enum class Quantity { kMinD12, kMaxTauMin };

std::optional<double> value(const Sample& s, Quantity q) { return q == Quantity::kMinD12 ? s.min_d12 : s.max_tau_min; }
std::optional<double> spread(const Sample& s, Quantity q) {
  return q == Quantity::kMinD12 ? s.min_d12_spread : s.max_tau_min_spread;
}
const char* name_of(Quantity q) { return q == Quantity::kMinD12 ? "min D12" : "max τmin"; }


// The samples of a group that have q, sorted by Ca.
std::vector<const Sample*> with_value(const SampleGroup& g, Quantity q) {
  std::vector<const Sample*> out;
  for (const auto& s : g.samples)
    if (value(s, q)) out.push_back(&s);
  std::sort(out.begin(), out.end(), [](const Sample* a, const Sample* b) { return a->ca < b->ca; });
  return out;
}

std::string group_dt(const std::string& group_key) {
  const auto k = GroupKey::parse(group_key);
  return k ? k->dt() : "auto";
}

std::string num(double x) { return format_significant(x, 2); }

// One part of the error of q at a case, in units of q, with how it was obtained.
struct Part {
  std::optional<double> e;
  std::string how;
  std::map<int, double> on_level;  // mesh part: the answer on the other levels it compared (level -> Ca)
};

// The cell of group `self`: the other groups by level (non dt_check) and the dt_check groups at its level.
struct Cell {
  std::map<int, const SampleGroup*> by_level;
  std::vector<const SampleGroup*> dt_checks;
};

Cell cell_of(const std::vector<SampleGroup>& groups, const std::vector<std::string>& roles, std::size_t self) {
  Cell c;
  const std::string key = cell_key(groups[self].key.group_key);
  for (std::size_t i = 0; i < groups.size(); ++i) {
    if (cell_key(groups[i].key.group_key) != key) continue;
    if (roles[i] == "dt_check") {
      if (groups[i].key.mesh_level == groups[self].key.mesh_level) c.dt_checks.push_back(&groups[i]);
    } else if (i == self || !c.by_level.count(groups[i].key.mesh_level)) {
      c.by_level[groups[i].key.mesh_level] = &groups[i];
    }
  }
  c.by_level[groups[self].key.mesh_level] = &groups[self];
  return c;
}

// Which answer a mesh comparison is about.
enum class Answer { kCaH, kCaStarLow, kCaStarHigh };

// Where the line through (a, ya), (b, yb) crosses `target` (nullopt when flat).
std::optional<double> crossing(double a, double ya, double b, double yb, double target) {
  if (ya == yb || !std::isfinite(ya) || !std::isfinite(yb)) return std::nullopt;
  return a + (b - a) * (target - ya) / (yb - ya);
}

// The answer of another level g2 near the bracket (a, b) of the answer level: the crossing of the line
// through g2's values at a and b when g2 has both (a check level run at the brackets; for a level finer than
// the answer group `finer_than`, check_level_crossing: its own bracket beyond them at the answer level's
// samples where they do not straddle), else g2's own answer from
// its own bracket (a coarser scan level sampled elsewhere; mesh_part does not ask a finer level that lacks a or b). `extrapolated`: a line through g2's values at a and b
// that does not straddle the target.
LevelCrossing level_answer(const SampleGroup& g2, Answer which, double a, double b, double thr,
                           const SampleGroup* finer_than) {
  const Quantity q = which == Answer::kCaH ? Quantity::kMaxTauMin : Quantity::kMinD12;
  const double target = which == Answer::kCaH ? 0.0 : thr;
  std::optional<double> ya, yb;
  for (const auto& s : g2.samples) {
    if (same_ca(s.ca, a)) ya = value(s, q);
    if (same_ca(s.ca, b)) yb = value(s, q);
  }
  if (ya && yb) {
    if (finer_than) {
      std::vector<double> answer_ca;
      for (const auto& s : finer_than->samples) answer_ca.push_back(s.ca);
      return check_level_crossing(g2, answer_ca, which == Answer::kCaH, a, b, thr);
    }
    return {crossing(a, *ya, b, *yb, target), (*ya - target) * (*yb - target) > 0};
  }
  const Transition t2 = analyse_group(g2.key, g2.samples, thr);
  if (which == Answer::kCaH) return {t2.ca_h, false};
  const auto& in = which == Answer::kCaStarLow ? t2.ca_star_low : t2.ca_star_high;
  const auto& out = which == Answer::kCaStarLow ? t2.ca_star_below : t2.ca_star_above;
  if (!in || !out) return {};
  std::optional<double> y_in, y_out;
  for (const auto& s : g2.samples) {
    if (same_ca(s.ca, *in)) y_in = s.min_d12;
    if (same_ca(s.ca, *out)) y_out = s.min_d12;
  }
  if (!y_in || !y_out) return {};
  return {crossing(*in, *y_in, *out, *y_out, thr), false};
}

// Whether g has a value of q at Ca c (a finished case there that recorded it).
bool has_value_at(const SampleGroup& g, Quantity q, double c) {
  for (const auto& s : g.samples)
    if (same_ca(s.ca, c) && value(s, q)) return true;
  return false;
}

// The largest |q_L2(c) − q_L(c)| over the bracket Ca c ∈ {a, b}: q_L2(c) taken at c where g2 has a sample
// there (a check level run at the brackets), else interpolated linearly between g2's nearest samples on either
// side of c (a level sampled elsewhere); nullopt where g2's samples do not span c.
std::optional<double> value_difference(const SampleGroup& g2, const SampleGroup& g, Quantity q, double a,
                                                    double b) {
  std::optional<double> out;
  const auto coarse = with_value(g2, q);
  for (const auto& s : g.samples) {
    if (!(same_ca(s.ca, a) || same_ca(s.ca, b)) || !value(s, q)) continue;
    const Sample *below = nullptr, *above = nullptr;
    for (const Sample* c : coarse) {
      if (c->ca <= s.ca || same_ca(c->ca, s.ca)) {
        if (!below || c->ca > below->ca) below = c;
      }
      if (c->ca >= s.ca || same_ca(c->ca, s.ca)) {
        if (!above || c->ca < above->ca) above = c;
      }
    }
    if (!below || !above) continue;
    double y2 = *value(*below, q);
    if (!same_ca(below->ca, s.ca) && !same_ca(above->ca, below->ca))
      y2 += (*value(*above, q) - y2) * (s.ca - below->ca) / (above->ca - below->ca);
    const double d = std::fabs(y2 - *value(s, q));
    if (!out || d > *out) out = d;
  }
  return out;
}

// The mesh part of an answer, directly in Ca: the answer level's own value `here` against the neighbouring
// levels' answers (Richardson with three monotone levels, else the last difference). A neighbour whose line
// through the bracket samples crosses the target more than a bracket width outside the bracket [a, b] (its
// values do not straddle the target and the line is nearly flat: an oblate capsule whose coarse level has no
// band there) says nothing about where level L's crossing is; it is compared as values instead: the largest
// |Δq| at the bracket samples over |slope| (slope of q on level L), as the periods and dt parts are. Where no
// neighbour gives anything else, one with no answer there at all (a coarse scan level whose max τmin keeps one
// sign over its grid while level L has a CaH: the NH prolate capsule at κ_b = 1e-2) is compared as values too,
// its q interpolated at the bracket Ca: without it the error would lack its mesh part and bisection would
// refine the bracket far below what the levels' disagreement allows (results/bending/README.md §8).
Part mesh_part(const Cell& cell, int level, Answer which, double a, double b, double here, double thr, double slope,
               std::set<int>& levels_used) {
  const Quantity q = which == Answer::kCaH ? Quantity::kMaxTauMin : Quantity::kMinD12;
  const double lo = std::min(a, b), hi = std::max(a, b), width = hi - lo;
  auto far = [&](double x) { return x < lo - width || x > hi + width; };
  std::optional<double> coarse, fine, far_e, values_e;  // values_e: a neighbour with no answer, as values
  std::string far_how, values_how;
  int values_level = 0;
  std::set<int> far_level;
  auto take = [&](int l, std::optional<double>& out) {
    auto it = cell.by_level.find(l);
    if (it == cell.by_level.end()) return;
    // A finer (check) level is run at the answer level's brackets. Until it has values at both, what it says
    // here is pending: its own bracket elsewhere (an oblate cell's level 4 at Ca 0.02 and 0.5, a line across 0.48
    // in Ca) or its values interpolated across such a gap are not an answer of that level near this one.
    if (l > level && !(has_value_at(*it->second, q, a) && has_value_at(*it->second, q, b))) return;
    const LevelCrossing c = level_answer(*it->second, which, a, b, thr, l > level ? cell.by_level.at(level) : nullptr);
    out = c.ca;
    if (!out) {
      const auto d = value_difference(*it->second, *cell.by_level.at(level), q, a, b);
      if (!d || !(std::fabs(slope) > 0) || !std::isfinite(slope)) return;
      const double e = *d / std::fabs(slope);
      if (!values_e || e > *values_e) {
        values_e = e;
        values_level = l;
        values_how = "level " + std::to_string(l) + " has no " + (which == Answer::kCaH ? "CaH" : "band edge") +
                     " here: its " + name_of(q) + ", interpolated at the bracket samples, differs by " + num(*d) +
                     ", over |slope| " + num(std::fabs(slope));
      }
      return;
    }
    // Only a crossing extrapolated from that level's own samples at a and b can be "far" (its own answer
    // from its own bracket, elsewhere or beyond, is a real mesh difference, however large).
    if (!out || !c.extrapolated || !far(*out)) return;
    far_level.insert(l);
    const auto d = value_difference(*it->second, *cell.by_level.at(level), q, a, b);
    if (d && std::fabs(slope) > 0 && std::isfinite(slope)) {
      const double e = *d / std::fabs(slope);
      if (!far_e || e > *far_e) {
        far_e = e;
        far_how = "level " + std::to_string(l) + " crosses far outside the bracket (at " + format_significant(*out, 4) +
                  "): " + name_of(q) + " differs by " + num(*d) + " at the bracket samples, over |slope| " +
                  num(std::fabs(slope));
      }
    }
    levels_used.insert(l);
    // kept in on_level (what that level says), left out of the comparison in Ca below
  };
  take(level - 1, coarse);
  take(level + 1, fine);
  Part p;
  if (coarse) p.on_level[level - 1] = *coarse;
  if (fine) p.on_level[level + 1] = *fine;
  if (coarse && far_level.count(level - 1)) coarse.reset();
  if (fine && far_level.count(level + 1)) fine.reset();
  if (coarse) levels_used.insert(level - 1);
  if (fine) levels_used.insert(level + 1);
  auto text = [](int l, double x) { return "level " + std::to_string(l) + ": " + format_significant(x, 4); };
  if (coarse && fine) {
    const double d1 = here - *coarse, d2 = *fine - here;
    if (d1 != 0 && d2 * d1 > 0 && std::fabs(d2) < std::fabs(d1)) {
      const double r = d2 / d1;
      p.e = std::fabs(d2) / (1 - r);
      p.how = "Richardson over levels " + std::to_string(level - 1) + "–" + std::to_string(level + 1) + " (" +
              text(level - 1, *coarse) + ", " + text(level + 1, *fine) + ", observed order " + num(std::log2(1 / r)) +
              ")";
      return p;
    }
  }
  if (fine) {
    p.e = std::fabs(*fine - here);
    p.how = "difference to level " + std::to_string(level + 1) + " (" + text(level + 1, *fine) + ")";
  } else if (coarse) {
    p.e = std::fabs(here - *coarse);
    p.how = "difference to level " + std::to_string(level - 1) + " (" + text(level - 1, *coarse) + ")";
  }
  if (far_e && (!p.e || *far_e > *p.e)) {
    p.e = far_e;
    p.how = far_how;
  }
  // Only where nothing else gives the mesh part: a finer level's answer is the better estimate.
  if (!p.e && values_e) {
    p.e = values_e;
    p.how = values_how;
    levels_used.insert(values_level);
  }
  return p;
}

// The dt part of the cell: the largest |q(r dt) − q(dt)| / (1 − r²) over the dt_check cases at this level.
Part dt_part(const Cell& cell, const SampleGroup& base, Quantity q) {
  Part p;
  for (const SampleGroup* g : cell.dt_checks)
    for (const auto& s : g->samples) {
      if (!value(s, q) || !s.dt) continue;
      for (const auto& b : base.samples) {
        if (!same_ca(b.ca, s.ca) || !value(b, q) || !b.dt || !(*s.dt < *b.dt)) continue;
        const double r = *s.dt / *b.dt;
        const double e = std::fabs(*value(s, q) - *value(b, q)) / (1 - r * r);
        if (!p.e || e > *p.e) {
          p.e = e;
          p.how = "dt " + num(*b.dt) + " against " + num(*s.dt) + " at Ca " + format_sampled(s.ca);
        }
      }
    }
  return p;
}

// The periods and dt parts of the error of q at the bracketing cases `cases` (largest over them), in units
// of q; the mesh part is added in Ca by the caller.
struct Parts {
  Part mesh, periods, dt;
};

Parts parts_at(const Cell& cell, const SampleGroup& g, const std::vector<const Sample*>& cases, Quantity q) {
  Parts out;
  for (const Sample* c : cases)
    if (auto sp = spread(*c, q); sp && (!out.periods.e || *sp > *out.periods.e))
      out.periods = {sp, "spread over the last periods at Ca " + format_sampled(c->ca), {}};
  out.dt = dt_part(cell, g, q);
  return out;
}

// Fills e's parts (periods and dt through |slope|, mesh already in Ca), numerical, source and how.
void to_ca(const Parts& parts, double slope, Quantity q, AnswerError& e) {
  std::string how;
  auto pick = [&](const std::optional<double>& out, const char* name) {
    if (out && (!e.numerical || *out > *e.numerical)) {
      e.numerical = out;
      e.source = name;
    }
  };
  e.on_level = parts.mesh.on_level;
  if (parts.mesh.e) {
    e.mesh = parts.mesh.e;
    how += "; mesh " + num(*e.mesh) + " (" + parts.mesh.how + ")";
  } else {
    how += "; mesh: no data";
  }
  pick(e.mesh, "mesh");
  auto one = [&](const Part& p, const char* name, std::optional<double>& out) {
    if (!p.e) {
      how += std::string("; ") + name + ": no data";
      return;
    }
    out = *p.e / std::fabs(slope);
    how += std::string("; ") + name + " " + num(*out) + " (" + name_of(q) + " ± " + num(*p.e) + ", " + p.how + ")";
    pick(out, name);
  };
  one(parts.periods, "periods", e.periods);
  one(parts.dt, "dt", e.dt);
  e.how += how;
}

// Secant of q between samples lo and hi of s, widened from [lo, hi] by moving the ends outwards (those
// allowed) until it spans at least `span`.
double secant(const std::vector<const Sample*>& s, std::size_t lo, std::size_t hi, double span, Quantity q,
              bool widen_lo, bool widen_hi, std::string& where) {
  // Widen only while q keeps the bracket's trend: past an extremum (the top of a sphere's tension window, which
  // closes again below CaL) a secant flattens and turns every error in q into a huge error in Ca.
  const double trend = *value(*s[hi], q) - *value(*s[lo], q);
  auto continues = [&](std::size_t inner, std::size_t outer, bool outwards_up) {
    const double step = *value(*s[outer], q) - *value(*s[inner], q);
    return (outwards_up ? step : -step) * trend >= 0;
  };
  while (s[hi]->ca - s[lo]->ca < span) {
    bool moved = false;
    if (widen_lo && lo > 0 && continues(lo, lo - 1, false)) --lo, moved = true;
    if (s[hi]->ca - s[lo]->ca < span && widen_hi && hi + 1 < s.size() && continues(hi, hi + 1, true))
      ++hi, moved = true;
    if (!moved) break;
  }
  where = "[" + format_sampled(s[lo]->ca) + ", " + format_sampled(s[hi]->ca) + "]";
  return (*value(*s[hi], q) - *value(*s[lo], q)) / (s[hi]->ca - s[lo]->ca);
}

AnswerError ca_h_error(const Transition& t, const Cell& cell, const SampleGroup& g, std::set<int>& levels) {
  AnswerError e;
  if (!t.ca_h || !t.ca_h_low || !t.ca_h_high) return e;
  const auto s = with_value(g, Quantity::kMaxTauMin);
  std::size_t a = s.size();
  for (std::size_t i = 0; i + 1 < s.size(); ++i)
    if (same_ca(s[i]->ca, *t.ca_h_low) && same_ca(s[i + 1]->ca, *t.ca_h_high)) a = i;
  if (a == s.size()) return e;
  std::string where;
  const double slope = secant(s, a, a + 1, 0.1 * std::fabs(*t.ca_h), Quantity::kMaxTauMin, true, true, where);
  e.how = "slope of max τmin " + num(slope) + " over Ca " + where;
  if (!(std::fabs(slope) > 0) || !std::isfinite(slope)) {
    e.how += "; zero slope: the error cannot be converted to Ca";
    return e;
  }
  Parts parts = parts_at(cell, g, {s[a], s[a + 1]}, Quantity::kMaxTauMin);
  parts.mesh = mesh_part(cell, g.key.mesh_level, Answer::kCaH, s[a]->ca, s[a + 1]->ca, *t.ca_h, t.d12_threshold,
                         slope, levels);
  to_ca(parts, slope, Quantity::kMaxTauMin, e);
  e.total = e.numerical;
  return e;
}

AnswerError edge_error(const std::optional<double>& inside, const std::optional<double>& outside, bool low,
                       double thr, const Cell& cell, const SampleGroup& g, std::set<int>& levels) {
  AnswerError e;
  if (!inside) return e;
  if (!outside) {
    e.how = "the edge is the end of the sampled range: its error is unknown";
    return e;
  }
  const auto s = with_value(g, Quantity::kMinD12);
  std::size_t in = s.size(), out = s.size();
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (same_ca(s[i]->ca, *inside)) in = i;
    if (same_ca(s[i]->ca, *outside)) out = i;
  }
  if (in == s.size() || out == s.size()) return e;
  e.bracket = std::fabs(*inside - *outside);
  e.how = "bracket " + num(e.bracket) + " (Ca " + format_sampled(*outside) + " outside)";
  std::string where;
  const double span = 0.1 * std::fabs(*inside);
  const double slope = low ? secant(s, out, in, span, Quantity::kMinD12, true, false, where)
                           : secant(s, in, out, span, Quantity::kMinD12, false, true, where);
  e.how += "; slope of min D12 " + num(slope) + " over Ca " + where;
  if (std::fabs(slope) > 0 && std::isfinite(slope)) {
    // The level's own crossing of the threshold between the two samples: what the mesh part compares.
    const auto here = crossing(s[in]->ca, *s[in]->min_d12, s[out]->ca, *s[out]->min_d12, thr);
    Parts parts = parts_at(cell, g, {s[in], s[out]}, Quantity::kMinD12);
    if (here)
      parts.mesh = mesh_part(cell, g.key.mesh_level, low ? Answer::kCaStarLow : Answer::kCaStarHigh, s[in]->ca,
                             s[out]->ca, *here, thr, slope, levels);
    to_ca(parts, slope, Quantity::kMinD12, e);
  }
  e.total = e.bracket + e.numerical.value_or(0.0);
  e.source = e.numerical && *e.numerical > e.bracket ? e.source : "bracket";
  return e;
}

}  // namespace

std::string AnswerError::lacks() const {
  const std::optional<double>* parts[] = {&mesh, &periods, &dt};  // in the order of kErrorParts
  static_assert(std::size(parts) == std::size(kErrorParts), "one value per named part");
  std::string out;
  for (std::size_t i = 0; i < std::size(parts); ++i)
    if (!*parts[i]) {
      if (!out.empty()) out += ',';
      out += kErrorParts[i];
    }
  return out;
}

LevelCrossing check_level_crossing(const SampleGroup& g, const std::vector<double>& answer_ca, bool of_ca_h, double a,
                                   double b, double d12_threshold) {
  const Quantity q = of_ca_h ? Quantity::kMaxTauMin : Quantity::kMinD12;
  const double target = of_ca_h ? 0.0 : d12_threshold;
  auto at = [&](double x) -> std::optional<double> {
    for (const auto& s : g.samples)
      if (same_ca(s.ca, x) && value(s, q)) return value(s, q);
    return std::nullopt;
  };
  const double lo = std::min(a, b), hi = std::max(a, b);
  const auto y_lo = at(lo), y_hi = at(hi);
  if (!y_lo || !y_hi) return {};
  const auto line = crossing(lo, *y_lo, hi, *y_hi, target);
  if ((*y_lo - target) * (*y_hi - target) <= 0 || !line) return {line, false};
  // One side of the target at both: walk the answer level's samples outwards from the bracket while g has
  // them; the first where g's value changes side closes g's own bracket.
  const bool up = *line > hi;
  std::vector<double> beyond;
  for (double x : answer_ca)
    if (up ? x > hi && !same_ca(x, hi) : x < lo && !same_ca(x, lo)) beyond.push_back(x);
  std::sort(beyond.begin(), beyond.end());
  if (!up) std::reverse(beyond.begin(), beyond.end());
  double x0 = up ? hi : lo, y0 = up ? *y_hi : *y_lo;
  for (double x : beyond) {
    const auto y = at(x);
    if (!y) break;
    if ((y0 - target) * (*y - target) <= 0) return {crossing(x0, y0, x, *y, target), false};
    x0 = x;
    y0 = *y;
  }
  return {line, true};
}

std::vector<std::string> group_roles(const std::vector<SampleGroup>& groups, const ErrorOptions& options) {
  std::vector<std::string> roles(groups.size(), "answer");
  // dt_check: within a cell and level, the groups whose time.dt is not the base one (the dt with the most
  // samples; ties to "auto", then to the larger step).
  std::map<std::pair<std::string, int>, std::map<std::string, std::size_t>> samples_by_dt;
  for (const auto& g : groups)
    samples_by_dt[{cell_key(g.key.group_key), g.key.mesh_level}][group_dt(g.key.group_key)] += g.samples.size() + 1;
  for (std::size_t i = 0; i < groups.size(); ++i) {
    const auto& g = groups[i];
    const auto& dts = samples_by_dt[{cell_key(g.key.group_key), g.key.mesh_level}];
    auto better = [](const std::pair<const std::string, std::size_t>& a,
                     const std::pair<const std::string, std::size_t>& b) {
      if (a.second != b.second) return a.second < b.second;
      if (a.first == "auto" || b.first == "auto") return b.first == "auto";
      return std::stod(a.first) < std::stod(b.first);
    };
    const std::string base = std::max_element(dts.begin(), dts.end(), better)->first;
    const int level = g.key.mesh_level;
    // Only multi-fidelity campaigns make dt checks; elsewhere a time.dt axis is a study of its own.
    if (!options.levels.empty() && group_dt(g.key.group_key) != base) roles[i] = "dt_check";
    else if (options.levels.size() >= 2)
      roles[i] = level == options.levels[1] ? "answer" : level < options.levels[1] ? "scan" : "mesh_check";
  }
  return roles;
}

GroupErrors answer_errors(const Transition& t, const std::vector<SampleGroup>& groups,
                          const std::vector<std::string>& roles, std::size_t index) {
  GroupErrors out;
  const Cell cell = cell_of(groups, roles, index);
  const SampleGroup& g = groups[index];
  std::set<int> levels{g.key.mesh_level};
  out.ca_h = ca_h_error(t, cell, g, levels);
  out.ca_star_low = edge_error(t.ca_star_low, t.ca_star_below, true, t.d12_threshold, cell, g, levels);
  out.ca_star_high = edge_error(t.ca_star_high, t.ca_star_above, false, t.d12_threshold, cell, g, levels);
  for (int l : levels) {
    if (!out.levels.empty()) out.levels += ',';
    out.levels += std::to_string(l);
  }
  return out;
}

void estimate_errors(std::vector<Transition>& rows, const std::vector<SampleGroup>& groups,
                     const ErrorOptions& options) {
  const auto roles = group_roles(groups, options);
  for (std::size_t i = 0; i < rows.size() && i < groups.size(); ++i) {
    Transition& t = rows[i];
    t.role = roles[i];
    const GroupErrors e = answer_errors(t, groups, roles, i);
    t.ca_h_err = e.ca_h.total;
    t.ca_star_low_err = e.ca_star_low.total;
    t.ca_star_high_err = e.ca_star_high.total;
    t.ca_h_err_source = e.ca_h.total ? e.ca_h.source : "";
    t.ca_star_low_err_source = e.ca_star_low.total ? e.ca_star_low.source : "";
    t.ca_star_high_err_source = e.ca_star_high.total ? e.ca_star_high.source : "";
    t.ca_h_err_lacks = e.ca_h.total ? e.ca_h.lacks() : "";
    t.ca_star_low_err_lacks = e.ca_star_low.total ? e.ca_star_low.lacks() : "";
    t.ca_star_high_err_lacks = e.ca_star_high.total ? e.ca_star_high.lacks() : "";
    t.error_levels = e.levels;
    t.error_note.clear();
    auto add = [&](const char* name, const AnswerError& a) {
      if (a.how.empty()) return;
      t.error_note += (t.error_note.empty() ? "" : " | ") + std::string(name) +
                      (a.total ? " ± " + num(*a.total) + " (" + a.source + ")" : " ± ?") + ": " + a.how;
    };
    add("CaH", e.ca_h);
    add("Ca* low", e.ca_star_low);
    add("Ca* high", e.ca_star_high);
    t.level_answers.clear();
    if (!e.ca_h.on_level.empty()) t.level_answers["ca_h"] = e.ca_h.on_level;
    if (!e.ca_star_low.on_level.empty()) t.level_answers["ca_star_low"] = e.ca_star_low.on_level;
    if (!e.ca_star_high.on_level.empty()) t.level_answers["ca_star_high"] = e.ca_star_high.on_level;
  }
}

}  // namespace capsim::campaign
