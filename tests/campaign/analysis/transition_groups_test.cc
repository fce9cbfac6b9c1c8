// Transitions are computed per group of cases that agree in every identity key but Ca.
// A grid axis over a numerical key (here time.dt) must give one Ca* / CaH per value, not a pooled one.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

TEST(TransitionGroups, NumericsAxisGivesOneTransitionPerValue) {
  const std::string dir = fresh_dir("transition_groups");
  const std::string db = dir + "/study.db";
  write_file(dir + "/g.toml", prolate_campaign("dt-axis", "time.dt = [0.01, 0.02]\n"));
  auto r = sh(campaign_cmd("FAKE_STEPS=1 FAKE_STEP_S=0.001", dir + "/g.toml", db, "--jobs 2"));
  ASSERT_EQ(r.code, 0) << r.err;
  auto t = sh(exe() + " query sql \"SELECT * FROM transitions ORDER BY group_key\" --db " + db + " --format json");
  ASSERT_EQ(t.code, 0) << t.err;
  const auto rows = nlohmann::json::parse(t.out);
  ASSERT_EQ(rows.size(), 2u) << t.out;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& row = rows[i];
    EXPECT_EQ(row["n_samples"].get<int>(), 4) << "each dt has its own four samples";
    // The group names its keys: every identity key except Ca, as canonical JSON.
    const auto key = nlohmann::json::parse(row["group_key"].get<std::string>());
    EXPECT_FALSE(key.contains("flow.capillary_number"));
    EXPECT_EQ(key.at("capsule.law"), "neo-hookean");
    EXPECT_DOUBLE_EQ(key.at("time.dt").get<double>(), i == 0 ? 0.01 : 0.02);
    // Fake worker truth for a/b >= 1: min_D12 < 0.05 for |Ca - 0.225| < 0.06, CaH = 0.35.
    EXPECT_DOUBLE_EQ(row["ca_star_low"].get<double>(), 0.2);
    EXPECT_DOUBLE_EQ(row["ca_star_high"].get<double>(), 0.2);
    EXPECT_NEAR(row["ca_h"].get<double>(), 0.35, 1e-12);
  }
  // Table 1 cannot show two groups in one cell: it says so (bad input), it does not pick one.
  auto q = sh(exe() + " query table1 --db " + db);
  EXPECT_EQ(q.code, 2) << q.out;
  EXPECT_NE(q.err.find("time.dt"), std::string::npos) << q.err;
}

// A bending axis (Table 1 at several κ_b in one campaign): query table1 names the option that picks
// one κ_b, and with it prints that κ_b's table, headed by its value.
TEST(TransitionGroups, BendingAxisIsChosenWithBendingModulus) {
  const std::string dir = fresh_dir("transition_groups_bending");
  const std::string db = dir + "/study.db";
  write_file(dir + "/g.toml", prolate_campaign("kb-axis", "bending_modulus = [0.0, 1e-3]\n"));
  auto r = sh(campaign_cmd("FAKE_STEPS=1 FAKE_STEP_S=0.001", dir + "/g.toml", db, "--jobs 2"));
  ASSERT_EQ(r.code, 0) << r.err;
  auto q = sh(exe() + " query table1 --db " + db);
  EXPECT_EQ(q.code, 2) << q.out;
  EXPECT_NE(q.err.find("--bending-modulus"), std::string::npos) << q.err;
  q = sh(exe() + " query table1 --db " + db + " --bending-modulus 0.001");
  ASSERT_EQ(q.code, 0) << q.err;
  EXPECT_NE(q.out.find("Bending modulus κ_b = 0.001"), std::string::npos) << q.out;
  q = sh(exe() + " query table1 --db " + db + " --bending-modulus 0 --format json");
  ASSERT_EQ(q.code, 0) << q.err;
  const auto rows = nlohmann::json::parse(q.out);
  ASSERT_EQ(rows.size(), 1u) << q.out;
  EXPECT_DOUBLE_EQ(rows[0]["bending_modulus"].get<double>(), 0.0);
  q = sh(exe() + " query table1 --db " + db + " --bending-modulus 0.5");
  EXPECT_EQ(q.code, 2) << q.out;
  EXPECT_NE(q.err.find("no transitions with capsule.bending_modulus = 0.5"), std::string::npos) << q.err;
}

