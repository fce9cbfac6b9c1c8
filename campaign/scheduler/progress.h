#pragma once
/// @file
/// @brief The campaign progress display on stderr: a redrawn line on a terminal, a plain log otherwise.

#include <chrono>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace capsim::campaign {

/// @brief Counts shown by the progress display.
struct ProgressCounts {
  int total = 0;      ///< cases in the campaign
  int finished = 0;   ///< done or unstable (including before this run)
  int failed = 0;     ///< failed
  int running = 0;    ///< workers alive
  int queued = 0;     ///< waiting to start
  double eta_s = -1;  ///< estimated seconds to go (< 0 unknown)
};

/// @brief Progress line "[name] 12/40 done, 2 running, 1 failed, 25 queued, ETA 3m20s".
class Progress {
 public:
  /// @brief @p name labels the lines; detects whether stderr is a terminal.
  explicit Progress(std::string name);
  /// @brief Shows the counts: redraws on a terminal (at most 10/s), logs a line on change or every 30 s
  /// otherwise. @p force always prints.
  void show(const ProgressCounts& c, bool force = false);
  /// @brief Prints a message on its own line (keeps the bar intact on a terminal).
  void message(const std::string& text);
  /// @brief Ends the redrawn line.
  void finish();

 private:
  std::string format(const ProgressCounts& c) const;
  std::string name_;
  bool tty_;
  bool drawn_ = false;
  std::string last_;
  std::chrono::steady_clock::time_point last_time_{};
};

/// @brief The time a campaign still needs, from what its finished cases cost.
///
/// CaseParams::estimated_cost is a rough power law in the mesh level (32× per level, where whole cases measure
/// 5–13×), so one ratio of measured wall time to estimated cost, taken over cheap cases that ran first
/// (`--order shortest`, or a level-2 scan before level 3), misjudges the expensive rest by an order of
/// magnitude. Each mesh level therefore keeps its own ratio; a level with no finished case yet borrows the
/// ratio of the nearest level that has one, times (kMeasuredPerLevel / 32) per level between them.
class EtaModel {
 public:
  /// @brief What a whole case costs per mesh level finer, as measured: the geometric mean of the wall-time
  /// ratios of the same case on consecutive levels in the committed databases (2026-12-03: 8.7 over 90
  /// level-2/3 pairs, 9.5 over 5 level-3/4 pairs; single pairs range 1.1-24). Only an ETA's first guess for
  /// a level that has no finished case yet.
  static constexpr double kMeasuredPerLevel = 9.0;
  /// @brief Records a finished case: its level, estimated cost and measured wall seconds.
  void add_done(int mesh_level, double est_cost, double wall_s);
  /// @brief Expected wall seconds of a case of @p mesh_level with @p est_cost; < 0 before any case finished.
  [[nodiscard]] double expected_s(int mesh_level, double est_cost) const;
  /// @brief Seconds until the last case ends: the work of @p pending (level, est_cost) and what @p running
  /// (level, est_cost, elapsed seconds) still needs, spread over @p jobs workers, but never less than the
  /// longest single remainder (one long case does not split). < 0 (printed "?") before any case finished,
  /// and when all that is left is running cases that already ran past their estimate.
  [[nodiscard]] double remaining_s(const std::vector<std::pair<int, double>>& pending,
                                   const std::vector<std::tuple<int, double, double>>& running, int jobs) const;

 private:
  std::map<int, std::pair<double, double>> by_level_;  // level -> (wall seconds, estimated cost)
  double wall_ = 0, cost_ = 0;
};

/// @brief "1h02m", "3m20s", "12s".
std::string format_duration(double seconds);

}  // namespace capsim::campaign
