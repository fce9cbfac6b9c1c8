// Faults: crashing / blowing-up / failing workers, stop signals, kill -9 of the manager then resume,
// and a query while the campaign runs.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <map>
#include <random>
#include <set>

#include "campaign/scheduler/worker_process.h"
#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

const std::string kTwelve = R"([campaign]
name = "twelve"
[defaults]
mesh.level = 1
[[grid]]
aspect_ratio = [0.5]
law = ["neo-hookean", "skalak"]
capillary_number = { start = 0.01, stop = 0.06, step = 0.01 }
)";

std::string sql_csv(const std::string& db, const std::string& q) {
  auto r = sh(exe() + " query sql \"" + q + "\" --db " + db + " --format csv");
  EXPECT_EQ(r.code, 0) << q << ": " << r.err;
  auto nl = r.out.find('\n');
  return nl == std::string::npos ? "" : r.out.substr(nl + 1);  // without the header
}

TEST(Faults, CrashBlowUpAndFailureAreRecordedAndTheRestFinishes) {
  const std::string dir = fresh_dir("faults_crash");
  const std::string db = dir + "/study.db";
  write_file(dir + "/c.toml", kTwelve);
  auto r = sh(campaign_cmd("FAKE_STEPS=2 FAKE_CRASH_CA=0.02 FAKE_UNSTABLE_CA=0.04 FAKE_FAIL_CA=0.05 "
                           "FAKE_BADINPUT_CA=0.06", dir + "/c.toml", db, "--jobs 2"));
  EXPECT_EQ(r.code, 1) << r.err;  // finished, with failures
  EXPECT_NE(r.err.find("failed"), std::string::npos);
  EXPECT_EQ(sql_csv(db, "SELECT status, count(*) FROM cases GROUP BY status ORDER BY status"),
            "done,4\nfailed,6\nunstable,2\n");
  auto crash = sql_csv(db, "SELECT error FROM cases WHERE capillary_number=0.02 AND law='skalak'");
  EXPECT_NE(crash.find("signal 11"), std::string::npos) << crash;
  EXPECT_NE(crash.find("crashing"), std::string::npos) << crash;  // stderr tail
  auto fail = sql_csv(db, "SELECT error FROM cases WHERE capillary_number=0.05 AND law='skalak'");
  EXPECT_NE(fail.find("code 1"), std::string::npos) << fail;
  EXPECT_NE(fail.find("singular matrix"), std::string::npos) << fail;
  EXPECT_NE(sql_csv(db, "SELECT error FROM cases WHERE capillary_number=0.06 LIMIT 1").find("bad input"),
            std::string::npos);
  auto unstable = sql_csv(db, "SELECT c.error, r.status FROM cases c JOIN results r USING(case_id) "
                              "WHERE c.capillary_number=0.04 AND c.law='skalak'");
  EXPECT_NE(unstable.find("NaN in velocity"), std::string::npos) << unstable;
  // Failed cases are not retried by default; --retry-failed retries them (now healthy).
  r = sh(campaign_cmd("FAKE_STEPS=1", dir + "/c.toml", db, "--jobs 2"));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(sql_csv(db, "SELECT count(*) FROM cases WHERE status='failed'"), "6\n");
  auto dry = sh(campaign_cmd("", dir + "/c.toml", db, "--dry-run --retry-failed"));
  EXPECT_EQ(dry.code, 0);
  EXPECT_NE(dry.out.find("run: retry failed"), std::string::npos) << dry.out;
  r = sh(campaign_cmd("FAKE_STEPS=1", dir + "/c.toml", db, "--jobs 2 --retry-failed"));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sql_csv(db, "SELECT status, count(*) FROM cases GROUP BY status ORDER BY status"), "done,10\nunstable,2\n");
  EXPECT_EQ(sql_csv(db, "SELECT max(attempts) FROM cases"), "2\n");
}

