#pragma once
/// @file
/// @brief The campaign progress display on stderr: a redrawn line on a terminal, a plain log otherwise.

#include <chrono>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace capsim::campaign {

class Store;

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
/// CaseParams::estimated_cost is t_end × the evaluations per unit time of the solver's step rule on the
/// reference mesh × 9^level. Whole cases follow it only loosely: within one level wall ∝ est_cost^0.55–0.83
/// (periodic cases stop before t_end, prestress adds stages along a run), and the same case costs ≈ 9× per
/// level finer where its estimate grows ≈ 12×. One ratio of
/// wall time to estimated cost, taken over the cheap cases that ran first (`--order shortest`, or a level-2
/// scan before level 3), misjudged the expensive rest by an order of magnitude (a certified Table 1 read
/// ETA 134 h for about 25 h of work). So each mesh level fits its own power law
///
///     log wall = log wall_mean + β (log est − log est_mean),
///
/// by least squares over its finished cases, with β drawn towards kCostExponent (the fit of the committed
/// databases) as if kPriorWeight cases spread one e-fold in est_cost had measured it: one case, or cases of
/// one estimate, give β = kCostExponent; a hundred spread cases give their own β. The prediction is the
/// arithmetic mean (× exp(s²/2), s² the residual variance in log wall), since the ETA sums predictions. A
/// level with no finished case yet uses the nearest level that has one (the coarser on a tie): its law at
/// the estimate moved to that level (÷ kEstimatePerLevel per level), times kMeasuredPerLevel per level.
class EtaModel {
 public:
  /// @brief What a whole case costs per mesh level finer, as measured: the geometric mean of the wall-time
  /// ratios of the same case on consecutive levels in the committed databases (8.7 over 90
  /// level-2/3 pairs, 9.5 over 5 level-3/4 pairs; single pairs range 1.1-24). Only an ETA's first guess for
  /// a level that has no finished case yet.
  static constexpr double kMeasuredPerLevel = 9.0;
  /// @brief What the estimate of the same case grows per mesh level finer: the geometric mean over the 44
  /// level-2/3 and 3/4 pairs of results/table1_certified/table1_certified.sqlite (11.9, pairs 9–15; 17.9 over the 57 pairs
  /// of results/bending/table1_bending.sqlite, where the bending stiffness grows as h^−2).
  static constexpr double kEstimatePerLevel = 12.0;
  /// @brief The exponent β of wall ∝ est_cost^β within one level, as measured (least squares in
  /// log-log; EtaModel.TheCostExponentIsTheFitOfTheCommittedDatabases redoes it): 0.74 over the 106 level-3
  /// cases of results/table1_paper/table1_paper.sqlite; 0.82 / 0.81 over 46 level-2 / 66 level-3 cases of
  /// results/table1_certified/table1_certified.sqlite; 0.61 / 0.64 over the main command's run
  /// results/table1/table1_mf_mixed.sqlite; 0.55 / 0.75 over 112 / 161 of results/bending/table1_bending.sqlite.
  /// (With an estimate ∝ 1/Ca it was 0.19–0.33, and the residual spread in log wall was up to 20% larger.)
  static constexpr double kCostExponent = 0.75;
  /// @brief How strongly β is drawn to kCostExponent: the Σ (log est − mean)² of a prior of that weight.
  static constexpr double kPriorWeight = 4.0;
  /// @brief Records a finished case: its level, estimated cost and measured wall seconds (of the whole
  /// case, all attempts).
  void add_done(int mesh_level, double est_cost, double wall_s);
  /// @brief Expected wall seconds of a case of @p mesh_level with @p est_cost; < 0 before any case finished.
  [[nodiscard]] double expected_s(int mesh_level, double est_cost) const;
  /// @brief One case still to run or running, as the ETA sees it.
  struct Work {
    int mesh_level = 0;
    double est_cost = 1;
    /// Part of the whole case still to run when its current attempt started (or now, for a queued case):
    /// 1 − t/t_end for a case resuming from a checkpoint at γ̇t = t, 1 for a fresh one. An upper bound: a case
    /// whose periods converge stops before t_end.
    double fraction_left = 1;
    bool running = false;
    double elapsed_s = 0;  ///< of the current attempt (running cases)
  };
  /// @brief Seconds until the last case ends: the predicted work of @p cases (whole-case prediction ×
  /// fraction_left, minus what a running case has run of it), spread over @p jobs workers, but never less
  /// than the longest single remainder (one long case does not split). < 0 (printed "?") before any case
  /// finished, and when all that is left is running cases that already ran past their estimate.
  [[nodiscard]] double remaining_s(const std::vector<Work>& cases, int jobs) const;

 private:
  /// Least-squares sums of one level, in logs: n, Σx, Σy, Σx², Σxy, Σy² (x = log est, y = log wall).
  struct Sums {
    double n = 0, x = 0, y = 0, xx = 0, xy = 0, yy = 0;
  };
  /// log wall predicted at log est @p x by the law of @p s.
  static double predict_log(const Sums& s, double x);
  std::map<int, Sums> by_level_;
};

/// @brief An EtaModel learnt from every finished case of @p campaign_id (also of earlier runs), with the
/// worker's wall time over all attempts (a manager's own clock sees only the last attempt of a resumed case);
/// cases run with another thread count are scaled to @p threads as if threads scaled perfectly (a first
/// guess, which cases run with @p threads correct).
EtaModel learn_eta(Store& store, std::int64_t campaign_id, int threads);

/// @brief "1h02m", "3m20s", "12s".
std::string format_duration(double seconds);

}  // namespace capsim::campaign
