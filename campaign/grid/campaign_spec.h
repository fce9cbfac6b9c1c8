#pragma once
/// @file
/// @brief A campaign file (TOML) parsed and validated strictly; see schemas/campaign_keys.md.

#include <string>
#include <vector>

#include "campaign/grid/case_keys.h"
#include "campaign/grid/case_params.h"

namespace capsim::campaign {

/// @brief One axis of a [[grid]] block: a dotted case key and its values (already validated).
struct GridAxis {
  std::string key;            ///< dotted case key, e.g. "flow.capillary_number"
  std::vector<Value> values;  ///< distinct values in file order
};

/// @brief One [[grid]] block: the Cartesian product of its axes.
struct GridBlock {
  std::vector<GridAxis> axes;  ///< in file order
};

/// @brief The [analysis] section.
struct AnalysisSpec {
  double d12_threshold = 0.05;  ///< min D12 below this marks the transition band (Ca*)
  bool adaptive = false;        ///< add cases automatically to bracket Ca* edges and CaH
  double ca_tolerance = 0.005;  ///< adaptive mode stops when brackets are narrower than this
  int max_cases = 200;          ///< adaptive mode never adds more than this many cases per campaign
  int max_rounds = 10;          ///< adaptive refinement rounds
  /// @brief Multi-fidelity: [scan, answer] or [scan, answer, check] mesh levels (empty: off). The grid runs
  /// on the scan level, the answer level starts from the scan's brackets (adaptive mode bisects there), the
  /// check level re-runs the final brackets for the mesh error (campaign/README.md, "Multi-fidelity").
  std::vector<int> levels;
  bool dt_check = false;        ///< re-run one bracketing case per cell with dt/2 (the time-step error)
  /// @brief numerics.kernel_precision of the check level's cases ("": the campaign's, as every other level).
  /// "mixed" halves the cost of a level-4 case (results/benchmarks.md, "Mixed precision") for a change of
  /// ~1e-6 in its answers, far below the level 3 → 4 differences it measures. A case's precision says how it
  /// was computed, not what: the analysis puts both precisions of a group into one (transitions.h group_key).
  std::string check_precision;
  /// @brief Each case the answer and check levels add stops on the answer it is for (time.stop_test: min D12
  /// for a Ca* edge, max τmin for CaH, both where a Ca serves both; analysis/multi_fidelity.h). Off by default;
  /// switched on for a campaign that has run, it changes only the cases added afterwards (a Ca that exists is
  /// not proposed again, whatever its stop test).
  bool stop_for_answer = false;
};

/// @brief A validated campaign.
struct CampaignSpec {
  std::string name;         ///< [campaign] name (required; identifies the campaign in the database)
  std::string description;  ///< [campaign] description
  std::string source;       ///< file it was read from
  CaseParams defaults;      ///< case keys shared by all cases ([defaults] over the built-in defaults)
  std::vector<GridBlock> grids;  ///< [[grid]] blocks
  AnalysisSpec analysis;    ///< [analysis]
  /// @brief Canonical JSON of the whole specification (stored with the campaign).
  std::string to_json() const;
};

/// @brief Parses campaign text; @p source names it in messages. @throws BadInput ("SOURCE: key: problem").
CampaignSpec parse_campaign(const std::string& text, const std::string& source);

/// @brief Reads and parses a campaign file. @throws BadInput (missing file, syntax, validation).
CampaignSpec load_campaign_file(const std::string& path);

/// @brief The cases of a campaign: union of its grid blocks over the defaults, duplicates (same identity)
/// removed, in first-appearance order.
std::vector<CaseParams> expand_grid(const CampaignSpec& spec);

}  // namespace capsim::campaign
