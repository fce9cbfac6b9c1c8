#pragma once
/// @file
/// @brief The adaptive mode's refinement: which capillary numbers to add so the Ca* edges and the CaH
/// bracket of each group shrink below the tolerance. Pure: the caller adds the cases to the store.

#include <algorithm>
#include <cmath>
#include <vector>

#include "campaign/analysis/transitions.h"

namespace capsim::campaign {

/// @brief @p x rounded to the decimal quantum of new capillary numbers: 10^-k, the largest below
/// @p tolerance / 2 (exact decimals: 0.0275, not 0.027500000000000004).
double quantise_ca(double x, double tolerance);

/// @brief Whether two capillary numbers are the same sample (equal to 1e-12 relative): the one test every
/// phase of the analysis uses to find a case at a Ca.
inline bool same_ca(double a, double b) { return std::fabs(a - b) < 1e-12 * std::max(1.0, std::fabs(b)); }

/// @brief Capillary numbers to add to a group with transition @p t so its Ca* edges and CaH bracket shrink
/// below @p tolerance; values are rounded to a decimal quantum below the tolerance and never repeat a Ca in
/// @p existing (the group's cases, whatever their status) or each other.
std::vector<double> propose_refinement(const Transition& t, std::vector<Sample> samples, double tolerance,
                                       const std::vector<double>& existing = {});

/// @brief Narrowest bracket worth making, per answer (multi-fidelity: max(ca_tolerance, numerical error)).
struct BracketTolerances {
  double ca_star_low = 0, ca_star_high = 0, ca_h = 0;
  /// Without a Ca* band, bisect around the smallest min D12 (to find a band the samples step over).
  bool bracket_minimum = true;
};

/// @brief The same with a tolerance per answer; @p tolerance sets the decimal quantum of new values.
std::vector<double> propose_refinement(const Transition& t, std::vector<Sample> samples, double tolerance,
                                       const BracketTolerances& per_answer, const std::vector<double>& existing);

/// @brief One adaptive round: for each group (analysed with @p d12_threshold), the new cases its proposals
/// give, at most @p budget in all (group order, then proposal order). Every returned case is new: a Ca
/// whose case already exists in the group is not proposed.
std::vector<CaseParams> refinement_round(const std::vector<SampleGroup>& groups, double d12_threshold,
                                         double tolerance, int budget);

}  // namespace capsim::campaign
