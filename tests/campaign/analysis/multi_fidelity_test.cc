// The phases of a multi-fidelity campaign as pure functions of the grouped cases: what the answer level
// needs from the scan, where it re-brackets, when refinement stops, what the check level and dt check run.
#include "campaign/analysis/multi_fidelity.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <variant>

#include "campaign/analysis/refinement.h"

namespace capsim::campaign {
namespace {

CaseSample fake(int level, double ca, const std::function<double(double)>& tau, const std::string& status = "done",
                double dt = 0, const std::function<double(double)>& d12 = nullptr) {
  CaseParams p = CaseParams::defaults();
  p.set("capsule.law", std::string("neo-hookean"));
  p.set("capsule.aspect_ratio", 0.5);
  p.set("mesh.level", std::int64_t{level});
  p.set("flow.capillary_number", ca);
  if (dt > 0) p.set("time.dt", dt);
  CaseSample c;
  c.case_id = "L";
  c.case_id += std::to_string(level) + '-' + std::to_string(ca) + '-' + std::to_string(dt);
  c.params = p;
  c.status = status;
  if (status == "done") {
    c.min_d12 = d12 ? d12(ca) : 0.3;  // by default no Ca* band: only CaH matters
    c.max_tau_min = tau(ca);
    c.dt = dt > 0 ? dt : 0.02;
  }
  return c;
}

// The same case on a sphere (a/b = 1): analyse_group gives an all-compressed sphere no CaH bound.
CaseSample sphere(CaseSample c) {
  c.params.set("capsule.aspect_ratio", 1.0);
  return c;
}

std::vector<double> ca_at(const std::vector<CaseParams>& cases, int level) {
  std::vector<double> out;
  for (const auto& p : cases) {
    EXPECT_EQ(p.mesh_level(), level);
    out.push_back(p.capillary_number());
  }
  std::sort(out.begin(), out.end());
  return out;
}

const MultiFidelityOptions kOptions{{2, 3}, 0.05, 0.005, true, false, ""};

// Level 2: CaH 0.23 (the oblate NH capsule's coarse value); level 3: CaH 0.60.
double tau2(double ca) { return 0.23 - ca; }
double tau3(double ca) { return 0.60 - ca; }

TEST(MultiFidelity, TheAnswerLevelStartsFromTheScanBrackets) {
  std::vector<CaseSample> cases;
  for (double ca : {0.1, 0.2, 0.5, 1.0}) cases.push_back(fake(2, ca, tau2));
  const auto add = answer_level_round(group_cases(cases), kOptions, 100);
  // The scan's CaH bracket (0.2, 0.5), and the smallest min D12 (no Ca* band; every min D12 equal: the first).
  EXPECT_EQ(ca_at(add, 3), (std::vector<double>{0.1, 0.2, 0.5}));
}

TEST(MultiFidelity, AScanMinimumNearTheThresholdSeedsItsNeighbours) {
  // The oblate capsule with κ_b = 1e-3 on level 2: no sample below 0.05, the smallest min D12 0.072 at Ca 0.08
  // and 0.074 at 0.1, with the band between them. The answer level starts from both neighbours of the minimum.
  const auto d12 = [](double ca) { return ca < 0.07 ? 0.2 : ca < 0.09 ? 0.072 : ca < 0.2 ? 0.074 : 0.36; };
  const auto tau = [](double) { return 0.01; };  // CaH above the range: its bracket adds the largest Ca
  std::vector<CaseSample> cases;
  for (double ca : {0.06, 0.08, 0.1, 0.3}) cases.push_back(fake(2, ca, tau, "done", 0, d12));
  auto add = answer_level_round(group_cases(cases), kOptions, 100);
  EXPECT_EQ(ca_at(add, 3), (std::vector<double>{0.06, 0.08, 0.1, 0.3}));
  // A minimum far above the threshold (0.3 everywhere but 0.2 at 0.08) seeds only itself.
  cases.clear();
  const auto flat = [](double ca) { return ca > 0.07 && ca < 0.09 ? 0.2 : 0.3; };
  for (double ca : {0.06, 0.08, 0.1, 0.3}) cases.push_back(fake(2, ca, tau, "done", 0, flat));
  add = answer_level_round(group_cases(cases), kOptions, 100);
  EXPECT_EQ(ca_at(add, 3), (std::vector<double>{0.08, 0.3}));
}

TEST(MultiFidelity, TheAnswerLevelReBracketsWhereTheScanWasWrong) {
  std::vector<CaseSample> cases;
  for (double ca : {0.1, 0.2, 0.5, 1.0}) cases.push_back(fake(2, ca, tau2));
  for (double ca : {0.1, 0.2}) cases.push_back(fake(3, ca, tau3));  // both above 0 at level 3
  cases.push_back(fake(3, 0.5, tau3, "queued"));                     // exists: not proposed again
  auto add = answer_level_round(group_cases(cases), kOptions, 100);
  EXPECT_TRUE(add.empty()) << "0.5 is queued: nothing is known yet beyond 0.2 on level 3";
  cases.pop_back();
  cases.push_back(fake(3, 0.5, tau3));
  add = answer_level_round(group_cases(cases), kOptions, 100);
  // CaH lies above 0.5 on level 3: the next scan Ca outwards.
  EXPECT_EQ(ca_at(add, 3), (std::vector<double>{1.0}));
  cases.push_back(fake(3, 1.0, tau3));
  cases.push_back(fake(3, 1.5, tau3, "failed"));
  // Bracketed now (0.5, 1.0): bisection (false position clamped to the middle half: 0.625).
  add = answer_level_round(group_cases(cases), kOptions, 100);
  EXPECT_EQ(ca_at(add, 3), (std::vector<double>{0.625}));
}

TEST(MultiFidelity, AllCompressedOnTheAnswerLevelProbesBothWays) {
  // The NH sphere: max τmin < 0 below CaL ≈ 0.42 and above CaH ≈ 0.62, > 0 between (level 3); the coarse
  // scan sees no positive value at all. One answer-level sample at 0.4 (τ < 0) does not say on which side
  // of the positive band it lies: the round must look above it too, not only below.
  const auto tau_sphere = [](double ca) { return (ca - 0.42) * (0.62 - ca); };
  const auto tau_coarse = [](double) { return -0.01; };
  std::vector<CaseSample> cases;
  for (double ca : {0.4, 0.6, 0.8}) cases.push_back(sphere(fake(2, ca, tau_coarse)));
  cases.push_back(sphere(fake(3, 0.4, tau_sphere)));
  auto add = answer_level_round(group_cases(cases), kOptions, 100);
  const auto proposed = ca_at(add, 3);
  EXPECT_TRUE(std::find(proposed.begin(), proposed.end(), 0.6) != proposed.end()) << "the next scan Ca above";
  // With 0.6 (τ > 0) and 0.8 (τ < 0) in, CaH is bracketed by the upper crossing and bisected there.
  for (double ca : proposed) cases.push_back(sphere(fake(3, ca, tau_sphere)));
  add = answer_level_round(group_cases(cases), kOptions, 100);
  cases.push_back(sphere(fake(3, 0.8, tau_sphere)));
  add = answer_level_round(group_cases(cases), kOptions, 100);
  for (double ca : ca_at(add, 3)) {
    EXPECT_GT(ca, 0.6);
    EXPECT_LT(ca, 0.8);
  }
  EXPECT_FALSE(add.empty());
}

TEST(MultiFidelity, AllCompressedProbesOneStepBelowTheScanAndStops) {
  // The NH sphere with κ_b = 1e-2: max τmin < 0 at every Ca, tending to 0 from below as Ca -> 0. The round
  // looks one step (÷1.5) below the scan's range and no further: walking down by ÷1.5 finds nothing.
  const auto tau = [](double ca) { return -0.1 * ca; };
  const auto d12 = [](double ca) { return 1.0 - ca; };  // smallest at the largest Ca: it seeds 0.8 only
  std::vector<CaseSample> cases;
  for (double ca : {0.4, 0.6, 0.8}) cases.push_back(sphere(fake(2, ca, tau, "done", 0, d12)));
  // The scan alone: its smallest compressed Ca seeds the answer level (no CaH bound stands for it on a sphere).
  auto add = answer_level_round(group_cases(cases), kOptions, 100);
  const auto seeded = ca_at(add, 3);
  EXPECT_TRUE(std::find(seeded.begin(), seeded.end(), 0.4) != seeded.end());
  for (double ca : {0.4, 0.6, 0.8}) cases.push_back(sphere(fake(3, ca, tau, "done", 0, d12)));
  add = answer_level_round(group_cases(cases), kOptions, 100);
  EXPECT_EQ(ca_at(add, 3), (std::vector<double>{0.267}));
  cases.push_back(sphere(fake(3, 0.267, tau, "done", 0, d12)));
  add = answer_level_round(group_cases(cases), kOptions, 100);
  EXPECT_TRUE(add.empty()) << "already one step below the scan's smallest Ca 0.4: " << add.size() << " proposed";
}

TEST(MultiFidelity, RefinementStopsAtTheNumericalError) {
  // The level-2 and level-3 values differ by 0.37 in τ (slope −1): the CaH error is 0.37, so a bracket of
  // width 0.1 is already narrower than what the mesh resolves; with a level 2 close to level 3 it is not.
  for (double offset : {0.37, 0.001}) {
    std::vector<CaseSample> cases;
    auto t2 = [offset](double ca) { return 0.60 + offset - ca; };
    for (double ca : {0.1, 0.2, 0.5, 1.0}) cases.push_back(fake(2, ca, t2));
    for (double ca : {0.1, 0.2, 0.5, 0.55, 0.65, 1.0}) cases.push_back(fake(3, ca, tau3));
    const auto add = answer_level_round(group_cases(cases), kOptions, 100);
    if (offset > 0.1) {
      EXPECT_TRUE(add.empty()) << "bracket 0.1 < error 0.37: refining it buys nothing";
    } else {
      ASSERT_EQ(add.size(), 1u);
      EXPECT_GT(add[0].capillary_number(), 0.55);
      EXPECT_LT(add[0].capillary_number(), 0.65);
    }
  }
}

// With dt_check, a cell is refined only once its dt check exists: until then its error lacks the dt part, and
// the rest alone may be far below it. The dt check runs once per cell, at the CaH-low case of the time.
TEST(MultiFidelity, RefinementWaitsForTheCellsDtCheck) {
  for (double dt_shift : {0.1, 0.001}) {
    std::vector<CaseSample> cases;
    auto t2 = [](double ca) { return 0.601 - ca; };  // level 2 close to level 3: a mesh error of 0.001
    for (double ca : {0.1, 0.2, 0.5, 1.0}) cases.push_back(fake(2, ca, t2));
    for (double ca : {0.1, 0.2, 0.5, 0.55, 0.65, 1.0}) cases.push_back(fake(3, ca, tau3));
    MultiFidelityOptions o = kOptions;
    ASSERT_EQ(answer_level_round(group_cases(cases), o, 100).size(), 1u) << "without dt_check it refines now";
    o.dt_check = true;
    EXPECT_TRUE(answer_level_round(group_cases(cases), o, 100).empty()) << "waits for the dt check";
    const auto dt = dt_check_cases(group_cases(cases), o, 100);
    ASSERT_EQ(dt.size(), 1u);
    EXPECT_DOUBLE_EQ(dt[0].capillary_number(), 0.55);
    cases.push_back(fake(3, 0.55, [&](double ca) { return tau3(ca) + dt_shift; }, "done", 0.01));
    const auto add = answer_level_round(group_cases(cases), o, 100);
    if (dt_shift > 0.05) {
      // dt part |Δτ| / (1 − 1/4) = 0.13 in τ, 0.13 in Ca at slope −1: wider than the bracket 0.1.
      EXPECT_TRUE(add.empty()) << "bracket 0.1 < dt error 0.13: refining it buys nothing";
    } else {
      ASSERT_EQ(add.size(), 1u);
      EXPECT_GT(add[0].capillary_number(), 0.55);
      EXPECT_LT(add[0].capillary_number(), 0.65);
      // The bracket moves (CaH-low 0.6 now); the cell keeps its one dt check.
      cases.push_back(fake(3, 0.6, tau3));
      EXPECT_TRUE(dt_check_cases(group_cases(cases), o, 100).empty()) << "one dt check per cell";
    }
  }
  // A cell with nothing for the dt check to re-run (no CaH-low, no Ca*-low: only a minimum of min D12 near the
  // threshold to bracket) does not wait for it.
  const auto d12 = [](double ca) { return ca < 0.07 ? 0.2 : ca < 0.09 ? 0.072 : ca < 0.2 ? 0.074 : 0.36; };
  const auto tension = [](double) { return -0.01; };  // compressed throughout: no CaH-low
  std::vector<CaseSample> cases;
  for (double ca : {0.06, 0.08, 0.1, 0.3}) {
    cases.push_back(fake(2, ca, tension, "done", 0, d12));
    cases.push_back(fake(3, ca, tension, "done", 0, d12));
  }
  MultiFidelityOptions o = kOptions;
  o.dt_check = true;
  EXPECT_TRUE(dt_check_cases(group_cases(cases), o, 100).empty());
  const auto add = ca_at(answer_level_round(group_cases(cases), o, 100), 3);
  EXPECT_TRUE(std::any_of(add.begin(), add.end(), [](double ca) { return ca > 0.08 && ca < 0.1; }))
      << "the minimum's bracket (0.08, 0.1) is refined";
}

TEST(MultiFidelity, TheCheckLevelRunsTheFinalBrackets) {
  std::vector<CaseSample> cases;
  for (double ca : {0.1, 0.2, 0.5, 1.0}) cases.push_back(fake(2, ca, tau2));
  for (double ca : {0.1, 0.55, 0.65, 1.0}) cases.push_back(fake(3, ca, tau3));
  MultiFidelityOptions o = kOptions;
  EXPECT_TRUE(check_level_cases(group_cases(cases), o, 100).empty()) << "no check level";
  o.levels = {2, 3, 4};
  EXPECT_EQ(ca_at(check_level_cases(group_cases(cases), o, 100), 4), (std::vector<double>{0.55, 0.65}));
  cases.push_back(fake(4, 0.55, tau3, "queued"));
  EXPECT_EQ(ca_at(check_level_cases(group_cases(cases), o, 100), 4), (std::vector<double>{0.65}));
  EXPECT_TRUE(check_level_cases(group_cases(cases), o, 0).empty()) << "no budget";
}

// [analysis] check_precision = "mixed": the check level's new cases carry it, and a check case in either
// precision counts as the check level's sample at its Ca (one group: group_key leaves the precision out).
// Where a Ca was done in both precisions the double sample is the one used.
TEST(MultiFidelity, TheCheckLevelInMixedPrecisionJoinsTheDoubleGroup) {
  const auto mixed = [](CaseSample c) {
    c.params.set("numerics.kernel_precision", std::string("mixed"));
    c.case_id += "-mixed";
    return c;
  };
  std::vector<CaseSample> cases;
  for (double ca : {0.1, 0.2, 0.5, 1.0}) cases.push_back(fake(2, ca, tau2));
  for (double ca : {0.1, 0.55, 0.65, 1.0}) cases.push_back(fake(3, ca, tau3));
  MultiFidelityOptions o = kOptions;
  o.levels = {2, 3, 4};
  o.check_precision = "mixed";
  const auto add = check_level_cases(group_cases(cases), o, 100);
  ASSERT_EQ(ca_at(add, 4), (std::vector<double>{0.55, 0.65}));
  for (const auto& p : add) {
    ASSERT_TRUE(p.values().contains("numerics.kernel_precision"));
    EXPECT_EQ(std::get<std::string>(p.values().at("numerics.kernel_precision")), "mixed");
  }
  // A double level-4 case at 0.55 (say from before the option) and a mixed one at 0.65: one level-4 group,
  // nothing more to run.
  cases.push_back(fake(4, 0.55, tau3));
  cases.push_back(mixed(fake(4, 0.65, tau3)));
  const auto groups = group_cases(cases);
  EXPECT_EQ(std::count_if(groups.begin(), groups.end(), [](const SampleGroup& g) { return g.key.mesh_level == 4; }), 1);
  EXPECT_TRUE(check_level_cases(groups, o, 100).empty());
  // Both precisions done at one Ca: one sample, the double one, whichever comes first.
  for (const bool double_first : {true, false}) {
    std::vector<CaseSample> both = cases;
    CaseSample d = fake(4, 0.65, [](double) { return -1.0; }), m = mixed(fake(4, 0.65, [](double) { return 1.0; }));
    both.pop_back();
    both.push_back(double_first ? d : m);
    both.push_back(double_first ? m : d);
    for (const auto& g : group_cases(both))
      if (g.key.mesh_level == 4) {
        ASSERT_EQ(g.samples.size(), 2u) << "one sample per Ca";
        for (const auto& smp : g.samples) {
          if (same_ca(smp.ca, 0.65)) {
            EXPECT_EQ(*smp.max_tau_min, -1.0) << "the double sample, double first " << double_first;
          }
        }
      }
  }
}

// The scheduler's top-up: the rounds go on while cases run only with a check level and only while every
// running case is a check-level one.
TEST(MultiFidelity, RoundsOverlapOnlyWhileCheckLevelCasesRun) {
  MultiFidelityOptions o = kOptions;
  EXPECT_FALSE(rounds_may_overlap(o, {3})) << "no check level";
  o.levels = {2, 3, 4};
  EXPECT_TRUE(rounds_may_overlap(o, {4}));
  EXPECT_TRUE(rounds_may_overlap(o, {4, 4}));
  EXPECT_TRUE(rounds_may_overlap(o, {})) << "nothing running: the ordinary round";
  EXPECT_FALSE(rounds_may_overlap(o, {4, 3})) << "an answer-level case may still move a bracket";
  EXPECT_FALSE(rounds_may_overlap(o, {2}));
}

// Where the check level's values at the final bracket lie on one side of 0 (its CaH is outside the bracket),
// the answer level's next sample outwards is run on the check level, one at a time, until it brackets CaH.
TEST(MultiFidelity, TheCheckLevelGoesOutwardsUntilItBracketsItsAnswer) {
  const auto tau4 = [](double ca) { return 0.72 - ca; };  // level 4: CaH 0.72, past level 3's (0.55, 0.65)
  std::vector<CaseSample> cases;
  for (double ca : {0.1, 0.2, 0.5, 1.0}) cases.push_back(fake(2, ca, tau2));
  for (double ca : {0.1, 0.55, 0.65, 0.8, 1.0}) cases.push_back(fake(3, ca, tau3));
  MultiFidelityOptions o = kOptions;
  o.levels = {2, 3, 4};
  for (double ca : {0.55, 0.65}) cases.push_back(fake(4, ca, tau4));
  EXPECT_EQ(ca_at(check_level_cases(group_cases(cases), o, 100), 4), (std::vector<double>{0.8}));
  cases.push_back(fake(4, 0.8, tau4, "running"));
  EXPECT_TRUE(check_level_cases(group_cases(cases), o, 100).empty()) << "waits for the case it needs";
  cases.back() = fake(4, 0.8, tau4);
  EXPECT_TRUE(check_level_cases(group_cases(cases), o, 100).empty()) << "bracketed by 0.65 and 0.8";
  // Still on one side at 0.8 (level-4 CaH 0.9): the next one, 1.0.
  std::vector<CaseSample> further(cases.begin(), cases.end() - 3);
  const auto tau4b = [](double ca) { return 0.9 - ca; };
  for (double ca : {0.55, 0.65, 0.8}) further.push_back(fake(4, ca, tau4b));
  EXPECT_EQ(ca_at(check_level_cases(group_cases(further), o, 100), 4), (std::vector<double>{1.0}));
  // Below the bracket (level-4 CaH 0.3): the answer level's sample below 0.55 is 0.1.
  std::vector<CaseSample> below(cases.begin(), cases.end() - 3);
  for (double ca : {0.55, 0.65}) below.push_back(fake(4, ca, [](double ca) { return 0.3 - ca; }));
  EXPECT_EQ(ca_at(check_level_cases(group_cases(below), o, 100), 4), (std::vector<double>{0.1}));
  // A check level that brackets at the final bracket needs nothing more.
  std::vector<CaseSample> inside(cases.begin(), cases.end() - 3);
  for (double ca : {0.55, 0.65}) inside.push_back(fake(4, ca, [](double ca) { return 0.62 - ca; }));
  EXPECT_TRUE(check_level_cases(group_cases(inside), o, 100).empty());
}

TEST(MultiFidelity, TheDtCheckHalvesTheStepOfTheCaHLowCase) {
  std::vector<CaseSample> cases;
  for (double ca : {0.1, 0.2, 0.5, 1.0}) cases.push_back(fake(2, ca, tau2));
  for (double ca : {0.1, 0.2, 0.5, 0.55, 0.65, 1.0}) cases.push_back(fake(3, ca, tau3));
  const auto add = dt_check_cases(group_cases(cases), kOptions, 100);
  ASSERT_EQ(add.size(), 1u);
  EXPECT_EQ(add[0].mesh_level(), 3);
  EXPECT_DOUBLE_EQ(add[0].capillary_number(), 0.55);
  EXPECT_NE(add[0].canonical().find("time.dt=0.01"), std::string::npos) << add[0].canonical();
  cases.push_back(fake(3, 0.55, tau3, "done", 0.01));
  EXPECT_TRUE(dt_check_cases(group_cases(cases), kOptions, 100).empty()) << "it exists";
  // The dt_check case does not disturb the answer level's rounds (it is another group).
  EXPECT_TRUE(answer_level_round(group_cases(cases), MultiFidelityOptions{{2, 3}, 0.05, 0.005, false, false, ""}, 100).empty());
}

// time.stop_test of a new case: "(unset)" where the key is absent (the default "both", written nowhere, so the
// identity is that of a case from before the key).
std::string stop_of(const CaseParams& p) {
  const auto it = p.values().find("time.stop_test");
  return it == p.values().end() ? "(unset)" : std::get<std::string>(it->second);
}

std::map<double, std::string> stops_by_ca(const std::vector<CaseParams>& cases) {
  std::map<double, std::string> out;
  for (const auto& p : cases) out[p.capillary_number()] = stop_of(p);
  return out;
}

// [analysis] stop_for_answer: each case the answer and check levels add stops on the answer it is for. A Ca*
// band at [0.03, 0.05] and CaH in (0.2, 0.5) on the scan level.
TEST(MultiFidelity, StopForAnswerGivesEachNewCaseTheStopTestOfItsAnswer) {
  const auto d12 = [](double ca) { return ca >= 0.029 && ca <= 0.051 ? 0.03 : 0.2; };
  const auto tau = [](double ca) { return 0.3 - ca; };
  std::vector<CaseSample> cases;
  for (double ca : {0.01, 0.02, 0.03, 0.05, 0.06, 0.2, 0.5, 1.0}) cases.push_back(fake(2, ca, tau, "done", 0, d12));
  MultiFidelityOptions o = kOptions;
  using Stops = std::map<double, std::string>;
  EXPECT_EQ(stops_by_ca(answer_level_round(group_cases(cases), o, 100)),
            (Stops{{0.02, "(unset)"}, {0.03, "(unset)"}, {0.05, "(unset)"}, {0.06, "(unset)"}, {0.2, "(unset)"},
                   {0.5, "(unset)"}}))
      << "off: every case keeps its template's stop";
  o.stop_for_answer = true;
  EXPECT_EQ(stops_by_ca(answer_level_round(group_cases(cases), o, 100)),
            (Stops{{0.02, "min_D12"}, {0.03, "min_D12"}, {0.05, "min_D12"}, {0.06, "min_D12"}, {0.2, "max_tau_min"},
                   {0.5, "max_tau_min"}}));
  // A Ca that brackets both answers waits for both (CaH in (0.03, 0.05) here).
  std::vector<CaseSample> overlap;
  for (double ca : {0.01, 0.02, 0.03, 0.05, 0.06}) overlap.push_back(fake(2, ca, [](double c) { return 0.04 - c; },
                                                                             "done", 0, d12));
  EXPECT_EQ(stops_by_ca(answer_level_round(group_cases(overlap), o, 100)),
            (Stops{{0.02, "min_D12"}, {0.03, "(unset)"}, {0.05, "(unset)"}, {0.06, "min_D12"}}));

  // The answer level has the seeds (level 3 = level 2: no mesh error): the refinement's bisections get the
  // stop of the bracket they halve, whatever the stop of the cases that made it.
  auto with_stop = [](CaseSample c, const std::string& stop) {
    c.params.set("time.stop_test", stop);
    return c;
  };
  for (double ca : {0.02, 0.03, 0.05, 0.06}) cases.push_back(with_stop(fake(3, ca, tau, "done", 0, d12), "min_D12"));
  for (double ca : {0.2, 0.5}) cases.push_back(with_stop(fake(3, ca, tau, "done", 0, d12), "max_tau_min"));
  const auto refine = answer_level_round(group_cases(cases), o, 100);
  const Stops stops = stops_by_ca(refine);
  ASSERT_EQ(stops.size(), 3u);
  EXPECT_EQ(stops.at(0.025), "min_D12");
  EXPECT_EQ(stops.at(0.055), "min_D12");
  EXPECT_EQ(std::prev(stops.end())->second, "max_tau_min") << "the CaH bisection, in (0.2, 0.5)";
  // The dt check halves the step of the CaH-low case and keeps its stop; the check level's brackets get theirs.
  const auto dt = dt_check_cases(group_cases(cases), o, 100);
  ASSERT_EQ(dt.size(), 1u);
  EXPECT_DOUBLE_EQ(dt[0].capillary_number(), 0.2);
  EXPECT_EQ(stop_of(dt[0]), "max_tau_min");
  o.levels = {2, 3, 4};
  EXPECT_EQ(stops_by_ca(check_level_cases(group_cases(cases), o, 100)),
            (Stops{{0.02, "min_D12"}, {0.03, "min_D12"}, {0.05, "min_D12"}, {0.06, "min_D12"}, {0.2, "max_tau_min"},
                   {0.5, "max_tau_min"}}));
}

// The stop test says which answer a case waited for, not what it computes: cases that differ in it only share a
// group (one sample per Ca: the one that waited for both, then the first), and it is in the identity only when set.
TEST(MultiFidelity, CasesThatDifferInTheirStopTestShareAGroup) {
  const auto stopping = [](CaseSample c, const std::string& stop, double tau) {
    c.params.set("time.stop_test", stop);
    c.case_id += "-" + stop;
    c.max_tau_min = tau;
    return c;
  };
  const CaseSample plain = fake(3, 0.5, [](double) { return -1.0; });
  EXPECT_EQ(GroupKey::of(plain.params).str(), GroupKey::of(stopping(plain, "min_D12", 0).params).str());
  EXPECT_NE(plain.params.identity("2"), stopping(plain, "min_D12", 0).params.identity("2"));
  EXPECT_EQ(plain.params.identity("2"), stopping(plain, "both", 0).params.identity("2"))
      << "the default is not in the identity";
  for (const bool plain_first : {true, false}) {
    const CaseSample other = stopping(plain, "max_tau_min", 1.0);
    const auto groups = group_cases(plain_first ? std::vector<CaseSample>{plain, other}
                                                : std::vector<CaseSample>{other, plain});
    ASSERT_EQ(groups.size(), 1u);
    ASSERT_EQ(groups[0].samples.size(), 1u) << "one sample per Ca";
    EXPECT_EQ(*groups[0].samples[0].max_tau_min, -1.0) << "the one that waited for both, plain first " << plain_first;
    EXPECT_EQ(groups[0].samples[0].stop_test, "both");
  }
  const auto one = group_cases({stopping(plain, "min_D12", 0.5)});
  ASSERT_EQ(one[0].samples.size(), 1u);
  EXPECT_EQ(one[0].samples[0].stop_test, "min_D12");
}

TEST(MultiFidelity, BisectionsSavedCountsWhatRefinementToTheToleranceWouldStillRun) {
  Transition t;
  EXPECT_EQ(bisections_saved(t, 0.005), 0) << "no bracket, nothing saved";
  t.ca_h_low = 0.5;
  t.ca_h_high = 0.54;  // 0.04 / 0.005 = 8: three more halvings
  EXPECT_EQ(bisections_saved(t, 0.005), 3);
  t.ca_star_below = 0.02;
  t.ca_star_low = 0.025;  // already at the tolerance: none
  t.ca_star_high = 0.05;
  t.ca_star_above = 0.06;  // 0.01 / 0.005 = 2: one
  EXPECT_EQ(bisections_saved(t, 0.005), 4);
  t.ca_h_high = 0.541;  // 8.2: four
  EXPECT_EQ(bisections_saved(t, 0.005), 5);
}

}  // namespace
}  // namespace capsim::campaign
