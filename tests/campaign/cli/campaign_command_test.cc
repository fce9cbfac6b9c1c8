// `capsim campaign status`: the work left, as the runner's ETA sees it (campaign/cli/campaign_command.cc).
#include <gtest/gtest.h>
#include <sqlite3.h>

#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

TEST(CampaignStatus, SaysHowMuchWorkIsLeftOnlyWhileCasesAreLeft) {
  const std::string dir = fresh_dir("campaign_status_work_left");
  const std::string db = dir + "/study.db";
  write_file(dir + "/c.toml", prolate_campaign("left"));
  ASSERT_EQ(sh(campaign_cmd("FAKE_STEPS=1 FAKE_STEP_S=0.001", dir + "/c.toml", db, "--jobs 2")).code, 0);
  const auto done = sh(exe() + " campaign status --db " + db);
  ASSERT_EQ(done.code, 0) << done.err;
  EXPECT_EQ(done.out.find("work left"), std::string::npos) << done.out;
  // Two cases back in the queue (as a stopped run leaves them): the finished ones say what they cost
  // (the stand-in worker reports wall_s = 0.2 s each), so about 0.4 s of work is left.
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &h), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(h, "UPDATE cases SET status='queued' WHERE case_id IN "
                            "(SELECT case_id FROM cases ORDER BY case_id LIMIT 2)", nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(h);
  const auto left = sh(exe() + " campaign status --db " + db);
  ASSERT_EQ(left.code, 0) << left.err;
  const auto at = left.out.find("work left: about ");
  ASSERT_NE(at, std::string::npos) << left.out;
  EXPECT_NE(left.out.find("core-h in the 2 queued and running cases", at), std::string::npos) << left.out;
  const double core_h = std::stod(left.out.substr(at + 17));
  EXPECT_GT(core_h, 0.1 / 3600);
  EXPECT_LT(core_h, 1.0 / 3600);
}

}  // namespace
}  // namespace capsim::campaign::testing
