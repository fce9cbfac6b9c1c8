// `capsim campaign status`: the work left, as the runner's ETA sees it (campaign/cli/campaign_command.cc).
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>

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

// A case interrupted with a checkpoint says how far it got (from the checkpoint in its folder), so a scientist
// can see what an hours-long level-4 case has done without opening its log.
TEST(CampaignStatus, AnInterruptedCaseSaysHowFarItsCheckpointGot) {
  const std::string dir = fresh_dir("campaign_status_checkpoint");
  const std::string db = dir + "/study.db";
  // t_end = 0.4: the checkpoint at γ̇t = 0.1 below leaves three quarters of the case to run.
  write_file(dir + "/c.toml", "[campaign]\nname = \"cp\"\n[defaults]\nmesh.level = 1\ntime.t_end = 0.4\n[[grid]]\n"
                              "aspect_ratio = [2.0]\nlaw = [\"neo-hookean\"]\ncapillary_number = [0.1, 0.2, 0.3, 0.4]\n");
  ASSERT_EQ(sh(campaign_cmd("FAKE_STEPS=1 FAKE_STEP_S=0.001", dir + "/c.toml", db, "--jobs 2")).code, 0);
  // A real checkpoint: the solver stopped after 5 steps of dt = 0.02 (t = 0.1).
  const auto run = sh(exe() + " run - --set mesh.level=1 --set time.dt=0.02 --stop-after 5 --threads 1 --quiet --out " +
                      dir + "/real");
  ASSERT_EQ(run.code, 3) << run.err;
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &h), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(h, "UPDATE cases SET status='queued', resumable=1, attempts=1, "
                            "error='interrupted (checkpoint written; resumes with --resume)' WHERE case_id IN "
                            "(SELECT case_id FROM cases ORDER BY case_id LIMIT 1)", nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(h);
  std::string folder = sql(db, "SELECT out_dir FROM cases ORDER BY case_id LIMIT 1");
  while (!folder.empty() && (folder.back() == '\n' || folder.back() == '\r')) folder.pop_back();
  ASSERT_FALSE(folder.empty());
  const auto work_left = [](const std::string& out) {
    const auto at = out.find("work left: about ");
    return at == std::string::npos ? -1.0 : std::stod(out.substr(at + 17));
  };
  const auto whole = sh(exe() + " campaign status --db " + db);
  ASSERT_EQ(whole.code, 0) << whole.err;
  std::filesystem::copy_file(dir + "/real/checkpoint.h5", folder + "/checkpoint.h5",
                             std::filesystem::copy_options::overwrite_existing);
  const auto st = sh(exe() + " campaign status --db " + db);
  ASSERT_EQ(st.code, 0) << st.err;
  EXPECT_NE(st.out.find("(checkpoint at γ̇t = 0.1 of 0.4)"), std::string::npos) << st.out;
  // The work left is the part after the checkpoint (printed to two digits: ±2 %), not the whole case.
  ASSERT_GT(work_left(whole.out), 0) << whole.out;
  EXPECT_NEAR(work_left(st.out) / work_left(whole.out), 0.75, 0.03) << whole.out << st.out;
  // A corrupt checkpoint is said to be one (a resumed worker refuses it with exit 2), not a crash.
  write_file(folder + "/checkpoint.h5", "not HDF5");
  const auto bad = sh(exe() + " campaign status --db " + db);
  ASSERT_EQ(bad.code, 0) << bad.err;
  EXPECT_NE(bad.out.find("(checkpoint unreadable: resuming will fail"), std::string::npos) << bad.out;
}

}  // namespace
}  // namespace capsim::campaign::testing
