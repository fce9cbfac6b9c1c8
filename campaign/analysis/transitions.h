#pragma once
/// @file
/// @brief Critical capillary numbers from finished cases: the Ca* interval (sampled Ca with
/// min D12 < threshold, the seed's Table 1 criterion), CaH (zero of max tau_min, interpolated linearly
/// between the bracketing samples) and the tumbling-to-swinging bracket Ca_TS read from the cases' regimes,
/// computed per group of cases that agree in every identity key but Ca.
/// Pure computation on values: the store reads the cases (CaseSample) and saves the rows (Transition); this
/// folder never touches the database, so the store may use these types without a cycle (store -> analysis).

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "campaign/grid/case_params.h"
#include "solver/diagnostics/period_analysis.h"

namespace capsim::campaign {

/// @brief Critical capillary numbers of one group of cases (every identity key equal except Ca).
struct Transition {
  /// @brief GroupKey::str() of the group (analysis/group_key.h): two groups differ exactly when this differs;
  /// "" in a version-2 row.
  std::string group_key;
  std::string law;                     ///< membrane law (also in group_key; a column for queries)
  double aspect_ratio = 0;             ///< a/b
  double skalak_C = -1;                ///< -1 for neo-hookean
  int mesh_level = 0;                  ///< mesh level
  double d12_threshold = 0.05;         ///< criterion used
  int n_samples = 0;                   ///< finished samples used
  std::optional<double> ca_star_low, ca_star_high;    ///< sampled Ca with min_D12 < threshold
  std::optional<double> ca_star_below, ca_star_above; ///< nearest samples outside the interval
  std::optional<double> ca_min_d12;    ///< sampled Ca of the smallest min_D12
  std::optional<double> ca_h;          ///< interpolated zero of max_tau_min
  std::optional<double> ca_h_low, ca_h_high;          ///< its bracket
  std::string ca_h_low_case, ca_h_high_case;          ///< bracket case ids
  std::string method = "grid";         ///< grid | adaptive
  std::string note;                    ///< e.g. "CaH above sampled range"
  /// @brief What the group is for in its cell (analysis/uncertainty.h): "answer" (Table 1 prints it),
  /// "scan" (the coarse level of a multi-fidelity campaign), "mesh_check" (a finer level run at the
  /// brackets only) or "dt_check" (a smaller time step at a bracketing case).
  std::string role = "answer";
  /// @brief Numerical uncertainty of each answer in Ca (analysis/uncertainty.h says how it is made);
  /// nullopt where the answer is missing or nothing estimates it.
  std::optional<double> ca_star_low_err, ca_star_high_err, ca_h_err;
  /// @brief The largest part of each error: "mesh", "periods", "dt" or "bracket" (a Ca* edge's sampling).
  std::string ca_star_low_err_source, ca_star_high_err_source, ca_h_err_source;
  /// @brief The parts of each error that had no data (AnswerError::lacks: e.g. "mesh,dt"; "" when complete or
  /// without an error): where not empty the error is a lower bound.
  std::string ca_star_low_err_lacks, ca_star_high_err_lacks, ca_h_err_lacks;
  std::string error_levels;  ///< mesh levels whose values entered the mesh part, e.g. "2,3"
  std::string error_note;    ///< provenance: every part of every error and how it was obtained
  /// @brief Each answer ("ca_star_low", "ca_star_high", "ca_h") on the other levels its mesh error compared
  /// (level -> value in Ca; AnswerError::on_level): e.g. the check level's value of an error check.
  std::map<std::string, std::map<int, double>> level_answers;
  /// @brief The tumbling-to-swinging transition read from the regime each case reports (Ca_TS; analyse_group
  /// gives the definition): the adjacent tumbling and swinging samples it lies between. Both set or neither
  /// (schema 7). Its error is the bracket itself: the two ends are sampled values, nothing is interpolated.
  std::optional<double> ca_ts_low, ca_ts_high;
  /// @brief Why Ca_TS has no bracket ("tumbles at every sampled Ca (0.02 to 5)"), that its bracket is not a
  /// clean one (starts with kRegimesNotMonotone) and which samples it skipped; "" for a sphere, and for a clean
  /// bracket with nothing skipped.
  std::string ca_ts_note;
};

/// @brief How Transition::ca_ts_note begins when the sampled regimes are not monotone in Ca (a tumbling sample
/// above a swinging one): the reader of a bracket must know that samples inside it disagree.
inline constexpr std::string_view kRegimesNotMonotone = "regimes not monotone in Ca";

/// @brief True for an initially spherical capsule (a/b = 1). It does not tumble, so the seed's Ca* (the
/// band of a tumbling-to-swinging transition) does not apply to it: its min D12 falls below any threshold as
/// Ca -> 0 simply because a sphere at rest has D12 = 0 (with bending stiffness the sphere's level-3 min D12
/// is below 0.15 already at Ca = 0.03), which is no transition.
bool is_sphere(const Transition& t);

/// @brief Transition::level_answers as stored (transitions.level_answers, schema 5) and printed by
/// `capsim query table1 --format json`: {"ca_h": {"2": 0.2312, "4": 0.6031}, ...}, full precision; "" when empty.
std::string level_answers_json(const std::map<std::string, std::map<int, double>>& answers);
/// @brief The inverse of level_answers_json; "" or text that is not such an object reads as none.
std::map<std::string, std::map<int, double>> level_answers_from_json(const std::string& text);

/// @brief One finished case of a group.
struct Sample {
  double ca = 0;                        ///< capillary number
  std::optional<double> min_d12;        ///< min D12 over the last period
  std::optional<double> max_tau_min;    ///< max over the period of the minimum principal tension
  std::string case_id;                  ///< identity
  std::optional<double> min_d12_spread;      ///< min_D12_period_spread of its result (nullopt: not recorded)
  std::optional<double> max_tau_min_spread;  ///< max_tau_min_period_spread of its result
  std::optional<double> dt;                  ///< time step the case ran with
  std::string stop_test{diagnostics::kStopTestBoth};  ///< its time.stop_test (which answers its stop waited for)
  /// @brief The regime its result reports (results.regime, spelled as diagnostics::to_string: "tumbling",
  /// "swinging", "steady", "unknown", "kayaking", ...); "" when not recorded.
  std::string regime;
};

/// @brief One case of a campaign with its result, as the store reads it (the input of the grouping).
struct CaseSample {
  std::string case_id;                  ///< identity
  CaseParams params;                    ///< all case keys
  std::string status;                   ///< queued | running | done | unstable | failed
  std::optional<double> min_d12;        ///< from its result (done/unstable), else nullopt
  std::optional<double> max_tau_min;    ///< from its result, else nullopt
  std::optional<double> min_d12_spread, max_tau_min_spread, dt;  ///< from its result (Sample says what)
  std::string regime;                   ///< from its result (Sample::regime), else ""
};

/// @brief The cases of one group.
struct SampleGroup {
  Transition key;                       ///< group_key, law, aspect_ratio, skalak_C (-1 neo-hookean), mesh_level
  std::vector<Sample> samples;          ///< its done cases
  std::vector<double> case_ca;          ///< Ca of every case of the group, any status (a case that exists)
  CaseParams base;                      ///< one case of the group: the template of new cases
};

/// @brief Groups cases by GroupKey (groups in order of first appearance); a group with no done case is
/// still listed (empty samples). Cases that differ in numerics.kernel_precision or time.stop_test only share
/// a group (see GroupKey); a Ca done more than once gives one sample: the double one, then the one whose
/// stop test was "both". @throws
/// capsim::config::ConfigError for a case the solver rejects.
std::vector<SampleGroup> group_cases(const std::vector<CaseSample>& cases);

/// @brief Computes the transition row of one group from its samples (any order; status done only).
/// CaH with max tau_min < 0 at every sample: for a spheroid, ca_h_high bounds it (CaH below the smallest
/// sample); for a sphere nothing does (it is compressed below a CaL as well), so both bounds stay empty and
/// the note says why.
///
/// Ca_TS (ca_ts_low, ca_ts_high, ca_ts_note), the tumbling-to-swinging transition by the cases' own regimes:
/// of the samples in Ca order, only those whose regime is "tumbling" or "swinging" count; the others (steady,
/// unknown, the off-plane kayaking, rolling, ...) name neither side of an in-plane transition and are skipped,
/// the note listing them. Then
/// - tumbling below and swinging above one pair of adjacent samples: that pair is the bracket;
/// - every sample tumbles: no bracket, note "tumbles at every sampled Ca (a to b)"; every sample swings: no
///   bracket, note "swings from the smallest sampled Ca (a)"; none of either: note "no tumbling or swinging case";
/// - not monotone (a tumbling sample above a swinging one): when the smallest sample tumbles and the largest
///   swings, the outermost bracket, from the last tumbling sample below the first swinging one to the first
///   swinging sample above the last tumbling one: every sample below it tumbles and every one above it swings,
///   so it holds every change of regime sampled (a misnamed or bistable sample near the transition widens the
///   bracket instead of hiding it); otherwise (swinging at the smallest sample, or tumbling at the largest) no
///   bracket. Either way the note begins with kRegimesNotMonotone and names the first swinging and the last
///   tumbling sample.
/// A sphere (is_sphere) gets nothing: it does not tumble.
Transition analyse_group(Transition key, std::vector<Sample> samples, double d12_threshold);

/// @brief analyse_group of every group, with @p method recorded.
std::vector<Transition> analyse_groups(const std::vector<SampleGroup>& groups, double d12_threshold,
                                       const std::string& method);

}  // namespace capsim::campaign
