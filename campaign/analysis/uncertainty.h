#pragma once
/// @file
/// @brief The numerical uncertainty of every Table 1 answer: Ca* edges and CaH with an error
/// in Ca, the source that dominates it, and how it was obtained. Pure computation on the grouped cases.
///
/// A *cell* is the set of groups that differ only in `mesh.level` and `time.dt` (one law, a/b, C and
/// everything else): the same answer computed at several resolutions. Within a cell each group has a role —
/// `answer` (its transition is the cell's answer), `scan` (the coarse level of a multi-fidelity campaign),
/// `mesh_check` (a finer level run at the brackets only) or `dt_check` (the answer level re-run with a
/// smaller fixed step at a bracketing case).
///
/// The error of an answer has three parts, each converted to Ca:
/// - **mesh**, compared as answers (in Ca): the answer level's value A_L (CaH, or for a Ca* edge the
///   threshold crossing of the line through its inside and outside samples) against the neighbouring levels'
///   A_{L±1} — the crossing of the line through that level's values at the same two Ca when it has both (a
///   check level run at the brackets; where they do not straddle, the finer level's crossing in its own
///   bracket beyond them when it has one — check_level_cases runs it outwards until it does — else
///   extrapolated), else its own answer from its own bracket (a scan level sampled elsewhere; comparing answers, not values interpolated across a coarse
///   grid, keeps the V of min D12 from posing as a mesh error). A finer level without values at both bracket Ca
///   is pending for that answer and does not enter it (its cases at the bracket are still to run: its own
///   bracket elsewhere, e.g. two far samples of other answers of the cell, says nothing about this one). With both neighbours and monotone
///   differences d₁ = A_L − A_{L−1}, d₂ = A_{L+1} − A_L (same sign, |d₂| < |d₁|): Richardson with the observed
///   ratio r = d₂/d₁, e = |d₂| / (1 − r) (the distance from A_L to the extrapolated limit; observed order
///   p = log₂(1/r) since each level halves h). Otherwise the difference to the finer level |d₂|, or, with
///   only a coarser level, |d₁| — the coarse level's own error, an over-estimate of level L's when the mesh
///   converges (it is what a two-level campaign can say). A neighbour whose line through its samples at the
///   two bracket Ca crosses the target more than a bracket width outside the bracket (no crossing there: the
///   oblate capsule with bending, whose level 2 has no band where level 3 has one) is compared as values
///   instead: max |Δq| at the two samples over |slope| of q on level L (as the periods and dt parts); its
///   crossing is still recorded in AnswerError::on_level. Where no neighbour has an answer near the bracket at
///   all (a scan level whose max τmin keeps one sign over its grid, or with no band, and no finer level), the
///   coarser one is compared as values, its q interpolated linearly at the two bracket Ca between its nearest
///   samples on either side (the last difference of a two-level campaign again: an over-estimate where the
///   mesh converges); only where its samples do not span the bracket does the mesh part stay missing.
/// - **periods**: the spread of the quantity q (max τmin for CaH, min D12 for an edge) over the last periods
///   of the two bracketing cases (min_D12_period_spread, max_tau_min_period_spread of their results), the
///   larger of the two;
/// - **dt**: a dt_check case at the same Ca and level with step r·dt: e = |q_{r dt} − q_dt| / (1 − r²)
///   (the time integrator is second order). One such pair is enough for the cell: its error is used for
///   every answer.
/// Periods and dt are errors of q; they become errors in Ca through the slope of q against Ca on the
/// answer level. The error of the answer is the largest part (named in the source):
/// - **CaH** (zero of max τmin between Ca_a and Ca_b): e_Ca = max(mesh, periods/|s|, dt/|s|), s the secant of
///   max τmin over the bracket widened outwards (one sample each side at a time) until it spans 10 % of CaH,
///   so that a bracket refined far below the noise of τmin does not give a meaningless slope; a side stops
///   widening at a sample that breaks the bracket's trend (past the top of a sphere's tension window the
///   secant would flatten).
/// - **a Ca* edge** (the sampled Ca inside the band, the neighbour outside it): the edge lies between the
///   two samples, so it inherits the whole gap, plus the numerical part:
///   e_Ca = |Ca_in − Ca_out| + max(mesh, periods/|s|, dt/|s|), s the secant of min D12 from the inside sample
///   outwards (widened away from the band in the same way). Its source is "bracket" when the gap is the
///   larger part.
/// A part that has no data (no other level, periods not recorded, no dt_check) is left out and said so in
/// the note and in AnswerError::lacks (Transition::*_err_lacks): the error is then a lower bound. With no part
/// at all a CaH error is unknown (nullopt) and a Ca* edge's error is its gap.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "campaign/analysis/group_key.h"
#include "campaign/analysis/transitions.h"