TEST(Faults, StopSignalCheckpointsWorkersAndRerunResumes) {
  const std::string dir = fresh_dir("faults_sigterm");
  const std::string db = dir + "/study.db";
  write_file(dir + "/c.toml", kTwelve);
  for (int sig : {SIGTERM, SIGINT}) {
    fs::remove_all(dir + "/study.db.runs");
    fs::remove(db);
    // 100 steps of 0.05 s: no case finishes between the workers' first checkpoint and the signal.
    pid_t pid = spawn_sh(campaign_cmd("FAKE_STEPS=100 FAKE_STEP_S=0.05", dir + "/c.toml", db, "--jobs 2"));
    ASSERT_TRUE(wait_for_checkpoints(db + ".runs", 2, 30)) << "the two workers did not start";
    kill(pid, sig);
    EXPECT_EQ(wait_child(pid, 30), 3);  // interrupted
    auto interrupted = sql_csv(db, "SELECT count(*) FROM cases WHERE status='queued' AND resumable=1");
    EXPECT_EQ(interrupted, "2\n");  // the two running cases checkpointed
    EXPECT_EQ(sql_csv(db, "SELECT count(*) FROM cases WHERE status='running'"), "0\n");
    auto dry = sh(campaign_cmd("", dir + "/c.toml", db, "--dry-run"));
    EXPECT_NE(dry.out.find("resume from checkpoint"), std::string::npos) << dry.out;
    auto r = sh(campaign_cmd("FAKE_STEPS=100 FAKE_STEP_S=0.002", dir + "/c.toml", db, "--jobs 2"));
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(sql_csv(db, "SELECT count(*) FROM results"), "12\n");
    EXPECT_EQ(sql_csv(db, "SELECT count(*) FROM attempts WHERE resumed=1 AND outcome='done'"), "2\n");
    EXPECT_EQ(sql_csv(db, "SELECT count(*) FROM attempts WHERE outcome='interrupted'"), "2\n");
  }
}

// scripts/checkpoints carries the checkpoints of a stopped campaign to a clone without the case folders (they
// are not committed): save, lose DB.runs, restore, rerun -> the two interrupted cases resume, not restart.
TEST(Faults, CheckpointsCarriedByTheScriptResumeInAFreshRunsFolder) {
  const std::string dir = fresh_dir("faults_carry");
  const std::string db = dir + "/study.db";
  const std::string script = std::string(CAPSIM_SOURCE_DIR) + "/scripts/checkpoints";
  write_file(dir + "/c.toml", kTwelve);
  pid_t pid = spawn_sh(campaign_cmd("FAKE_STEPS=100 FAKE_STEP_S=0.05", dir + "/c.toml", db, "--jobs 2"));
  ASSERT_TRUE(wait_for_checkpoints(db + ".runs", 2, 30)) << "the two workers did not start";
  kill(pid, SIGTERM);
  ASSERT_EQ(wait_child(pid, 30), 3);
  ASSERT_EQ(sql_csv(db, "SELECT count(*) FROM cases WHERE status='queued' AND resumable=1"), "2\n");
  auto saved = sh(script + " save " + db);
  ASSERT_EQ(saved.code, 0) << saved.err;
  EXPECT_NE(saved.out.find("2 case folder(s)"), std::string::npos) << saved.out;
  EXPECT_EQ(count_lines(sh(script + " list " + db).out), 2);
  fs::remove_all(db + ".runs");  // the fresh clone
  auto restored = sh(script + " restore " + db);
  ASSERT_EQ(restored.code, 0) << restored.err;
  EXPECT_NE(restored.out.find("2 case folder(s) restored"), std::string::npos) << restored.out;
  auto r = sh(campaign_cmd("FAKE_STEPS=100 FAKE_STEP_S=0.002", dir + "/c.toml", db, "--jobs 2"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sql_csv(db, "SELECT count(*) FROM attempts WHERE resumed=1 AND outcome='done'"), "2\n");
  // Bad input: one message, exit 2, nothing changed.
  EXPECT_EQ(sh(script + " restore " + dir + "/nope.db").code, 2);
  EXPECT_EQ(sh(script + " frobnicate " + db).code, 2);
  // Nothing resumable left: save says so and removes the stale archive; restore then has nothing to read.
  ASSERT_EQ(sh(script + " save " + db).code, 0);
  EXPECT_FALSE(fs::exists(db + ".checkpoints.tar.gz"));
  EXPECT_EQ(sh(script + " restore " + db).code, 2);
}

// Found while a copy of a running campaign's database was analysed: the copy kept the original's absolute
// case folders and its manager rewrote their case.toml and truncated a live worker's logs. A campaign run on
// a copy must write only under its own runs folder.
TEST(Faults, ACopyOfTheDatabaseNeverWritesIntoTheOriginalsCaseFolders) {
  const std::string dir = fresh_dir("faults_copy");
  const std::string db = dir + "/study.db";
  write_file(dir + "/c.toml", kTwelve);
  pid_t pid = spawn_sh(campaign_cmd("FAKE_STEPS=100 FAKE_STEP_S=0.05", dir + "/c.toml", db, "--jobs 2"));
  ASSERT_TRUE(wait_for_checkpoints(db + ".runs", 2, 30)) << "the two workers did not start";
  kill(pid, SIGINT);
  ASSERT_EQ(wait_child(pid, 30), 3);  // interrupted: two resumable cases, the rest queued or done
  const auto before = folder_snapshot(db + ".runs");
  ASSERT_FALSE(before.empty());
  fs::create_directories(dir + "/copy");
  fs::copy_file(db, dir + "/copy/study.db");
  auto r = sh(campaign_cmd("FAKE_STEPS=2 FAKE_STEP_S=0.001", dir + "/c.toml", dir + "/copy/study.db", "--jobs 2"));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sql_csv(dir + "/copy/study.db", "SELECT count(*) FROM cases WHERE status='done'"), "12\n");
  EXPECT_EQ(folder_snapshot(db + ".runs"), before) << "the copy wrote into the original's case folders";
  // The cases that had not finished in the original ran in the copy's own folder.
  const std::string unfinished = sql_csv(db, "SELECT count(*) FROM cases WHERE status != 'done'");
  EXPECT_NE(unfinished, "0\n");
  EXPECT_EQ(sql_csv(dir + "/copy/study.db",
                    "SELECT count(*) FROM cases WHERE out_dir LIKE '" + dir + "/copy/study.db.runs/%'"),
            unfinished);
}

