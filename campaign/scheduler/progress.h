#pragma once
/// @file
/// @brief The campaign progress display on stderr: a redrawn line on a terminal, a plain log otherwise.

#include <chrono>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "campaign/grid/case_params.h"

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

/// @brief What multi-fidelity refinement will still add to one cell of a campaign (its cases of one law, a/b, C,
/// ... on every level: GroupKey::cell), as the ETA sees it.
struct CellOutlook {
  int answer_level = 0;        ///< the campaign's answer level ([analysis] levels, the second)
  double answer_est_cost = 0;  ///< estimate of a typical answer-level case of the cell (0: none known)
  double answer_est_cost_below = 0;  ///< the same typical case's estimate one level coarser (0: none known)
  int answer_cases = 0;        ///< answer-level cases the cell has, any status
  double answer_rounds = 0;    ///< answer-level rounds it has had
  /// None of its cases runs or waits although refinement was asked after its last case ended: it has its
  /// answer (a cell's rounds read only its own cases), nothing more will be added to it.
  bool settled = false;
};

/// @brief The time a campaign still needs, from what its finished cases cost.
///
/// CaseParams::estimated_cost is the cost model of solver/dynamics/cost_model.h. Whole cases follow it only
/// loosely within a level: wall ∝ est_cost^0.55–0.83 (periodic cases stop before t_end, prestress adds stages
/// along a run). One ratio of wall time to estimated cost, taken over the cheap cases that ran first
/// (`--order shortest`, or a level-2 scan before level 3), misjudged the expensive rest by an order of
/// magnitude (a certified Table 1 read ETA 134 h for about 25 h of work). So each mesh level fits its own
/// power law
///
///     log wall = log wall_mean + β (log est − log est_mean),
///
/// by least squares over its finished cases, with β drawn towards kCostExponent (the fit of the committed
/// databases) as if kPriorWeight cases spread one e-fold in est_cost had measured it: one case, or cases of
/// one estimate, give β = kCostExponent; a hundred spread cases give their own β. The prediction is the
/// arithmetic mean (× exp(s²/2), s² the residual variance in log wall), since the ETA sums predictions. A
/// level with no finished case yet uses the nearest level that has one (the coarser on a tie): the cost model
/// carries a case across levels (wall ∝ est, not est^β, since the same case moves as its estimate does). Where
/// the case's own estimate on that level is known (Work::est_cost_below, the level just coarser), the case is
/// carried itself: that level's law at its estimate there, times the ratio of its two estimates, so a case
/// that is expensive on the coarser level is carried at that level's lower wall per estimate (β < 1); else
/// at that level's mean ratio of wall time to estimate. A level's first finished cases are noisy (a case's
/// wall time spreads by ×1.4 or more about its level's law), so a level with a coarser one is drawn towards
/// the prediction carried from it: the weighted mean in log wall of its own law (weight: its finished cases)
/// and the carry (weight kCarryWeight). The carry to a finer level is multiplied by kFinerLevelCarry per level:
/// the cost model's ratio of one case's estimates on two levels overstates the ratio of its wall times.
///
/// A multi-fidelity campaign adds cases as it goes (a cell's first answer-level round seeds its brackets, each
/// later one adds a case or two), which the queue does not hold yet: for each cell not yet settled the ETA adds
/// the answer-level rounds a cell takes on average (kAnswerRoundsPerCell, drawn towards the cells of this
/// campaign that have settled) beyond those it has had, at kCasesPerLaterRound cases each (for a cell that has
/// had none, the answer-level cases a cell takes: kAnswerCasesPerCell drawn the same way towards the settled
/// cells, since a campaign whose cells bracket nothing on the answer level, or close their brackets in a round
/// or two, needs fewer), each case at the cell's typical answer-level cost. A cell's rounds
/// run one after the other (a round needs the previous round's results), so the campaign also lasts at least
/// as long as the longest cell's chain: its current round, then one case's time per round to come.
class EtaModel {
 public:
  /// @brief The exponent β of wall ∝ est_cost^β within one level, as measured (least squares in log-log;
  /// EtaModel.TheCostExponentIsTheFitOfTheCommittedDatabases redoes it): 0.74 over the 106 level-3 cases of
  /// results/table1_paper/table1_paper.sqlite; 0.82 / 0.81 over 46 level-2 / 66 level-3 cases of
  /// results/table1_certified/table1_certified.sqlite; 0.61 / 0.64 over the main command's run
  /// results/table1/table1_mf_mixed.sqlite; 0.55 / 0.75 over 112 / 161 of results/bending/table1_bending.sqlite.
  /// (With an estimate ∝ 1/Ca it was 0.19–0.33, and the residual spread in log wall was up to 20% larger.)
  static constexpr double kCostExponent = 0.75;
  /// @brief How strongly β is drawn to kCostExponent: the Σ (log est − mean)² of a prior of that weight.
  static constexpr double kPriorWeight = 4.0;
  /// @brief Answer-level cases a multi-fidelity cell takes, seeds, bisections and dt check together: 9.7,
  /// 9.5 and 9.3 per cell in the main preset's databases results/table1_mf.sqlite,
  /// results/table1_mf_mixed.sqlite (both at the tag results-archive-52bef5c) and results/table1/table1_mf_mixed.sqlite.
  static constexpr double kAnswerCasesPerCell = 9.5;
  /// @brief Answer-level rounds a multi-fidelity cell takes: the mean of 4.67, 4.83 and 4.67 per cell in the
  /// same databases (5.7–6.5 in the three campaigns of results/bending/table1_bending.sqlite, 7.3 in the second
  /// of results/table1_certified/table1_certified.sqlite).
  static constexpr double kAnswerRoundsPerCell = 4.7;
  /// @brief Cases of an answer-level round after a cell's first: 1.55, 1.43, 1.45 in the three databases
  /// above, 1.4–1.7 in the bending ones, 1.3–1.55 in the certified one.
  static constexpr double kCasesPerLaterRound = 1.5;
  /// @brief How many settled cells kAnswerRoundsPerCell counts as, against the cells of the campaign itself.
  static constexpr double kPriorCells = 4.0;
  /// @brief How many finished cases of a level the prediction carried from the coarser level counts as (class
  /// comment): the ratio of one case's variance about its level's law to the carry's squared error, at its
  /// smallest. The carry of the same case from level 2 to 3 is off by a factor 0.85 (log error 0.17,
  /// squared 0.028) over the twins of results/table1/table1_mf_mixed.sqlite
  /// (EtaModel.TheCostModelCarriesACaseAcrossLevels); a case's residual variance in log wall about its level's
  /// law is 0.12–0.15 there, 0.20–0.59 in results/table1_certified/table1_certified.sqlite and 0.25–0.42 in
  /// results/bending/table1_bending.sqlite: 0.12 / 0.028 ≈ 4.
  static constexpr double kCarryWeight = 4.0;
  /// @brief A case's wall time on the next finer level over its wall time on this one, divided by the cost
  /// model's ratio of its two estimates: 0.84, the geometric mean over the 115 cases run on both levels 2 and 3
  /// (same cell, Ca and time step) of the committed databases — 0.85 over 29 in the main command's version-2 run
  /// (tests/campaign/store/fixtures/table1_mf_mixed_v2.sqlite; its version-3 rerun in results/table1/ gives 0.92),
  /// 0.97 over 29 in results/table1_certified/table1_certified.sqlite, 0.78 over 57 in
  /// results/bending/table1_bending.sqlite (EtaModel.TheCostModelCarriesACaseAcrossLevels redoes it). Two parts:
  /// the finer level's cases stop sooner (their periods repeat sooner; a multi-fidelity case waits for one answer
  /// only: γ̇t_final 0.80 of its level-2 twin's for the main command's Ca* cases), and the rest is the cost
  /// model's level scaling (wall per unit γ̇t 0.95, 1.04 and 0.77 of the carried in the three). Levels 1 → 2
  /// (0.63 in results/viscosity_ratio/viscosity_ratio.sqlite) and 3 → 4 (0.60 in the certified database, its
  /// level 4 on two instruction sets) are not in the mean: too few databases to say whether they differ.
  static constexpr double kFinerLevelCarry = 0.84;
  /// @brief Records a finished case: its level, estimated cost and measured wall seconds (of the whole
  /// case, all attempts).
  void add_done(int mesh_level, double est_cost, double wall_s);
  /// @brief Expected wall seconds of a case of @p mesh_level with @p est_cost (and, if known and > 0, its
  /// estimate @p est_cost_below on mesh level @p mesh_level − 1); < 0 before any case finished.
  [[nodiscard]] double expected_s(int mesh_level, double est_cost, double est_cost_below = 0) const;
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
    std::string cell{};    ///< its multi-fidelity cell (a key of remaining_s's cells), "" for none
    double est_cost_below = 0;  ///< its estimate on mesh level mesh_level − 1 (0: not known)
  };
  /// @brief Seconds until the last case ends: the predicted work of @p cases (whole-case prediction ×
  /// fraction_left, minus what a running case has run of it) and what @p cells will still add (class
  /// comment), spread over @p jobs workers, but never less than the longest single remainder (one long case
  /// does not split) nor the longest cell's chain of rounds. < 0 (printed "?") before any case finished, and
  /// when all that is left is running cases that already ran past their estimate.
  [[nodiscard]] double remaining_s(const std::vector<Work>& cases, int jobs,
                                   const std::map<std::string, CellOutlook>& cells = {}) const;

 private:
  /// Least-squares sums of one level, in logs: n, Σx, Σy, Σx², Σxy, Σy² (x = log est, y = log wall).
  struct Sums {
    double n = 0, x = 0, y = 0, xx = 0, xy = 0, yy = 0;
  };
  /// log wall predicted at log est @p x by the law of @p s.
  static double predict_log(const Sums& s, double x);
  /// log wall of a case of @p mesh_level carried from the nearest other level with a finished case (only a
  /// coarser one if @p coarser_only), at log est @p x and (NaN: unknown) @p x_below one level coarser (class
  /// comment); NaN if there is none.
  double carried_log(int mesh_level, double x, double x_below, bool coarser_only) const;
  /// log wall predicted for a case of @p mesh_level: its own law drawn towards the carry, or the carry alone.
  double law_log(int mesh_level, double x, double x_below) const;
  std::map<int, Sums> by_level_;
};

