// Ca* interval and CaH from samples; adaptive refinement proposals.
#include <gtest/gtest.h>

#include <cmath>

#include "campaign/analysis/refinement.h"
#include "campaign/analysis/transitions.h"

namespace capsim::campaign {
namespace {

Sample sample(double ca, std::optional<double> d12, std::optional<double> tau, const std::string& id) {
  Sample s;
  s.ca = ca;
  s.min_d12 = d12;
  s.max_tau_min = tau;
  s.case_id = id;
  return s;
}

std::vector<Sample> samples(const std::vector<double>& cas, double (*d12)(double), double (*tau)(double)) {
  std::vector<Sample> out;
  for (double ca : cas) out.push_back(sample(ca, d12(ca), tau(ca), "id" + std::to_string(ca)));
  return out;
}

double d12_oblate(double ca) { return 0.02 + 2.0 * std::fabs(ca - 0.03); }
double tau_oblate(double ca) { return 0.70 - ca; }

TEST(Transitions, CaStarIsTheSampledIntervalBelowThreshold) {
  auto s = samples({0.05, 0.01, 0.02, 0.03, 0.04, 0.06}, d12_oblate, tau_oblate);  // unsorted on purpose
  Transition t = analyse_group(Transition{}, s, 0.05);
  ASSERT_TRUE(t.ca_star_low && t.ca_star_high);
  EXPECT_DOUBLE_EQ(*t.ca_star_low, 0.02);
  EXPECT_DOUBLE_EQ(*t.ca_star_high, 0.04);
  EXPECT_DOUBLE_EQ(*t.ca_star_below, 0.01);
  EXPECT_DOUBLE_EQ(*t.ca_star_above, 0.05);
  EXPECT_DOUBLE_EQ(*t.ca_min_d12, 0.03);
  EXPECT_EQ(t.n_samples, 6);
  // A stricter threshold narrows it.
  Transition u = analyse_group(Transition{}, s, 0.03);
  EXPECT_DOUBLE_EQ(*u.ca_star_low, 0.03);
  EXPECT_DOUBLE_EQ(*u.ca_star_high, 0.03);
}

// The notes are printed (campaign status, the main command): numbers to 3 significant digits and sampled Ca as
// sampled, never the 17 digits of a double.
TEST(Transitions, NotesPrintNumbersToTheirPrecision) {
  std::vector<Sample> s = {sample(0.4, 0.44971266940321575, 0.01, "a"), sample(0.5, 0.49025674011763399, -0.01, "b")};
  const Transition t = analyse_group(Transition{}, s, 0.05);
  EXPECT_NE(t.note.find("smallest 0.45 at Ca=0.4"), std::string::npos) << t.note;
  EXPECT_EQ(t.note.find("0.4497"), std::string::npos) << t.note;
}

TEST(Transitions, CaHIsInterpolatedBetweenTheBracketingSamples) {
  auto s = samples({0.2, 0.4, 0.6, 1.0, 1.5}, d12_oblate, tau_oblate);
  Transition t = analyse_group(Transition{}, s, 0.05);
  ASSERT_TRUE(t.ca_h);
  EXPECT_NEAR(*t.ca_h, 0.70, 1e-12);  // linear data: exact zero
  EXPECT_DOUBLE_EQ(*t.ca_h_low, 0.6);
  EXPECT_DOUBLE_EQ(*t.ca_h_high, 1.0);
  EXPECT_EQ(t.ca_h_low_case, s[2].case_id);
  // Nonlinear data: the linear zero lies inside the bracket, not at its middle.
  s[2].max_tau_min = 0.3;
  s[3].max_tau_min = -0.1;
  t = analyse_group(Transition{}, s, 0.05);
  EXPECT_NEAR(*t.ca_h, 0.6 + 0.4 * 0.75, 1e-12);
}

TEST(Transitions, CaHTakesTheLastSignChangeAndReportsMissingBrackets) {
  auto s = samples({0.1, 0.2, 0.3, 0.4}, d12_oblate, tau_oblate);
  s[0].max_tau_min = -0.1;  // negative at a small Ca, positive again above: the criterion is "above which"
  s[1].max_tau_min = 0.2;
  s[2].max_tau_min = -0.2;
  s[3].max_tau_min = -0.3;
  Transition t = analyse_group(Transition{}, s, 0.05);
  EXPECT_NEAR(*t.ca_h, 0.2 + 0.1 * 0.5, 1e-12);
  for (auto& x : s) x.max_tau_min = 1.0;
  t = analyse_group(Transition{}, s, 0.05);
  EXPECT_FALSE(t.ca_h);
  EXPECT_NE(t.note.find("CaH above 0.4"), std::string::npos) << t.note;
  for (auto& x : s) x.max_tau_min = -1.0;
  t = analyse_group(Transition{}, s, 0.05);
  EXPECT_FALSE(t.ca_h);
  EXPECT_NE(t.note.find("CaH below 0.1"), std::string::npos) << t.note;
}

TEST(Transitions, NoSampleBelowThreshold) {
  auto s = samples({0.1, 0.2}, d12_oblate, tau_oblate);
  Transition t = analyse_group(Transition{}, s, 0.05);
  EXPECT_FALSE(t.ca_star_low);
  EXPECT_DOUBLE_EQ(*t.ca_min_d12, 0.1);
  EXPECT_NE(t.note.find("never below"), std::string::npos);
}

TEST(Transitions, ASphereHasNoCaStarAndNoMinimumToBracket) {
  // A sphere's min D12 -> 0 as Ca -> 0 (D12 = 0 at rest): below the threshold at small Ca, yet no transition.
  auto s = samples({0.005, 0.02, 0.1}, [](double ca) { return 5.0 * ca; }, tau_oblate);
  Transition key;
  key.aspect_ratio = 1.0;
  Transition t = analyse_group(key, s, 0.05);
  EXPECT_FALSE(t.ca_star_low);
  EXPECT_FALSE(t.ca_star_high);
  EXPECT_DOUBLE_EQ(*t.ca_min_d12, 0.005);
  EXPECT_NE(t.note.find("Ca* does not apply"), std::string::npos) << t.note;
  // max τmin > 0 everywhere here, so nothing else to refine: no bisection around the smallest min D12.
  EXPECT_TRUE(propose_refinement(t, s, 0.005).empty());
  // The same samples on an oblate capsule are a Ca* band [0.005].
  key.aspect_ratio = 0.5;
  t = analyse_group(key, s, 0.05);
  ASSERT_TRUE(t.ca_star_low);
  EXPECT_DOUBLE_EQ(*t.ca_star_low, 0.005);
}

TEST(Transitions, AnAllCompressedSphereBoundsNoCaH) {
  // max τmin < 0 at every sample. A spheroid: CaH lies below the smallest sample. A sphere is compressed below a
  // CaL as well (the NH sphere with κ_b = 1e-2), so the same samples bound nothing and the note says why.
  auto s = samples({0.1, 0.2, 0.4}, d12_oblate, [](double ca) { return -0.1 * ca; });
  Transition key;
  key.aspect_ratio = 2.0;
  Transition t = analyse_group(key, s, 0.05);
  ASSERT_TRUE(t.ca_h_high);
  EXPECT_DOUBLE_EQ(*t.ca_h_high, 0.1);
  EXPECT_NE(t.note.find("CaH below 0.1"), std::string::npos) << t.note;
  key.aspect_ratio = 1.0;
  t = analyse_group(key, s, 0.05);
  EXPECT_FALSE(t.ca_h);
  EXPECT_FALSE(t.ca_h_low);
  EXPECT_FALSE(t.ca_h_high);
  EXPECT_TRUE(t.ca_h_high_case.empty());
  EXPECT_EQ(t.note.find("CaH below"), std::string::npos) << t.note;
  EXPECT_NE(t.note.find("max_tau_min < 0 at every sampled Ca (0.1 to 0.4): no tension window [CaL, CaH] sampled"),
            std::string::npos)
      << t.note;
  // One sample in tension brackets the upper crossing as for any shape.
  s[1].max_tau_min = 0.05;
  t = analyse_group(key, s, 0.05);
  ASSERT_TRUE(t.ca_h);
  EXPECT_DOUBLE_EQ(*t.ca_h_low, 0.2);
  EXPECT_DOUBLE_EQ(*t.ca_h_high, 0.4);
}

// Samples at @p cas with the regimes @p regimes ("tumbling", "swinging", ...), D12 and tension that bracket
// nothing of their own: Ca_TS must come from the regimes alone.
std::vector<Sample> regime_samples(const std::vector<double>& cas, const std::vector<std::string>& regimes) {
  std::vector<Sample> out;
  for (std::size_t i = 0; i < cas.size(); ++i) {
    out.push_back(sample(cas[i], 0.3, 0.1, "id" + std::to_string(i)));
    out.back().regime = regimes[i];
  }
  return out;
}

Transition prolate() {
  Transition key;
  key.aspect_ratio = 2.0;
  return key;
}

TEST(RegimeTransition, ACleanSequenceGivesTheAdjacentTumblingAndSwingingSamples) {
  // NH a/b = 2 at λ = 1 (results/viscosity_ratio): tumbling up to 0.213, swinging from 0.25 (unsorted on purpose).
  auto s = regime_samples({0.25, 0.05, 0.213, 0.4, 0.2, 0.3},
                          {"swinging", "tumbling", "tumbling", "swinging", "tumbling", "swinging"});
  const Transition t = analyse_group(prolate(), s, 0.05);
  ASSERT_TRUE(t.ca_ts_low && t.ca_ts_high);
  EXPECT_DOUBLE_EQ(*t.ca_ts_low, 0.213);
  EXPECT_DOUBLE_EQ(*t.ca_ts_high, 0.25);
  EXPECT_EQ(t.ca_ts_note, "");
  // Independent of the Ca* criterion (min D12 0.3 everywhere: no Ca*), and its note stays the Ca* / CaH one.
  EXPECT_FALSE(t.ca_star_low);
  EXPECT_EQ(t.note.find("swing"), std::string::npos) << t.note;
}

TEST(RegimeTransition, EveryTumblingOrEverySwingingSampleGivesNoBracketAndSaysWhich) {
  auto s = regime_samples({0.02, 0.5, 5}, {"tumbling", "tumbling", "tumbling"});
  Transition t = analyse_group(prolate(), s, 0.05);
  EXPECT_FALSE(t.ca_ts_low);
  EXPECT_FALSE(t.ca_ts_high);
  EXPECT_EQ(t.ca_ts_note, "tumbles at every sampled Ca (0.02 to 5)");
  for (auto& x : s) x.regime = "swinging";
  t = analyse_group(prolate(), s, 0.05);
  EXPECT_FALSE(t.ca_ts_low);
  EXPECT_FALSE(t.ca_ts_high);
  EXPECT_EQ(t.ca_ts_note, "swings from the smallest sampled Ca (0.02)");
  // One sample: its Ca alone.
  t = analyse_group(prolate(), {s[1]}, 0.05);
  EXPECT_EQ(t.ca_ts_note, "swings from the smallest sampled Ca (0.5)");
  s[1].regime = "tumbling";
  t = analyse_group(prolate(), {s[1]}, 0.05);
  EXPECT_EQ(t.ca_ts_note, "tumbles at every sampled Ca (0.5)");
  t = analyse_group(prolate(), {}, 0.05);
  EXPECT_FALSE(t.ca_ts_low);
  EXPECT_EQ(t.ca_ts_note, "no finished case");
}

TEST(RegimeTransition, NonMonotoneRegimesGiveTheOutermostBracketOrNone) {
  // A tumbling sample (0.3) above a swinging one (0.25): the outermost bracket runs from the last tumbling sample
  // below the first swinging one (0.2) to the first swinging sample above the last tumbling one (0.35).
  auto s = regime_samples({0.1, 0.2, 0.25, 0.3, 0.35, 0.5},
                          {"tumbling", "tumbling", "swinging", "tumbling", "swinging", "swinging"});
  Transition t = analyse_group(prolate(), s, 0.05);
  ASSERT_TRUE(t.ca_ts_low && t.ca_ts_high);
  EXPECT_DOUBLE_EQ(*t.ca_ts_low, 0.2);
  EXPECT_DOUBLE_EQ(*t.ca_ts_high, 0.35);
  EXPECT_EQ(t.ca_ts_note.rfind(kRegimesNotMonotone, 0), 0u) << t.ca_ts_note;
  EXPECT_EQ(t.ca_ts_note,
            "regimes not monotone in Ca: tumbling at Ca=0.3 above swinging at Ca=0.25; the bracket is the outermost: "
            "every sample below it tumbles, every one above it swings");
  // Tumbling at the largest sample: no bracket has tumbling below and swinging above.
  s[5].regime = "tumbling";
  t = analyse_group(prolate(), s, 0.05);
  EXPECT_FALSE(t.ca_ts_low);
  EXPECT_FALSE(t.ca_ts_high);
  EXPECT_EQ(t.ca_ts_note, "regimes not monotone in Ca: tumbling at Ca=0.5 above swinging at Ca=0.25; tumbling at the "
                          "largest sampled Ca, so no bracket has tumbling below and swinging above");
  // Swinging at the smallest sample, tumbling above: none either.
  s = regime_samples({0.1, 0.2, 0.3}, {"swinging", "tumbling", "swinging"});
  t = analyse_group(prolate(), s, 0.05);
  EXPECT_FALSE(t.ca_ts_low);
  EXPECT_FALSE(t.ca_ts_high);
  EXPECT_EQ(t.ca_ts_note, "regimes not monotone in Ca: tumbling at Ca=0.2 above swinging at Ca=0.1; swinging at the "
                          "smallest sampled Ca, so no bracket has tumbling below and swinging above");
}

TEST(RegimeTransition, SamplesOfOtherRegimesAreSkippedAndNamed) {
  // Steady, unknown (no full period) and off-plane regimes (a tilted capsule's kayaking) are neither side of the
  // in-plane transition: skipped, so the bracket joins the tumbling and swinging samples around them.
  auto s = regime_samples({0.01, 0.05, 0.1, 0.15, 0.2, 0.3, 2, 3},
                          {"tumbling", "kayaking", "tumbling", "steady", "swinging", "unknown", "swinging", "unknown"});
  Transition t = analyse_group(prolate(), s, 0.05);
  ASSERT_TRUE(t.ca_ts_low && t.ca_ts_high);
  EXPECT_DOUBLE_EQ(*t.ca_ts_low, 0.1);
  EXPECT_DOUBLE_EQ(*t.ca_ts_high, 0.2);
  EXPECT_EQ(t.ca_ts_note, "skipped kayaking at Ca=0.05; skipped steady at Ca=0.15; skipped unknown at Ca=0.3, 3");
  // Only skipped regimes (a result without one reads as ""): no bracket.
  s = regime_samples({0.1, 0.2, 0.3}, {"rolling", "", "rolling"});
  t = analyse_group(prolate(), s, 0.05);
  EXPECT_FALSE(t.ca_ts_low);
  EXPECT_FALSE(t.ca_ts_high);
  EXPECT_EQ(t.ca_ts_note,
            "no tumbling or swinging case; skipped rolling at Ca=0.1, 0.3; skipped no recorded regime at Ca=0.2");
  // Skipped samples beside an all-tumbling sequence: the range is that of the tumbling samples.
  s = regime_samples({0.1, 0.2, 0.3}, {"tumbling", "tumbling", "unknown"});
  t = analyse_group(prolate(), s, 0.05);
  EXPECT_EQ(t.ca_ts_note, "tumbles at every sampled Ca (0.1 to 0.2); skipped unknown at Ca=0.3");
}

TEST(RegimeTransition, ASphereGetsNothing) {
  // A sphere does not tumble: even a sequence that would bracket a transition on a spheroid gives no Ca_TS.
  auto s = regime_samples({0.1, 0.2, 0.3}, {"tumbling", "swinging", "steady"});
  Transition key;
  key.aspect_ratio = 1.0;
  const Transition t = analyse_group(key, s, 0.05);
  EXPECT_FALSE(t.ca_ts_low);
  EXPECT_FALSE(t.ca_ts_high);
  EXPECT_EQ(t.ca_ts_note, "");
  EXPECT_FALSE(analyse_group(key, {}, 0.05).ca_ts_low);
  EXPECT_EQ(analyse_group(key, {}, 0.05).ca_ts_note, "");
}

// group_cases hands each sample the regime of its case, and where a Ca was run twice, that of the kept case.
TEST(RegimeTransition, GroupingCarriesTheRegimeOfTheKeptCase) {
  std::vector<CaseSample> cases;
  for (const auto& [ca, regime] : std::vector<std::pair<double, std::string>>{{0.1, "tumbling"}, {0.2, "swinging"}}) {
    CaseParams p = CaseParams::defaults();
    p.set("capsule.aspect_ratio", 2.0);
    p.set("flow.capillary_number", ca);
    CaseSample c;
    c.case_id = "c" + std::to_string(ca);
    c.params = p;
    c.status = "done";
    c.min_d12 = 0.3;
    c.max_tau_min = 0.1;
    c.regime = regime;
    cases.push_back(c);
  }
  const auto groups = group_cases(cases);
  ASSERT_EQ(groups.size(), 1u);
  ASSERT_EQ(groups[0].samples.size(), 2u);
  EXPECT_EQ(groups[0].samples[0].regime, "tumbling");
  EXPECT_EQ(groups[0].samples[1].regime, "swinging");
  const auto rows = analyse_groups(groups, 0.05, "grid");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_DOUBLE_EQ(*rows[0].ca_ts_low, 0.1);
  EXPECT_DOUBLE_EQ(*rows[0].ca_ts_high, 0.2);
}

TEST(Adaptive, ProposalsShrinkBracketsAndConverge) {
  // Start coarse, add the proposals of each round: the Ca* edges and CaH converge to the tolerance.
  std::vector<double> cas = {0.01, 0.1, 0.4, 0.8, 1.2};
  const double tol = 0.005;
  int rounds = 0;
  for (; rounds < 30; ++rounds) {
    auto s = samples(cas, d12_oblate, tau_oblate);
    Transition t = analyse_group(Transition{}, s, 0.05);
    auto add = propose_refinement(t, s, tol);
    if (add.empty()) break;
    for (double x : add) {
      for (double y : cas) ASSERT_NE(x, y);
      cas.push_back(x);
    }
  }
  EXPECT_LT(rounds, 30);
  auto s = samples(cas, d12_oblate, tau_oblate);
  Transition t = analyse_group(Transition{}, s, 0.05);
  ASSERT_TRUE(t.ca_star_low && t.ca_star_high && t.ca_h);
  // True band: |Ca - 0.03| < 0.015, i.e. (0.015, 0.045).
  EXPECT_LE(*t.ca_star_low - 0.015, tol);
  EXPECT_GE(*t.ca_star_low, 0.015);
  EXPECT_LE(0.045 - *t.ca_star_high, tol);
  EXPECT_NEAR(*t.ca_h, 0.70, 1e-9);
  EXPECT_LE(*t.ca_h_high - *t.ca_h_low, tol);
  EXPECT_LT(cas.size(), 40u);  // a fixed 0.005 grid over [0.01, 1.2] would need 239 cases
}

}  // namespace
}  // namespace capsim::campaign