namespace capsim::campaign {

/// @brief How a campaign's levels are used ([analysis] levels): empty = every group is an answer group
/// (table1 prints the finest level; a time.dt axis is a study of its own, its groups are not dt checks);
/// [scan, answer] or [scan, answer, check]: roles by level, and within a level the groups whose time.dt is
/// not the base one (the dt with the most samples) are dt checks.
struct ErrorOptions {
  std::vector<int> levels;
};

/// @brief The names of an error's numerical parts, in the order AnswerError::lacks lists them.
inline constexpr const char* kErrorParts[] = {"mesh", "periods", "dt"};

/// @brief One answer's error, split into its parts (in Ca; nullopt: no data for that part).
struct AnswerError {
  std::optional<double> total;                    ///< what is reported (nullopt: unknown)
  std::optional<double> numerical;                ///< the largest of mesh, periods, dt, in Ca
  double bracket = 0;                             ///< sampling part (Ca* edges: the gap to the outside sample)
  std::optional<double> mesh, periods, dt;        ///< each part in Ca
  std::string source;                             ///< "mesh" | "periods" | "dt" | "bracket" | ""
  std::string how;                                ///< one line: the parts and how each was obtained
  /// @brief The same answer on the other levels of the cell that the mesh part compared (level -> Ca;
  /// for a Ca* edge the threshold crossing at the bracket, see the file comment): what a check level says.
  std::map<int, double> on_level;
  /// @brief The parts with no data, "mesh", "periods", "dt" in that order and comma-separated ("" when all three
  /// entered). `total` is then a lower bound of the error: e.g. a CaH of a campaign with one level and no dt check
  /// carries the period spread alone. `capsim query table1` marks such an answer's ± (schemas/006).
  [[nodiscard]] std::string lacks() const;
};

/// @brief The errors of the three answers of one group.
struct GroupErrors {
  AnswerError ca_star_low, ca_star_high, ca_h;
  std::string levels;  ///< levels that entered the mesh part, e.g. "2,3"
};

/// @brief Where a finer (check) level puts an answer that the answer level brackets by the samples a, b.
struct LevelCrossing {
  std::optional<double> ca;   ///< nullopt: the level lacks a value at a or b, or its two values are equal
  /// The level's values at a and b lie on one side of the target and none of its samples beyond the bracket
  /// (in the direction their line points) straddles it: `ca` is the line's extrapolated crossing, and the
  /// level needs a sample further out (check_level_cases proposes the answer level's next one).
  bool extrapolated = false;
};

/// @brief The crossing of the target (0 by max τmin for CaH when @p of_ca_h, else @p d12_threshold by min D12)
/// on the level of @p g near the bracket (a, b) of the answer level, whose sampled Ca are @p answer_ca: the
/// line through g's values at a and b when they straddle the target; where they do not, g's answer lies
/// outside the bracket, and it is found by walking the answer level's samples outwards (in the direction the
/// line points) while g has values there: the first whose value is on the other side closes g's own bracket,
/// interpolated, not extrapolated. Else the line's extrapolated crossing, flagged. Only the answer level's
/// neighbours count, so a far sample of g (a Ca* case of the same cell) does not make a bracket across half
/// the range. Why: level 4 of the certified Table 1 moves two CaH past their level-3 brackets (both level-4
/// max τmin of one sign); an extrapolation across a curved τ(Ca) is not an answer of that level.
LevelCrossing check_level_crossing(const SampleGroup& g, const std::vector<double>& answer_ca, bool of_ca_h, double a,
                                   double b, double d12_threshold);

/// @brief Role of every group (groups[i] -> result[i]) under @p options; see the file comment.
std::vector<std::string> group_roles(const std::vector<SampleGroup>& groups, const ErrorOptions& options);

/// @brief The errors of the answers of @p t (the transition of groups[index]) from the other groups of its
/// cell (@p roles from group_roles).
GroupErrors answer_errors(const Transition& t, const std::vector<SampleGroup>& groups,
                          const std::vector<std::string>& roles, std::size_t index);

/// @brief Sets role and the error fields of every row; rows[i] must be the transition of groups[i].
void estimate_errors(std::vector<Transition>& rows, const std::vector<SampleGroup>& groups,
                     const ErrorOptions& options);

}  // namespace capsim::campaign
