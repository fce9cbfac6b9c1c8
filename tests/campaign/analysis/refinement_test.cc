// The adaptive round is a pure function of the grouped cases: it proposes only cases that do not exist.
#include <gtest/gtest.h>

#include <cmath>

#include "campaign/analysis/group_key.h"
#include "campaign/analysis/refinement.h"
#include "campaign/analysis/transitions.h"

namespace capsim::campaign {
namespace {

CaseSample fake_case(double ca, const std::string& status, double dt = 0) {
  CaseParams p = CaseParams::defaults();
  p.set("capsule.law", std::string("neo-hookean"));
  p.set("capsule.aspect_ratio", 2.0);
  p.set("mesh.level", std::int64_t{1});
  p.set("flow.capillary_number", ca);
  if (dt > 0) p.set("time.dt", dt);
  // The fake worker's truth for a/b >= 1 (tests/campaign/fake_worker.sh): Ca* band (0.165, 0.285), CaH 0.35.
  std::optional<double> d12, tau;
  if (status == "done") {
    d12 = 0.02 + 0.5 * std::fabs(ca - 0.225);
    tau = 0.35 - ca;
  }
  CaseSample c;
  c.case_id = "id" + std::to_string(ca) + "-" + std::to_string(dt);
  c.params = p;
  c.status = status;
  c.min_d12 = d12;
  c.max_tau_min = tau;
  return c;
}

TEST(Refinement, ExistingCasesAreNotProposedAgain) {
  std::vector<CaseSample> cases;
  for (double ca : {0.1, 0.2, 0.3, 0.4}) cases.push_back(fake_case(ca, "done"));
  auto groups = group_cases(cases);
  ASSERT_EQ(groups.size(), 1u);
  const auto first = refinement_round(groups, 0.05, 0.02, 100);
  ASSERT_EQ(first.size(), 3u);  // the two Ca* edges (0.15, 0.25) and CaH (0.35)
  // The proposals were added but have not run (queued, or 0.15 unstable): nothing new to propose from them.
  cases.push_back(fake_case(0.15, "unstable"));
  cases.push_back(fake_case(0.25, "queued"));
  cases.push_back(fake_case(0.35, "queued"));
  EXPECT_TRUE(refinement_round(group_cases(cases), 0.05, 0.02, 100).empty());
}

TEST(Refinement, BudgetLimitsTheRound) {
  std::vector<CaseSample> cases;
  for (double ca : {0.1, 0.2, 0.3, 0.4}) cases.push_back(fake_case(ca, "done"));
  EXPECT_EQ(refinement_round(group_cases(cases), 0.05, 0.02, 2).size(), 2u);
  EXPECT_TRUE(refinement_round(group_cases(cases), 0.05, 0.02, 0).empty());
}

TEST(TransitionGroups, EveryIdentityKeyButCaSeparatesGroups) {
  std::vector<CaseSample> cases;
  for (double dt : {0.01, 0.02})
    for (double ca : {0.1, 0.2, 0.3}) cases.push_back(fake_case(ca, "done", dt));
  const auto groups = group_cases(cases);
  ASSERT_EQ(groups.size(), 2u);
  for (const auto& g : groups) {
    EXPECT_EQ(g.samples.size(), 3u);
    EXPECT_EQ(g.key.law, "neo-hookean");
    EXPECT_EQ(g.key.skalak_C, -1);
    EXPECT_EQ(g.key.group_key.find("flow.capillary_number"), std::string::npos) << g.key.group_key;
  }
  EXPECT_NE(groups[0].key.group_key, groups[1].key.group_key);
  EXPECT_NE(group_difference(groups[0].key.group_key, groups[1].key.group_key).find("time.dt"), std::string::npos);
  // Ca alone never separates: the same case at another Ca has the same key.
  EXPECT_EQ(GroupKey::of(cases[0].params), GroupKey::of(cases[1].params));
}

}  // namespace
}  // namespace capsim::campaign
