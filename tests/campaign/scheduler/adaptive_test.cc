// Adaptive mode end to end (fake worker with known Ca* band and CaH): from a coarse grid the manager adds
// cases until the Ca* edges and the CaH bracket are narrower than the tolerance.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

TEST(Adaptive, BracketsCaStarAndCaHWithFewCases) {
  const std::string dir = fresh_dir("adaptive");
  const std::string db = dir + "/study.db";
  write_file(dir + "/a.toml", R"([campaign]
name = "adaptive"
[defaults]
mesh.level = 1
[[grid]]
aspect_ratio = [0.5]
law = ["neo-hookean"]
capillary_number = [0.01, 0.1, 0.4, 0.8, 1.2]
[analysis]
adaptive = true
ca_tolerance = 0.005
max_rounds = 20
)");
  auto r = sh(campaign_cmd("FAKE_STEPS=1 FAKE_STEP_S=0.001", dir + "/a.toml", db, "--jobs 2"));
  ASSERT_EQ(r.code, 0) << r.err;
  auto t = sh(exe() + " query sql \"SELECT * FROM transitions\" --db " + db + " --format json");
  ASSERT_EQ(t.code, 0) << t.err;
  auto rows = nlohmann::json::parse(t.out);
  ASSERT_EQ(rows.size(), 1u);
  const auto& row = rows[0];
  EXPECT_EQ(row["method"], "adaptive");
  // Truth of the fake worker: min_D12 < 0.05 for Ca in (0.015, 0.045); max_tau_min = 0.70 - Ca.
  const double tol = 0.005;
  EXPECT_GE(row["ca_star_low"].get<double>(), 0.015);
  EXPECT_LE(row["ca_star_low"].get<double>() - row["ca_star_below"].get<double>(), tol);
  EXPECT_LE(row["ca_star_high"].get<double>(), 0.045);
  EXPECT_LE(row["ca_star_above"].get<double>() - row["ca_star_high"].get<double>(), tol);
  EXPECT_NEAR(row["ca_h"].get<double>(), 0.70, 1e-9);
  EXPECT_LE(row["ca_h_high"].get<double>() - row["ca_h_low"].get<double>(), tol);
  const int n = row["n_samples"].get<int>();
  // A fixed grid with the same resolution over [0.01, 1.2] needs 239 cases.
  EXPECT_LT(n, 40) << "adaptive mode used " << n << " cases";
  std::printf("adaptive mode: %d cases (fixed 0.005 grid over [0.01, 1.2]: 239)\n", n);
  auto s = sh(exe() + " campaign status --db " + db);
  EXPECT_NE(s.out.find("added by adaptive refinement"), std::string::npos) << s.out;
  // Re-running adds nothing.
  r = sh(campaign_cmd("FAKE_STEPS=1 FAKE_STEP_S=0.001", dir + "/a.toml", db, "--jobs 2"));
  EXPECT_EQ(r.code, 0);
  auto again = nlohmann::json::parse(sh(exe() + " query sql \"SELECT n_samples FROM transitions\" --db " + db +
                                        " --format json").out);
  EXPECT_EQ(again[0]["n_samples"].get<int>(), n);
}

// A round once reported the Ca values it proposed, also those whose case already exists (here an
// unstable case at Ca = 0.15 is proposed again every round: it is no sample, yet its identity exists). The
// reported counts must add up to the adaptive cases the database holds.
TEST(Adaptive, RoundsReportTheCasesTheyAdded) {
  const std::string dir = fresh_dir("adaptive_added");
  const std::string db = dir + "/study.db";
  write_file(dir + "/a.toml", R"([campaign]
name = "adaptive-added"
[defaults]
mesh.level = 1
[[grid]]
aspect_ratio = [2.0]
law = ["neo-hookean"]
capillary_number = [0.1, 0.2, 0.3, 0.4]
[analysis]
adaptive = true
ca_tolerance = 0.02
max_rounds = 6
)");
  auto r = sh(campaign_cmd("FAKE_STEPS=1 FAKE_STEP_S=0.001 FAKE_UNSTABLE_CA=0.15", dir + "/a.toml", db, "--jobs 2"));
  ASSERT_EQ(r.code, 0) << r.err;
  int reported = 0, rounds = 0;
  const std::string tag = ": adaptive round ";
  for (auto at = r.err.find(tag); at != std::string::npos; at = r.err.find(tag, at + 1)) {
    const auto colon = r.err.find(": ", at + tag.size());
    ASSERT_NE(colon, std::string::npos) << r.err;
    reported += std::stoi(r.err.substr(colon + 2));
    ++rounds;
  }
  ASSERT_GT(rounds, 0) << "no adaptive round ran:\n" << r.err;
  const int in_db = std::stoi(sql(db, "SELECT count(*) FROM campaign_cases WHERE origin='adaptive'"));
  EXPECT_EQ(reported, in_db) << r.err;
  // The unstable case exists once; it is never proposed as a new case again.
  EXPECT_EQ(std::stoi(sql(db, "SELECT count(*) FROM cases WHERE abs(capillary_number - 0.15) < 1e-12")), 1);
}

}  // namespace
}  // namespace capsim::campaign::testing
