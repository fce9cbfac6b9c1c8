// The order in which `campaign run` starts the queued cases (--order): by the cost estimate
// t_end · 32^level / Ca, most expensive first (longest, the default) or cheapest first (shortest); and
// `campaign analyse`, which recomputes the stored transitions.
#include <gtest/gtest.h>

#include "campaign/scheduler/campaign_runner.h"
#include "campaign/store/sqlite_db.h"
#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

// Six cases whose estimates differ only through 1/Ca (one law, one level, one t_end).
const std::string kSix = R"([campaign]
name = "six"
[defaults]
mesh.level = 1
[[grid]]
aspect_ratio = [0.5]
law = ["skalak"]
capillary_number = [0.03, 0.01, 0.06, 0.02, 0.05, 0.04]
)";

/// Ca of the cases in the order their first attempts started (one worker: one at a time).
std::string started_order(const std::string& order) {
  const std::string dir = fresh_dir("runner_order_" + order);
  const std::string db = dir + "/study.db";
  write_file(dir + "/c.toml", kSix);
  auto r = sh(campaign_cmd("FAKE_STEPS=1", dir + "/c.toml", db, "--jobs 1 --order " + order));
  EXPECT_EQ(r.code, 0) << r.err;
  return sql(db, "SELECT c.capillary_number FROM attempts a JOIN cases c USING(case_id) ORDER BY a.attempt_id");
}

TEST(CampaignRunner, LongestFirstStartsTheSmallestCaFirst) {
  EXPECT_EQ(started_order("longest"), "0.01\n0.02\n0.03\n0.04\n0.05\n0.06\n");
}

TEST(CampaignRunner, ShortestFirstStartsTheLargestCaFirst) {
  EXPECT_EQ(started_order("shortest"), "0.06\n0.05\n0.04\n0.03\n0.02\n0.01\n");
}

// `capsim campaign analyse` recomputes the stored transitions from the cases (after a change of the analysis,
// a database is refreshed without running anything), and refuses while a manager holds the database.
TEST(CampaignRunner, AnalyseRecomputesTheStoredTransitions) {
  const std::string dir = fresh_dir("runner_analyse");
  const std::string db = dir + "/study.db";
  write_file(dir + "/c.toml", prolate_campaign("prolate"));
  ASSERT_EQ(sh(campaign_cmd("FAKE_STEPS=1", dir + "/c.toml", db, "--jobs 2")).code, 0);
  const std::string before = sql(db, "SELECT ca_star_low, ca_h FROM transitions");
  {
    Db d(db, false, false);
    d.exec("UPDATE transitions SET ca_star_low = 9, ca_h = 99");
  }
  ASSERT_NE(sql(db, "SELECT ca_star_low, ca_h FROM transitions"), before);
  {
    ManagerLock held(db);  // a manager running on the database
    const auto busy = sh(exe() + " campaign analyse --db " + db);
    EXPECT_EQ(busy.code, 2) << busy.out;
    EXPECT_NE(busy.err.find("another campaign manager"), std::string::npos) << busy.err;
  }
  const auto r = sh(exe() + " campaign analyse --db " + db);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("campaign 'prolate': transitions recomputed"), std::string::npos) << r.out;
  EXPECT_EQ(sql(db, "SELECT ca_star_low, ca_h FROM transitions"), before);
  EXPECT_EQ(sh(exe() + " campaign analyse --db " + db + " --campaign nope").code, 2);
}

}  // namespace
}  // namespace capsim::campaign::testing
