#include "campaign/scheduler/progress.h"

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
  if (!(est_cost > 0) || !(wall_s >= 0)) return;
  auto& [w, c] = by_level_[mesh_level];
  w += wall_s;
  c += est_cost;
  wall_ += wall_s;
  cost_ += est_cost;
}

double EtaModel::expected_s(int mesh_level, double est_cost) const {
  if (!(cost_ > 0)) return -1;
  const auto it = by_level_.find(mesh_level);
  if (it != by_level_.end() && it->second.second > 0) return est_cost * it->second.first / it->second.second;
  // No case of this level finished yet: the nearest level that has one (the coarser on a tie), corrected from
  // the estimate's 32x per level to what whole cases measure per level.
  int nearest = 0;
  double ratio = -1;
  for (const auto& [level, wc] : by_level_) {
    if (!(wc.second > 0)) continue;
    if (ratio < 0 || std::abs(level - mesh_level) < std::abs(nearest - mesh_level)) {
      nearest = level;
      ratio = wc.first / wc.second;
    }
  }
  if (ratio < 0) ratio = wall_ / cost_;
  return est_cost * ratio * std::pow(kMeasuredPerLevel / 32.0, mesh_level - nearest);
}

double EtaModel::remaining_s(const std::vector<std::pair<int, double>>& pending,
                             const std::vector<std::tuple<int, double, double>>& running, int jobs) const {
  if (!(cost_ > 0)) return -1;
  double total = 0, longest = 0;
  bool overdue = false;
  for (const auto& [level, est] : pending) {
    const double e = expected_s(level, est);
    total += e;
    longest = std::max(longest, e);
  }
  for (const auto& [level, est, elapsed] : running) {
    const double e = expected_s(level, est) - elapsed;
    overdue |= e <= 0;
    total += std::max(0.0, e);
    longest = std::max(longest, e);
  }
  // Only cases that already ran past their estimate are left: how much longer they take is not known
  // (printing "0s" while they still run would be a wrong answer).
  if (overdue && !(total > 0)) return -1;
  return std::max(total / std::max(1, jobs), longest);
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
