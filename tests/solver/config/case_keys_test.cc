// The case-key registry: its entries agree with the code they describe, the echo reads back, and the
// committed schemas/case_keys.md is what the registry generates.
#include "solver/config/case_keys.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "solver/config/case_config.h"
#include "solver/dynamics/time_stepper.h"
#include "solver/membrane/membrane_law.h"
#include "solver/mesh/mesh.h"
#include "solver/quadrature/triangle_rule.h"

namespace capsim::config {
namespace {

TEST(CaseKeys, EveryDefaultPassesItsOwnRule) {
  for (const auto& k : case_keys()) EXPECT_EQ(check_case_value(k, k.default_value), "") << k.name;
  EXPECT_NO_THROW(CaseConfig{}.validate());
}

TEST(CaseKeys, NamesAreUniqueAndSectioned) {
  for (const auto& k : case_keys()) {
    EXPECT_EQ(find_case_key(k.name), &k) << k.name;
    EXPECT_EQ(k.name, k.section() + "." + k.short_name());
    EXPECT_FALSE(k.doc.empty()) << k.name;
    EXPECT_FALSE(k.rule_reason.empty()) << k.name;
  }
  EXPECT_EQ(find_case_key("flow.capillary"), nullptr);
}

TEST(CaseKeys, EveryNumberIsBoundedByAFiniteInterval) {
  for (const auto& k : case_keys()) {
    if (k.type != KeyType::kFloat && k.type != KeyType::kFloatOrAuto && !k.rule.has_interval) continue;
    ASSERT_TRUE(k.rule.has_interval || !k.rule.ints.empty()) << k.name;
    if (k.rule.has_interval) {
      EXPECT_TRUE(std::isfinite(k.rule.lo) && std::isfinite(k.rule.hi) && k.rule.lo < k.rule.hi) << k.name;
    }
  }
}

TEST(CaseKeys, WordListsAreWhatTheSolverAccepts) {
  for (const auto& w : find_case_key("mesh.spheroid_map")->rule.words) EXPECT_NO_THROW((void)mesh::parse_spheroid_map(w)) << w;
  // The enum keys: every accepted word parses to a value whose word it is, and every value has its word accepted.
  const auto law_words = find_case_key("capsule.law")->rule.words;
  ASSERT_EQ(law_words.size(), KeyWords<MembraneLawKind>::words.size());
  for (const auto& w : law_words) {
    const auto law = from_word<MembraneLawKind>(w);
    ASSERT_TRUE(law) << w;
    EXPECT_EQ(word_of(*law), w);
    EXPECT_EQ(membrane::make_law(*law, 1.0)->name(), w);
  }
  const auto scheme_words = find_case_key("time.scheme")->rule.words;
  ASSERT_EQ(scheme_words.size(), KeyWords<TimeScheme>::words.size());
  for (const auto& w : scheme_words) {
    const auto scheme = from_word<TimeScheme>(w);
    ASSERT_TRUE(scheme) << w;
    EXPECT_EQ(dynamics::make_integrator(*scheme)->name(), w);
  }
  EXPECT_FALSE(from_word<MembraneLawKind>("mooney"));
  // Every accepted triangle-rule degree has a rule, and the rules the keys refuse (1 and 2) exist: the
  // registry's reason, not a missing rule, keeps them out.
  for (const char* key : {"numerics.regular_degree", "numerics.membrane_degree"}) {
    for (auto d : find_case_key(key)->rule.ints) EXPECT_NO_THROW((void)quadrature::triangle_rule(static_cast<int>(d))) << key;
    for (int d : {1, 2}) EXPECT_NE(check_case_value(*find_case_key(key), KeyValue{std::int64_t{d}}), "") << key << d;
  }
  EXPECT_EQ(check_case_value(*find_case_key("numerics.far_degree"), KeyValue{std::int64_t{2}}), "");
}

TEST(CaseKeys, MessagesSayWhatIsAccepted) {
  const auto& deg = *find_case_key("numerics.membrane_degree");
  EXPECT_EQ(check_case_value(deg, KeyValue{std::int64_t{3}}), "must be 4, 5 or 6, got 3");
  EXPECT_EQ(check_case_value(deg, KeyValue{3.0}), "expected an integer, got a float");
  EXPECT_EQ(check_case_value(*find_case_key("flow.capillary_number"), KeyValue{1e308}),
            "must be in (0, 100], got 1e+308");
  EXPECT_EQ(check_case_value(*find_case_key("time.dt"), KeyValue{std::string("fast")}),
            "must be \"auto\" or in (0, 1], got \"fast\"");
  EXPECT_EQ(check_case_value(*find_case_key("mesh.level"), KeyValue{std::int64_t{4294967299}}),
            "must be in 0..6, got 4294967299");
}

// The aspect-ratio bounds are where the default spheroid map still gives usable elements at level 3.
TEST(CaseKeys, AspectRatioBoundsKeepTheMeshUsable) {
  const auto& k = *find_case_key("capsule.aspect_ratio");
  for (double r : {k.rule.lo, k.rule.hi}) {
    const auto q = mesh::mesh_quality(mesh::make_capsule_mesh(3, r));
    std::printf("a/b = %g: min angle %.1f deg, max edge ratio %.2f\n", r, q.min_angle_deg, q.max_edge_ratio);
    EXPECT_GT(q.min_angle_deg, 20.0) << r;
  }
}

TEST(CaseKeys, EchoReadsBackToTheSameCase) {
  CaseConfig c;
  c.level = 2;
  c.dt = 0.01;
  c.law = config::MembraneLawKind::NeoHookean;
  c.volume_correction = false;
  EXPECT_EQ(parse_case_config(c.to_toml(), "echo").to_map(), c.to_map());
  EXPECT_EQ(case_key_names().size(), case_keys().size());
}

TEST(CaseKeys, CommittedDocumentationIsGenerated) {
  std::ifstream in(std::string(CAPSIM_SOURCE_DIR) + "/schemas/case_keys.md");
  ASSERT_TRUE(in) << "schemas/case_keys.md is missing";
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  const auto begin = text.find(kMarkdownBegin);
  const auto end = text.find(kMarkdownEnd);
  ASSERT_NE(begin, std::string::npos) << "schemas/case_keys.md lacks the generated block";
  ASSERT_NE(end, std::string::npos);
  EXPECT_EQ(text.substr(begin, end + kMarkdownEnd.size() + 1 - begin), case_keys_markdown())
      << "schemas/case_keys.md is stale: replace its generated block by the output of `capsim keys --format md`";
}

}  // namespace
}  // namespace capsim::config