TEST(Faults, KillNineOfTheManagerThenResumeRunsEveryCaseExactlyOnce) {
  const std::string dir = fresh_dir("faults_kill9");
  const std::string db = dir + "/study.db";
  const std::string log = dir + "/completions.log";
  write_file(dir + "/c.toml", kTwelve);
  const std::string env = "FAKE_STEPS=6 FAKE_STEP_S=0.04 FAKE_LOG=" + log;
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> delay_ms(50, 600);
  int kills = 0;
  for (int round = 0; round < 6; ++round) {
    pid_t pid = spawn_sh(campaign_cmd(env, dir + "/c.toml", db, "--jobs 3"));
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(rng)));
    if (kill(pid, SIGKILL) == 0) ++kills;
    wait_child(pid, 10);
  }
  EXPECT_GE(kills, 1);
  auto r = sh(campaign_cmd(env, dir + "/c.toml", db, "--jobs 3"));
  EXPECT_EQ(r.code, 0) << r.err;
  // Every case finished exactly once: one result row each, one completed attempt each, one completion.
  EXPECT_EQ(sql_csv(db, "SELECT count(*) FROM cases WHERE status='done'"), "12\n");
  EXPECT_EQ(sql_csv(db, "SELECT count(*) FROM results"), "12\n");
  EXPECT_EQ(sql_csv(db, "SELECT count(*) FROM (SELECT case_id FROM attempts WHERE outcome IN ('done','ingested') "
                        "GROUP BY case_id HAVING count(*) = 1)"), "12\n");
  EXPECT_EQ(sql_csv(db, "SELECT count(*) FROM attempts WHERE finished_at IS NULL"), "0\n");
  EXPECT_EQ(sql_csv(db, "PRAGMA integrity_check"), "ok\n");
  std::map<std::string, int> completions;
  std::istringstream in(read_file(log));
  std::string word, path;
  while (in >> word >> path) completions[path]++;
  EXPECT_EQ(completions.size(), 12u);
  for (const auto& [p, n] : completions) EXPECT_EQ(n, 1) << p;
  // No orphaned worker is left running.
  EXPECT_TRUE(find_orphan_workers(db + ".runs").empty());
  // Re-running does nothing.
  r = sh(campaign_cmd(env, dir + "/c.toml", db, "--jobs 3"));
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(sql_csv(db, "SELECT count(*) FROM attempts WHERE outcome IN ('done','ingested')"), "12\n");
}

