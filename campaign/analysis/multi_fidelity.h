#pragma once
/// @file
/// @brief Multi-fidelity campaigns: which cases the answer and check levels need, from what the
/// other levels found. Pure: the scheduler adds the returned cases and runs them (campaign_runner.cc).
///
/// The phases, for [analysis] levels = [scan, answer(, check)]:
/// 1. the grid runs on the scan level (cheap; its brackets are where the answers are, roughly);
/// 2. **seed**: each scan group's bracketing Ca — both samples of each Ca* edge, of the CaH bracket, and the
///    sample of smallest min D12 while no Ca* was found — are run on the answer level;
/// 3. **re-bracket**: where the answer level does not bracket an answer the scan level did (the oblate NH
///    CaH is 0.23 on level 2 and 0.60 on level 3), the next scan Ca outwards is run on the answer level
///    (beyond the scan's range: ×1.5 or ÷1.5), until the answer level brackets it; where max τmin < 0 at
///    every answer-level sample, the next scan Ca above the largest sample is run too (a membrane is
///    compressed below a lower critical CaL as well as above CaH, so "all negative" does not say which side);
/// 4. **refine** (adaptive mode): bisection on the answer level (analysis/refinement.h), each bracket
///    stopping once it is narrower than max(ca_tolerance, the answer's numerical error): refining a bracket
///    below what the mesh resolves buys nothing; without a Ca* band the minimum of min D12 is bracketed only
///    while it is within 3× the threshold (a band may lie between samples; a sphere's 0.45 has none). With
///    dt_check = true a cell is refined only once its dt check exists (phase 5): until then its errors lack
///    the dt part, and a bracket refined down to the rest alone may be refined below the time step's error.
///    (The mesh part needs no such wait: the scan level exists from the start, and where it has no answer of
///    its own near a bracket it is compared as values, analysis/uncertainty.h.);
/// 5. **dt check** (dt_check = true): once per cell, when phases 2–4 add nothing (with dt_check, before the
///    cell is refined), the CaH-low case (else the Ca*-low case) on the answer level with time.dt = half the
///    step it ran with; its dt part then serves every answer of the cell (analysis/uncertainty.h);
/// 6. **check** (a third level): the final bracketing cases of every answer re-run on the check level,
///    which gives the mesh part of the error (analysis/uncertainty.h); where the check level's two values
///    lie on one side of the target (its answer is outside the answer level's bracket), the answer level's
///    next sample outwards too, one at a time, until the check level brackets its answer itself.
/// Phases 2–4 repeat as rounds until none adds a case; 5 runs when they add none, and they resume after it
/// (the refinement); 6 runs last (the cheap dt check first, so that a campaign interrupted among the check
/// level's long cases has it). The mesh part is not waited for: on a third level it costs hours.

#include <string>
#include <vector>

#include "campaign/analysis/transitions.h"
#include "campaign/analysis/uncertainty.h"
#include "campaign/grid/case_params.h"

namespace capsim::campaign {

/// @brief The inputs of every phase.
struct MultiFidelityOptions {
  std::vector<int> levels;      ///< [scan, answer] or [scan, answer, check]
  double d12_threshold = 0.05;
  double ca_tolerance = 0.005;  ///< smallest bracket adaptive mode makes
  bool adaptive = false;        ///< phase 4
  bool dt_check = false;        ///< phase 5 will run: phase 4 waits for each cell's dt check
  std::string check_precision;  ///< numerics.kernel_precision of phase 6's new cases ("": the answer case's)
  /// @brief Phases 2–6 give each new case the stop test of the answer it is for (time.stop_test): a Ca* edge's
  /// cases stop once min D12 repeats, CaH's once max τmin repeats, a Ca serving both waits for both; the scan
  /// level (the grid) keeps the template's. Off: every new case keeps its template's stop test.
  bool stop_for_answer = false;
};

/// @brief Phases 2–4: the cases of one round on the answer level (none: the answer level is done). New cases
/// only (a Ca that exists in the answer group, whatever its status, is not proposed), at most @p budget.
std::vector<CaseParams> answer_level_round(const std::vector<SampleGroup>& groups, const MultiFidelityOptions& o,
                                           int budget);

/// @brief The bisections adaptive refinement did not make because it stopped at the numerical error: for each
/// bracket of @p t (both Ca* edges, CaH) that is wider than @p ca_tolerance, ceil(log2(width / ca_tolerance))
/// — the cases a refinement down to ca_tolerance alone would still have run ("report the cases
/// saved"). 0 for a missing bracket.
int bisections_saved(const Transition& t, double ca_tolerance);

/// @brief Phase 6: the final brackets of the answer level on the check level (levels[2]; none without one),
/// in o.check_precision where set. A Ca the check group has in any precision is not proposed again.
std::vector<CaseParams> check_level_cases(const std::vector<SampleGroup>& groups, const MultiFidelityOptions& o,
                                          int budget);

/// @brief Whether the rounds may go on while cases still run or wait (the scheduler's top-up when a worker is
/// free): only with a check level, and only while every unfinished case — running or queued — is a
/// check-level one (@p unfinished_levels: their mesh levels). Why: the rounds are sequential, so one
/// check-level case of hours kept every other worker idle until it ended, while the answer level and other
/// cells had work waiting (seen in the certified Table 1: four level-3 refinements and the check level of
/// other cells behind one level-4 case); and a queue of check-level cases (17 of them, ≈ 36 core-hours) kept
/// the check case a finished one had just called for (Sk a/b 0.5 at 2.561) behind all of them. An unfinished
/// answer-level case may still move a bracket, so then nothing; a check-level case changes at most its own
/// cell's mesh error, i.e. whether a level-3 bisection there is still needed (a few minutes of a core, not
/// hours), or which check case the cell needs next.
bool rounds_may_overlap(const MultiFidelityOptions& o, const std::vector<int>& unfinished_levels);

/// @brief Phase 5: per cell, the CaH-low case of the answer level (else its Ca*-low case) with time.dt set
/// to half the step it ran with; none in a cell that has a dt check case already (any Ca, any status).
std::vector<CaseParams> dt_check_cases(const std::vector<SampleGroup>& groups, const MultiFidelityOptions& o,
                                       int budget);

}  // namespace capsim::campaign