// A viscosity-ratio axis, the same way: --viscosity-ratio picks one λ, whose table is headed by its value; the
// default λ = 1 is the seed's capsule and heads nothing.
TEST(TransitionGroups, ViscosityRatioAxisIsChosenWithViscosityRatio) {
  const std::string dir = fresh_dir("transition_groups_lambda");
  const std::string db = dir + "/study.db";
  write_file(dir + "/g.toml", prolate_campaign("lambda-axis", "viscosity_ratio = [1.0, 5.0]\n"));
  auto r = sh(campaign_cmd("FAKE_STEPS=1 FAKE_STEP_S=0.001", dir + "/g.toml", db, "--jobs 2"));
  ASSERT_EQ(r.code, 0) << r.err;
  auto q = sh(exe() + " query table1 --db " + db);
  EXPECT_EQ(q.code, 2) << q.out;
  EXPECT_NE(q.err.find("flow.viscosity_ratio"), std::string::npos) << q.err;
  EXPECT_NE(q.err.find("--viscosity-ratio"), std::string::npos) << q.err;
  q = sh(exe() + " query table1 --db " + db + " --viscosity-ratio 5");
  ASSERT_EQ(q.code, 0) << q.err;
  EXPECT_NE(q.out.find("Viscosity ratio λ (inner/outer) = 5"), std::string::npos) << q.out;
  q = sh(exe() + " query table1 --db " + db + " --viscosity-ratio 1");
  ASSERT_EQ(q.code, 0) << q.err;
  EXPECT_EQ(q.out.find("Viscosity ratio"), std::string::npos) << q.out;
  q = sh(exe() + " query table1 --db " + db + " --viscosity-ratio 5 --format json");
  ASSERT_EQ(q.code, 0) << q.err;
  const auto rows = nlohmann::json::parse(q.out);
  ASSERT_EQ(rows.size(), 1u) << q.out;
  EXPECT_DOUBLE_EQ(rows[0]["group_key"]["flow.viscosity_ratio"].get<double>(), 5.0);
  q = sh(exe() + " query table1 --db " + db + " --viscosity-ratio 2");
  EXPECT_EQ(q.code, 2) << q.out;
  EXPECT_NE(q.err.find("no transitions with flow.viscosity_ratio = 2"), std::string::npos) << q.err;
  q = sh(exe() + " query table1 --db " + db + " --viscosity-ratio -1");
  EXPECT_EQ(q.code, 2) << q.out;
  // query cases: every case with its λ (1 where the key is at its default, so not stored), and a filter.
  q = sh(exe() + " query cases --db " + db + " --format json");
  ASSERT_EQ(q.code, 0) << q.err;
  const auto all = nlohmann::json::parse(q.out);
  int at1 = 0, at5 = 0;
  for (const auto& c : all) (c["viscosity_ratio"].get<double>() == 5.0 ? at5 : at1) += 1;
  EXPECT_EQ(at1, 4);
  EXPECT_EQ(at5, 4);
  q = sh(exe() + " query cases --db " + db + " --viscosity-ratio 5 --format json");
  ASSERT_EQ(q.code, 0) << q.err;
  const auto five = nlohmann::json::parse(q.out);
  ASSERT_EQ(five.size(), 4u) << q.out;
  for (const auto& c : five) EXPECT_EQ(c["viscosity_ratio"].get<double>(), 5.0);
  q = sh(exe() + " query cases --db " + db + " --viscosity-ratio 1 --format json");
  ASSERT_EQ(q.code, 0) << q.err;
  EXPECT_EQ(nlohmann::json::parse(q.out).size(), 4u) << q.out;
}

// campaign status tells the groups apart: its table had one row per group but no column for the key that
// differs (two rows "neo-hookean 2 level 3" with different κ_b read the same), nor did its problem-case lines.
TEST(TransitionGroups, StatusNamesTheKeyThatTellsTheGroupsApart) {
  const std::string dir = fresh_dir("transition_groups_status");
  const std::string db = dir + "/study.db";
  write_file(dir + "/g.toml", prolate_campaign("kb-status", "bending_modulus = [0.0, 1e-3]\n"));
  auto r = sh(campaign_cmd("FAKE_STEPS=1 FAKE_STEP_S=0.001 FAKE_FAIL_CA=0.4", dir + "/g.toml", db, "--jobs 2"));
  ASSERT_EQ(r.code, 1) << r.err;  // finished, with the two Ca = 0.4 cases failed
  const auto st = sh(exe() + " campaign status --db " + db);
  ASSERT_EQ(st.code, 0) << st.err;
  EXPECT_NE(st.out.find("| group |"), std::string::npos) << st.out;
  EXPECT_NE(st.out.find("| capsule.bending_modulus=0.0 |"), std::string::npos) << st.out;
  EXPECT_NE(st.out.find("| capsule.bending_modulus=0.001 |"), std::string::npos) << st.out;
  EXPECT_NE(st.out.find("Ca=0.4 level 1 capsule.bending_modulus=0.001"), std::string::npos) << st.out;
  // One group only: no such column (the table of a plain campaign is unchanged).
  write_file(dir + "/h.toml", prolate_campaign("plain"));
  ASSERT_EQ(sh(campaign_cmd("FAKE_STEPS=1 FAKE_STEP_S=0.001", dir + "/h.toml", dir + "/plain.db", "--jobs 2")).code, 0);
  const auto plain = sh(exe() + " campaign status --db " + dir + "/plain.db");
  EXPECT_EQ(plain.out.find("group"), std::string::npos) << plain.out;
}

}  // namespace
}  // namespace capsim::campaign::testing