TEST(Faults, OrphanWorkerOfADeadManagerIsStoppedAndItsCaseResumed) {
  // A worker that outlives its manager (e.g. parent-death signal lost): the next manager finds it by its
  // --out folder, stops it (it checkpoints) and resumes the case.
  const std::string dir = fresh_dir("faults_orphan");
  const std::string db = dir + "/study.db";
  write_file(dir + "/c.toml", R"([campaign]
name = "one"
[[grid]]
capillary_number = [0.03]
aspect_ratio = [0.5]
)");
  pid_t mgr = spawn_sh(campaign_cmd("FAKE_STEPS=400 FAKE_STEP_S=0.05", dir + "/c.toml", db, "--jobs 1"));
  std::string running;
  for (int i = 0; i < 100 && running != "1\n"; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (fs::exists(db)) running = sql_csv(db, "SELECT count(*) FROM cases WHERE status='running'");
  }
  ASSERT_EQ(running, "1\n");
  // Start a second worker by hand on the same folder, detached from any manager, to play the orphan.
  auto id = sql_csv(db, "SELECT case_id FROM cases");
  id.pop_back();
  const std::string out = fs::weakly_canonical(db + ".runs/" + id).string();
  kill(mgr, SIGKILL);
  wait_child(mgr, 10);
  pid_t orphan = spawn_sh("env " + fake_worker_env() + " FAKE_STEPS=400 FAKE_STEP_S=0.05 " + fake_worker() + " run " + out + "/case.toml --out " +
                          out + " --threads 1 --json");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ASSERT_FALSE(find_orphan_workers(db + ".runs").empty());
  pid_t mgr2 = spawn_sh(campaign_cmd("FAKE_STEPS=400 FAKE_STEP_S=0.001", dir + "/c.toml", db, "--jobs 1"));
  EXPECT_EQ(wait_child(orphan, 30), 3);  // stopped by the new manager, after checkpointing
  EXPECT_EQ(wait_child(mgr2, 60), 0);
  EXPECT_EQ(sql_csv(db, "SELECT status, resumable FROM cases"), "done,0\n");
  EXPECT_EQ(sql_csv(db, "SELECT outcome FROM attempts ORDER BY attempt_id"), "orphaned\ndone\n");
  EXPECT_EQ(sql_csv(db, "SELECT resumed FROM attempts ORDER BY attempt_id DESC LIMIT 1"), "1\n");
}

TEST(Faults, SecondManagerOnTheSameDatabaseIsRefused) {
  const std::string dir = fresh_dir("faults_lock");
  const std::string db = dir + "/study.db";
  write_file(dir + "/c.toml", kTwelve);
  pid_t mgr = spawn_sh(campaign_cmd("FAKE_STEPS=10 FAKE_STEP_S=0.05", dir + "/c.toml", db, "--jobs 2"));
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  auto r = sh(campaign_cmd("", dir + "/c.toml", db, "--jobs 2"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("another campaign manager"), std::string::npos) << r.err;
  EXPECT_EQ(wait_child(mgr, 60), 0);
}

TEST(Queries, QueryWhileTheCampaignRunsDoesNotBlockIt) {
  const std::string dir = fresh_dir("query_concurrent");
  const std::string db = dir + "/study.db";
  write_file(dir + "/c.toml", kTwelve);
  pid_t mgr = spawn_sh(campaign_cmd("FAKE_STEPS=5 FAKE_STEP_S=0.05", dir + "/c.toml", db, "--jobs 2"));
  for (int i = 0; i < 500 && !fs::exists(db); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_TRUE(fs::exists(db));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  // A reader that holds a read transaction open for the rest of the run.
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open_v2(db.c_str(), &h, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(h, "BEGIN; SELECT count(*) FROM cases;", nullptr, nullptr, nullptr), SQLITE_OK);
  int queries = 0;
  std::set<std::string> done_counts;
  int code = -1000;
  while ((code = wait_child(mgr, 0.05)) == -1000) {
    auto t0 = std::chrono::steady_clock::now();
    auto q = sh(exe() + " query cases --db " + db + " --format csv");
    auto s = sh(exe() + " campaign status --db " + db);
    auto c = sh(exe() + " query sql \"SELECT count(*) FROM cases WHERE status='done'\" --db " + db + " --format csv");
    EXPECT_EQ(q.code, 0) << q.err;
    EXPECT_EQ(s.code, 0) << s.err;
    EXPECT_EQ(c.code, 0) << c.err;
    EXPECT_EQ(count_lines(q.out), 13) << q.out;  // header + 12 cases
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
    done_counts.insert(c.out);
    ++queries;
  }
  sqlite3_exec(h, "COMMIT", nullptr, nullptr, nullptr);
  sqlite3_close(h);
  EXPECT_EQ(code, 0);
  EXPECT_GE(queries, 2);
  EXPECT_GE(done_counts.size(), 2u);  // the queries saw the campaign progress
  EXPECT_EQ(sql_csv(db, "SELECT count(*) FROM results"), "12\n");
}

}  // namespace
}  // namespace capsim::campaign::testing