/// @brief The cells of a multi-fidelity campaign as the ETA sees them (CellOutlook), kept up to date as
/// refinement adds cases. Cases are told once each, in the batches they were added in.
class CellTally {
 public:
  explicit CellTally(int answer_level) : answer_level_(answer_level) {}
  /// @brief The cases present when the tally starts (a resumed campaign's earlier rounds are counted at
  /// EtaModel's cases per round) or a batch refinement added (one round for each cell it adds
  /// answer-level cases to). @p est_cost of each case as stored.
  void add_batch(const std::vector<std::pair<CaseParams, double>>& cases, bool first);
  /// @brief The outlook of every cell; @p busy are the cells with a case running or waiting.
  [[nodiscard]] std::map<std::string, CellOutlook> outlook(const std::set<std::string>& busy) const;
  /// @brief The cell of a case (GroupKey::cell as text).
  static std::string cell_of(const CaseParams& params);

 private:
  struct Cell {
    int answer_cases = 0;
    double answer_rounds = 0;
    double answer_log_est = 0;  // Σ log est over its answer-level cases
    double scan_log_est = 0;    // Σ log est over its other cases, each moved to the answer level
    double answer_log_est_below = 0, scan_log_est_below = 0;  // the same sums one level below the answer level
    bool below_known = true;  // false if a case of the cell has no estimate one level below the answer level
    int scan_cases = 0;
  };
  int answer_level_;
  std::map<std::string, Cell> cells_;
};

/// @brief An EtaModel learnt from every finished case of @p campaign_id (also of earlier runs), with the
/// worker's wall time over all attempts (a manager's own clock sees only the last attempt of a resumed case);
/// cases run with another thread count are scaled to @p threads as if threads scaled perfectly (a first
/// guess, which cases run with @p threads correct).
EtaModel learn_eta(Store& store, std::int64_t campaign_id, int threads);

/// @brief "1h02m", "3m20s", "12s".
std::string format_duration(double seconds);

}  // namespace capsim::campaign
