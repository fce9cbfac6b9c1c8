#include "campaign/scheduler/progress.h"

#include "campaign/analysis/group_key.h"
#include "campaign/store/store.h"

#include <cmath>

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace capsim::campaign {

std::string format_duration(double s) {
  if (s < 0) return "?";
  long t = static_cast<long>(s + 0.5);
  char buf[64];
  if (t >= 3600) std::snprintf(buf, sizeof buf, "%ldh%02ldm", t / 3600, (t % 3600) / 60);
  else if (t >= 60) std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
  else std::snprintf(buf, sizeof buf, "%lds", t);
  return buf;
}

void EtaModel::add_done(int mesh_level, double est_cost, double wall_s) {
  if (!(est_cost > 0) || !(wall_s >= 0) || !std::isfinite(est_cost) || !std::isfinite(wall_s)) return;
  const double x = std::log(est_cost), y = std::log(std::max(wall_s, 1e-3));
  Sums& s = by_level_[mesh_level];
  s.n += 1;
  s.x += x;
  s.y += y;
  s.xx += x * x;
  s.xy += x * y;
  s.yy += y * y;
}

double EtaModel::predict_log(const Sums& s, double x) {
  const double mx = s.x / s.n, my = s.y / s.n;
  const double sxx = std::max(0.0, s.xx - s.n * mx * mx), sxy = s.xy - s.n * mx * my;
  const double beta = std::clamp((sxy + kPriorWeight * kCostExponent) / (sxx + kPriorWeight), 0.0, 1.5);
  // Residual variance of log wall about the law (unbiased once three cases are in); the prediction is the
  // mean wall, not the median, because the ETA adds predictions up.
  double var = 0;
  if (s.n >= 3) {
    const double syy = std::max(0.0, s.yy - s.n * my * my);
    var = std::max(0.0, syy - 2 * beta * sxy + beta * beta * sxx) / (s.n - 2);
  }
  return my + beta * (x - mx) + 0.5 * std::min(var, 1.0);
}

double EtaModel::carried_log(int mesh_level, double x, double x_below, bool coarser_only) const {
  int nearest = 0;
  bool found = false;
  for (const auto& [level, _] : by_level_)  // ascending: on a tie the coarser stays
    if (level != mesh_level && (!coarser_only || level < mesh_level) &&
        (!found || std::abs(level - mesh_level) < std::abs(nearest - mesh_level)))
      nearest = level, found = true;
  if (!found) return std::nan("");
  // The case itself, where its estimate on the level below is known and that level is the nearest one.
  if (nearest == mesh_level - 1 && std::isfinite(x_below))
    return law_log(nearest, x_below, std::nan("")) + (x - x_below) + std::log(kFinerLevelCarry);
  // Else at that level's mean ratio of wall to estimate (its prediction at its mean estimate, moved in
  // proportion). Either way times kFinerLevelCarry per level finer (its inverse per level coarser).
  const double mx = by_level_.at(nearest).x / by_level_.at(nearest).n;
  return law_log(nearest, mx, std::nan("")) + (x - mx) + (mesh_level - nearest) * std::log(kFinerLevelCarry);
}

double EtaModel::law_log(int mesh_level, double x, double x_below) const {
  const auto it = by_level_.find(mesh_level);
  if (it == by_level_.end()) return carried_log(mesh_level, x, x_below, false);
  const double own = predict_log(it->second, x);
  const double carried = carried_log(mesh_level, x, x_below, true);
  if (!std::isfinite(carried)) return own;
  // A level's first cases drawn towards the carry from the coarser level, which counts as kCarryWeight cases.
  const double n = it->second.n;
  return (n * own + kCarryWeight * carried) / (n + kCarryWeight);
}

double EtaModel::expected_s(int mesh_level, double est_cost, double est_cost_below) const {
  if (by_level_.empty() || !(est_cost > 0)) return -1;
  return std::exp(law_log(mesh_level, std::log(est_cost), est_cost_below > 0 ? std::log(est_cost_below) : std::nan("")));
}

double EtaModel::remaining_s(const std::vector<Work>& cases, int jobs, const std::map<std::string, CellOutlook>& cells) const {
  if (by_level_.empty()) return -1;
  jobs = std::max(1, jobs);
  double total = 0, longest = 0;
  bool overdue = false;
  std::map<std::string, std::pair<double, double>> round_left;  // cell -> (work, longest case) of its queue
  for (const auto& w : cases) {
    const double e = expected_s(w.mesh_level, w.est_cost, w.est_cost_below) * std::clamp(w.fraction_left, 0.0, 1.0) -
                     (w.running ? w.elapsed_s : 0.0);
    overdue |= w.running && e <= 0;
    total += std::max(0.0, e);
    longest = std::max(longest, e);
    if (!w.cell.empty()) {
      auto& [work, longest_case] = round_left[w.cell];
      work += std::max(0.0, e);
      longest_case = std::max(longest_case, e);
    }
  }
  // What refinement will still add: the rounds and cases per cell drawn towards this campaign's settled cells.
  double rounds_per_cell = kPriorCells * kAnswerRoundsPerCell, cases_per_cell = kPriorCells * kAnswerCasesPerCell;
  double weight = kPriorCells;
  for (const auto& [_, c] : cells)
    if (c.settled) {
      rounds_per_cell += c.answer_rounds;
      cases_per_cell += c.answer_cases;
      weight += 1;
    }
  rounds_per_cell /= weight;
  cases_per_cell /= weight;
  for (const auto& [key, c] : cells) {
    if (c.settled) continue;
    const double e = expected_s(c.answer_level, c.answer_est_cost, c.answer_est_cost_below);
    if (!(e > 0)) continue;
    const double rounds_to_come = std::max(0.0, rounds_per_cell - c.answer_rounds);
    const double cases_to_come = c.answer_rounds > 0 ? rounds_to_come * kCasesPerLaterRound : cases_per_cell;
    total += cases_to_come * e;
    const auto it = round_left.find(key);
    const double current = it == round_left.end() ? 0.0 : std::max(it->second.first / jobs, it->second.second);
    longest = std::max(longest, current + rounds_to_come * e);
  }
  // Only cases that already ran past their estimate are left: how much longer they take is not known
  // (printing "0s" while they still run would be a wrong answer).
  if (overdue && !(total > 0)) return -1;
  return std::max(total / jobs, longest);
}

std::string CellTally::cell_of(const CaseParams& params) { return GroupKey::of(params).cell().str(); }

namespace {
// log of an estimate on another level, clearing @p known if the solver rejects the case there (estimate 0).
double log_or_unknown(double est, bool& known) {
  known = known && est > 0;
  return est > 0 ? std::log(est) : 0.0;
}
}  // namespace

void CellTally::add_batch(const std::vector<std::pair<CaseParams, double>>& cases, bool first) {
  std::set<std::string> rounds;  // cells this batch gives an answer-level round
  for (const auto& [params, est] : cases) {
    Cell& c = cells_[cell_of(params)];
    if (params.mesh_level() == answer_level_) {
      ++c.answer_cases;
      c.answer_log_est += std::log(std::max(est, 1e-300));
      c.answer_log_est_below += log_or_unknown(params.estimated_cost_on_level(answer_level_ - 1), c.below_known);
      rounds.insert(cell_of(params));
    } else if (params.mesh_level() < answer_level_) {
      c.scan_log_est += std::log(std::max(params.estimated_cost_on_level(answer_level_), 1e-300));
      c.scan_log_est_below += log_or_unknown(params.estimated_cost_on_level(answer_level_ - 1), c.below_known);
      ++c.scan_cases;
    }
  }
  for (const auto& key : rounds) {
    Cell& c = cells_[key];
    // A resumed campaign's earlier rounds are not recorded: count them at the mean cases per round.
    c.answer_rounds = first ? c.answer_cases * EtaModel::kAnswerRoundsPerCell / EtaModel::kAnswerCasesPerCell
                            : c.answer_rounds + 1;
  }
}

std::map<std::string, CellOutlook> CellTally::outlook(const std::set<std::string>& busy) const {
  std::map<std::string, CellOutlook> out;
  for (const auto& [key, c] : cells_) {
    CellOutlook o;
    o.answer_level = answer_level_;
    o.answer_cases = c.answer_cases;
    o.answer_rounds = c.answer_rounds;
    if (c.answer_cases > 0) {
      o.answer_est_cost = std::exp(c.answer_log_est / c.answer_cases);
      if (c.below_known) o.answer_est_cost_below = std::exp(c.answer_log_est_below / c.answer_cases);
    } else if (c.scan_cases > 0) {
      o.answer_est_cost = std::exp(c.scan_log_est / c.scan_cases);
      if (c.below_known) o.answer_est_cost_below = std::exp(c.scan_log_est_below / c.scan_cases);
    }
    o.settled = busy.count(key) == 0;
    out.emplace(key, o);
  }
  return out;
}

EtaModel learn_eta(Store& store, std::int64_t campaign_id, int threads) {
  EtaModel m;
  for (const auto& c : store.finished_costs(campaign_id))
    m.add_done(c.mesh_level, c.est_cost, c.wall_s * std::max(1, c.threads) / std::max(1, threads));
  return m;
}

Progress::Progress(std::string name) : name_(std::move(name)), tty_(isatty(STDERR_FILENO) == 1) {}

std::string Progress::format(const ProgressCounts& c) const {
  char buf[256];
  std::snprintf(buf, sizeof buf, "[%s] %d/%d done, %d running, %d failed, %d queued, ETA %s", name_.c_str(),
                c.finished, c.total, c.running, c.failed, c.queued, format_duration(c.eta_s).c_str());
  return buf;
}

void Progress::show(const ProgressCounts& c, bool force) {
  const auto now = std::chrono::steady_clock::now();
  const std::string line = format(c);
  const double since = std::chrono::duration<double>(now - last_time_).count();
  if (tty_) {
    if (!force && since < 0.1) return;
    const int bar = 20;
    int filled = c.total > 0 ? (bar * (c.finished + c.failed)) / c.total : 0;
    std::string b(static_cast<std::size_t>(filled), '#');
    b.resize(bar, '.');
    std::fprintf(stderr, "\r\033[K[%s] %s", b.c_str(), line.c_str());
    std::fflush(stderr);
    drawn_ = true;
  } else {
    // Plain log: a line whenever the counts change (ETA aside), else every 30 s.
    const std::string key = line.substr(0, line.find(", ETA"));
    if (!force && key == last_ && since < 30) return;
    std::fprintf(stderr, "%s\n", line.c_str());
    last_ = key;
  }
  last_time_ = now;
}

void Progress::message(const std::string& text) {
  if (tty_ && drawn_) std::fprintf(stderr, "\r\033[K");
  std::fprintf(stderr, "%s\n", text.c_str());
  if (tty_ && drawn_) last_time_ = {};
}

void Progress::finish() {
  if (tty_ && drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace capsim::campaign
