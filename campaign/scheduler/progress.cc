#include "campaign/scheduler/progress.h"

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

double EtaModel::expected_s(int mesh_level, double est_cost) const {
  if (by_level_.empty() || !(est_cost > 0)) return -1;
  const double x = std::log(est_cost);
  if (const auto it = by_level_.find(mesh_level); it != by_level_.end()) return std::exp(predict_log(it->second, x));
  // No case of this level finished yet: the nearest level that has one (the coarser on a tie), at the
  // estimate moved to that level, times the measured factor per level.
  int nearest = by_level_.begin()->first;
  for (const auto& [level, _] : by_level_)
    if (std::abs(level - mesh_level) < std::abs(nearest - mesh_level)) nearest = level;
  const int d = mesh_level - nearest;
  return std::exp(predict_log(by_level_.at(nearest), x - d * std::log(kEstimatePerLevel))) * std::pow(kMeasuredPerLevel, d);
}

double EtaModel::remaining_s(const std::vector<Work>& cases, int jobs) const {
  if (by_level_.empty()) return -1;
  double total = 0, longest = 0;
  bool overdue = false;
  for (const auto& w : cases) {
    const double e = expected_s(w.mesh_level, w.est_cost) * std::clamp(w.fraction_left, 0.0, 1.0) -
                     (w.running ? w.elapsed_s : 0.0);
    overdue |= w.running && e <= 0;
    total += std::max(0.0, e);
    longest = std::max(longest, e);
  }
  // Only cases that already ran past their estimate are left: how much longer they take is not known
  // (printing "0s" while they still run would be a wrong answer).
  if (overdue && !(total > 0)) return -1;
  return std::max(total / std::max(1, jobs), longest);
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
