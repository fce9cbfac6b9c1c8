#pragma once
/// @file
/// @brief Critical capillary numbers from finished cases: the Ca* interval (sampled Ca with
/// min D12 < threshold, the seed's Table 1 criterion) and CaH (zero of max tau_min, interpolated linearly
/// between the bracketing samples), plus the refinement points of the adaptive mode.

#include <optional>
#include <string>
#include <vector>

#include "campaign/store/store.h"

namespace capsim::campaign {

/// @brief One finished case of a (law, a/b, C, level) group.
struct Sample {
  double ca = 0;                        ///< capillary number
  std::optional<double> min_d12;        ///< min D12 over the last period
  std::optional<double> max_tau_min;    ///< max over the period of the minimum principal tension
  std::string case_id;                  ///< identity
};

/// @brief Computes the transition row of one group from its samples (any order; status done only).
Transition analyse_group(Transition key, std::vector<Sample> samples, double d12_threshold);

/// @brief Capillary numbers to add so the Ca* edges and the CaH bracket shrink below @p tolerance
/// (adaptive mode); values are rounded to a decimal quantum below the tolerance and never repeat a sample.
std::vector<double> propose_refinement(const Transition& t, std::vector<Sample> samples, double tolerance);

/// @brief A group of samples with its key fields filled in a Transition.
struct SampleGroup {
  Transition key;               ///< law, aspect_ratio, skalak_C (-1 for neo-hookean), mesh_level
  std::vector<Sample> samples;  ///< done cases of the group
  std::string some_case_id;     ///< any case of the group (a template for new cases)
};

/// @brief Loads the done cases of a campaign grouped by (law, a/b, C, level); groups with no done case
/// are still listed (empty samples) when the campaign has cases in them.
std::vector<SampleGroup> load_groups(Db& db, std::int64_t campaign_id);

/// @brief Recomputes and stores the transitions of a campaign; returns them.
std::vector<Transition> analyse_campaign(Store& store, std::int64_t campaign_id, double d12_threshold,
                                         const std::string& method);

}  // namespace capsim::campaign
