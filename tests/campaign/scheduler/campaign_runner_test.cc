// The order in which `campaign run` starts the queued cases (--order): by the cost estimate
// t_end · 32^level / Ca, most expensive first (longest, the default) or cheapest first (shortest); and
// `campaign analyse`, which recomputes the stored transitions.
#include <gtest/gtest.h>

#include <filesystem>

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

// The order counts the work left: a case that resumes from a checkpoint near its end is the shortest, so
// `--order shortest` finishes an interrupted case before starting whole ones (and `longest` starts it last).
TEST(CampaignRunner, AResumedCaseIsOrderedByTheWorkItHasLeft) {
  const std::string dir = fresh_dir("runner_order_resumed");
  const std::string db = dir + "/study.db";
  // t_end = 0.11: a checkpoint at γ̇t = 0.1 leaves 9 % of the case, less than 0.06's estimate over 0.01's.
  std::string six = kSix;
  six.replace(six.find("mesh.level = 1\n"), 15, "mesh.level = 1\ntime.t_end = 0.11\n");
  write_file(dir + "/c.toml", six);
  ASSERT_EQ(sh(campaign_cmd("FAKE_STEPS=1", dir + "/c.toml", db, "--jobs 1")).code, 0);
  const auto real = sh(exe() + " run - --set mesh.level=1 --set time.dt=0.02 --stop-after 5 --threads 1 --quiet --out " +
                       dir + "/real");
  ASSERT_EQ(real.code, 3) << real.err;
  std::string folder = sql(db, "SELECT out_dir FROM cases WHERE capillary_number = 0.01");
  while (!folder.empty() && (folder.back() == '\n' || folder.back() == '\r')) folder.pop_back();
  ASSERT_FALSE(folder.empty());
  std::filesystem::copy_file(dir + "/real/checkpoint.h5", folder + "/checkpoint.h5",
                             std::filesystem::copy_options::overwrite_existing);
  write_file(folder + "/checkpoint.txt", "0\n");  // what the stand-in worker resumes from
  for (const std::string order : {"shortest", "longest"}) {
    {
      Db d(db, false, false);
      d.exec("DELETE FROM attempts; UPDATE cases SET status = 'queued'; "
             "UPDATE cases SET resumable = 1 WHERE capillary_number = 0.01");
    }
    auto r = sh(campaign_cmd("FAKE_STEPS=1", dir + "/c.toml", db, "--jobs 1 --order " + order));
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string got =
        sql(db, "SELECT c.capillary_number FROM attempts a JOIN cases c USING(case_id) ORDER BY a.attempt_id");
    if (order == "shortest") EXPECT_EQ(got, "0.01\n0.06\n0.05\n0.04\n0.03\n0.02\n");
    else EXPECT_EQ(got, "0.02\n0.03\n0.04\n0.05\n0.06\n0.01\n");
  }
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

// A campaign is its file's grid plus what its analysis added. Found when a campaign file was cut to one of its
// cases and rerun: the dry run listed that one case, the run started another, the most expensive of the
// earlier grid's queued cases. Links of an earlier grid that the file no longer has are now reported by the
// dry run, unlinked by the run (not run, not analysed) and their cases kept in the database.
TEST(CampaignRunner, ACaseRemovedFromTheGridIsNeitherRunNorAnalysedButStaysInTheDatabase) {
  const std::string dir = fresh_dir("runner_stale_grid");
  const std::string db = dir + "/study.db";
  write_file(dir + "/c.toml", kSix);
  // The six cases registered, none run: a stopped manager leaves them queued.
  pid_t pid = spawn_sh(campaign_cmd("FAKE_STEPS=100 FAKE_STEP_S=0.05", dir + "/c.toml", db, "--jobs 1"));
  ASSERT_TRUE(wait_for_checkpoints(db + ".runs", 1, 30));
  kill(pid, SIGTERM);
  ASSERT_EQ(wait_child(pid, 30), 3);
  ASSERT_EQ(sql(db, "SELECT count(*) FROM campaign_cases"), "6\n");
  // The file cut to two Ca values.
  std::string two = kSix;
  two.replace(two.find("[0.03, 0.01, 0.06, 0.02, 0.05, 0.04]"), 36, "[0.03, 0.05]");
  write_file(dir + "/c.toml", two);
  const auto dry = sh(campaign_cmd("", dir + "/c.toml", db, "--dry-run"));
  ASSERT_EQ(dry.code, 0) << dry.err;
  EXPECT_NE(dry.out.find("2 cases: 2 to run, 0 to skip, 4 to unlink"), std::string::npos) << dry.out;
  EXPECT_EQ(count_lines(dry.out), 1 + 2 + 4 + 1) << dry.out;  // header, grid, unlinked, summary
  const auto r = sh(campaign_cmd("FAKE_STEPS=1", dir + "/c.toml", db, "--jobs 1"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("4 case(s) an earlier version of 'six' linked are no longer in its grid"), std::string::npos)
      << r.err;
  EXPECT_EQ(sql(db, "SELECT c.capillary_number FROM cases c JOIN results USING(case_id) ORDER BY 1"),
            "0.03\n0.05\n");
  EXPECT_EQ(sql(db, "SELECT count(*) FROM cases"), "6\n");  // kept
  EXPECT_EQ(sql(db, "SELECT count(*) FROM campaign_cases"), "2\n");
  EXPECT_EQ(sh(campaign_cmd("", dir + "/c.toml", db, "--dry-run")).out.find("to unlink"), std::string::npos);
  // The full file again: the four are linked (and run) again.
  write_file(dir + "/c.toml", kSix);
  ASSERT_EQ(sh(campaign_cmd("FAKE_STEPS=1", dir + "/c.toml", db, "--jobs 1")).code, 0);
  EXPECT_EQ(sql(db, "SELECT count(*) FROM campaign_cases"), "6\n");
  EXPECT_EQ(sql(db, "SELECT count(*) FROM results"), "6\n");
}

}  // namespace
}  // namespace capsim::campaign::testing
