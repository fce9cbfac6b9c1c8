// `campaign submit|collect` without a Slurm installation: the sbatch script itself, a stand-in `sbatch`
// and `squeue` in PATH, array tasks run by hand (the generated script with SLURM_ARRAY_TASK_ID set) with
// the fake worker, folders prepared by hand (corrupt / missing results), schema migration 1 -> 2.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <regex>

#include "campaign/slurm/slurm.h"
#include "campaign/store/store.h"
#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

const std::string kSix = R"([campaign]
name = "six"
[defaults]
mesh.level = 1
[[grid]]
aspect_ratio = [0.5]
law = ["neo-hookean", "skalak"]
capillary_number = [0.02, 0.03, 0.04]
)";

/// A folder with stand-ins for sbatch (copies the script to DIR/submitted-N.sh, prints the next job id)
/// and squeue (prints DIR/squeue.txt if present: "JOB|TASK|STATE" lines).
struct FakeSlurm {
  std::string dir;
  explicit FakeSlurm(const std::string& base) : dir(base + "/fakebin") {
    fs::create_directories(dir);
    write_file(dir + "/sbatch", "#!/bin/sh\n"
                                "[ \"$1\" = --parsable ] || { echo 'fake sbatch: expected --parsable' >&2; exit 1; }\n"
                                "n=$(cat " + dir + "/next 2>/dev/null || echo 100)\n"
                                "echo $((n + 1)) > " + dir + "/next\n"
                                "cp \"$2\" " + dir + "/submitted-$n.sh\n"
                                "echo \"$n;cluster\"\n");
    write_file(dir + "/squeue", "#!/bin/sh\ncat " + dir + "/squeue.txt 2>/dev/null\nexit 0\n");
    chmod((dir + "/sbatch").c_str(), 0755);
    chmod((dir + "/squeue").c_str(), 0755);
  }
  /// Environment prefix: the stand-ins first in PATH, the fake worker.
  std::string env(const std::string& extra = "") const {
    return "env PATH=" + dir + ":/usr/bin:/bin " + fake_worker_env() + " " + extra + " ";
  }
  void live(const std::string& lines) const { write_file(dir + "/squeue.txt", lines); }
  std::string script(int job) const { return dir + "/submitted-" + std::to_string(job) + ".sh"; }
};

/// Everything the database holds, as text (for "run twice = same database").
std::string dump(const std::string& db) {
  std::string all;
  for (const char* t : {"campaigns", "cases", "campaign_cases", "results", "attempts", "transitions", "slurm_jobs",
                        "slurm_tasks", "meta"})
    all += std::string(t) + ":\n" + sql(db, std::string("SELECT * FROM ") + t + " ORDER BY 1, 2");
  return all;
}

/// Runs array task @p task of a generated script the way Slurm would (environment set, bash).
CmdResult run_task(const FakeSlurm& f, const std::string& script, int job, int task, const std::string& env = "") {
  return sh(f.env(env + " SLURM_ARRAY_JOB_ID=" + std::to_string(job) + " SLURM_ARRAY_TASK_ID=" + std::to_string(task)) +
            "bash " + script);
}

TEST(SbatchScript, ArraySizeCasesPerTaskAndLimits) {
  EXPECT_EQ(array_size(7, 3), 3);
  EXPECT_EQ(array_size(6, 3), 2);
  EXPECT_EQ(array_size(1, 5), 1);
  EXPECT_EQ(array_size(0, 5), 0);
  SbatchSettings s;
  s.job_name = "capsim-table 1/quick";
  s.worker = "/opt/capsim/bin/capsim";
  s.runs_dir = "/shared/study.db.runs";
  s.log_dir = "/shared/study.db.runs/slurm";
  for (int i = 0; i < 7; ++i) s.case_ids.push_back("case" + std::to_string(i));
  s.cases_per_task = 3;
  s.array_limit = 2;
  s.threads = 4;
  s.partition = "short";
  s.time_limit = "01:30:00";
  const std::string text = make_sbatch_script(s);
  EXPECT_EQ(text.rfind("#!/bin/bash\n", 0), 0u);
  EXPECT_NE(text.find("#SBATCH --array=0-2%2\n"), std::string::npos) << text;
  EXPECT_NE(text.find("#SBATCH --cpus-per-task=4\n"), std::string::npos);
  EXPECT_NE(text.find("#SBATCH --partition=short\n"), std::string::npos);
  EXPECT_NE(text.find("#SBATCH --time=01:30:00\n"), std::string::npos);
  EXPECT_NE(text.find("#SBATCH --signal=B:TERM@60\n"), std::string::npos);
  EXPECT_NE(text.find("#SBATCH --job-name=capsim-table_1_quick\n"), std::string::npos);
  EXPECT_NE(text.find("#SBATCH --output=/shared/study.db.runs/slurm/%A_%a.out\n"), std::string::npos);
  EXPECT_NE(text.find("per_task=3\n"), std::string::npos);
  EXPECT_NE(text.find("capsim='/opt/capsim/bin/capsim'"), std::string::npos);
  EXPECT_NE(text.find("'case6'"), std::string::npos);
  // No limit, no partition, no time: those lines are absent; every #SBATCH line precedes the first command.
  s.array_limit = 0;
  s.partition.clear();
  s.time_limit.clear();
  s.cases_per_task = 1;
  const std::string plain = make_sbatch_script(s);
  EXPECT_NE(plain.find("#SBATCH --array=0-6\n"), std::string::npos) << plain;
  EXPECT_EQ(plain.find("--partition"), std::string::npos);
  EXPECT_EQ(plain.find("#SBATCH --time"), std::string::npos);
  EXPECT_LT(plain.rfind("#SBATCH"), plain.find("set -u"));
  // Time formats sbatch accepts.
  for (const char* ok : {"30", "30:00", "01:30:00", "2-00", "2-12:00", "2-12:00:00"}) EXPECT_TRUE(valid_slurm_time(ok)) << ok;
  for (const char* bad : {"", "1h", "01:30:00:00", "-5", "1:2:3:4", "ab:cd"}) EXPECT_FALSE(valid_slurm_time(bad)) << bad;
}

TEST(SlurmSubmit, FakeSbatchThenTasksByHandThenCollectEqualsCampaignRun) {
  const std::string dir = fresh_dir("slurm_submit_collect");
  write_file(dir + "/c.toml", kSix);
  const std::string db = dir + "/study.db";
  FakeSlurm f(dir);
  auto r = sh(f.env("FAKE_STEPS=1") + exe() + " campaign submit " + dir + "/c.toml --db " + db +
              " --cases-per-task 4 --array-limit 1 --partition debug --time 00:10:00");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("submitted job 100: 6 case(s)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("2 array task(s)"), std::string::npos) << r.out;
  const std::string script = read_file(f.script(100));
  EXPECT_NE(script.find("#SBATCH --array=0-1%1"), std::string::npos) << script;
  EXPECT_NE(script.find("#SBATCH --partition=debug"), std::string::npos);
  EXPECT_EQ(sql(db, "SELECT job_id, n_tasks, n_cases, cases_per_task, array_limit, state FROM slurm_jobs"),
            "100,2,6,4,1,submitted\n");
  EXPECT_EQ(sql(db, "SELECT task_index, count(*) FROM slurm_tasks GROUP BY 1 ORDER BY 1"), "0,4\n1,2\n");
  EXPECT_EQ(sql(db, "SELECT count(*) FROM cases WHERE status='queued'"), "6\n");
  // While the job is queued, a second submit hands nothing out twice.
  f.live("100|0|PENDING\n100|1|PENDING\n");
  r = sh(f.env() + exe() + " campaign submit " + dir + "/c.toml --db " + db);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("nothing to submit"), std::string::npos) << r.out;
  auto st = sh(f.env() + exe() + " campaign status --db " + db);
  EXPECT_NE(st.out.find("slurm job 100"), std::string::npos) << st.out;
  EXPECT_NE(st.out.find("2 PENDING"), std::string::npos) << st.out;
  // ... and a local `campaign run` refuses while the cases are in live array tasks.
  r = sh(f.env() + exe() + " campaign run " + dir + "/c.toml --db " + db);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("Slurm job(s) 100"), std::string::npos) << r.err;
  // The array tasks run (by hand); the tasks never open the database.
  const std::string before_tasks = dump(db);
  for (int task = 0; task < 2; ++task) {
    auto t = run_task(f, f.script(100), 100, task, "FAKE_STEPS=1");
    EXPECT_EQ(t.code, 0) << t.out << t.err;
  }
  EXPECT_EQ(dump(db), before_tasks);
  f.live("");
  r = sh(f.env() + exe() + " campaign collect --db " + db);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("ingested 6 result(s)"), std::string::npos) << r.out;
  const std::string once = dump(db);
  r = sh(f.env() + exe() + " campaign collect --db " + db);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("ingested 0 result(s)"), std::string::npos) << r.out;
  EXPECT_EQ(dump(db), once);  // idempotent
  EXPECT_EQ(sql(db, "SELECT count(*) FROM results"), "6\n");
  EXPECT_EQ(sql(db, "SELECT count(*) FROM attempts"), "6\n");
  EXPECT_EQ(sql(db, "SELECT state FROM slurm_jobs"), "collected\n");
  EXPECT_EQ(sql(db, "SELECT DISTINCT state FROM slurm_tasks"), "ingested\n");
  // The same file through `campaign run`: same identities, statuses, results and transitions.
  const std::string ref = dir + "/ref.db";
  r = sh(campaign_cmd("FAKE_STEPS=1", dir + "/c.toml", ref));
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string q_cases = "SELECT c.case_id, c.status, c.params_json, r.status, r.min_D12, r.max_tau_min, "
                              "r.mean_D12, r.period, r.regime, r.volume_drift, r.steps FROM cases c LEFT JOIN results r "
                              "USING(case_id) ORDER BY 1";
  EXPECT_EQ(sql(db, q_cases), sql(ref, q_cases));
  const std::string q_tr = "SELECT law, aspect_ratio, skalak_C, n_samples, ca_star_low, ca_star_high, ca_h, method, note "
                           "FROM transitions ORDER BY 1, 2";
  EXPECT_EQ(sql(db, q_tr), sql(ref, q_tr));
  // Everything done: nothing to submit.
  r = sh(f.env() + exe() + " campaign submit " + dir + "/c.toml --db " + db);
  EXPECT_NE(r.out.find("nothing to submit"), std::string::npos) << r.out;
}

TEST(SlurmSubmit, CollectIsExactlyOnceAndSkipsCorruptOrMissingResults) {
  const std::string dir = fresh_dir("slurm_corrupt");
  write_file(dir + "/c.toml", kSix);
  const std::string db = dir + "/study.db";
  FakeSlurm f(dir);
  auto r = sh(f.env() + exe() + " campaign submit " + dir + "/c.toml --db " + db);
  ASSERT_EQ(r.code, 0) << r.err;
  std::vector<std::string> ids;
  {
    std::istringstream in(sql(db, "SELECT case_id FROM slurm_tasks ORDER BY task_index"));
    std::string id;
    while (std::getline(in, id)) ids.push_back(id);
  }
  ASSERT_EQ(ids.size(), 6u);
  const std::string runs = db + ".runs/";
  // Folders prepared by hand, as array tasks of job 100 would leave them:
  //  ids[0]: a complete result (task 0)         ids[1]: result.json written half-way (task 1, exit 0)
  //  ids[2]: interrupted, checkpoint (task 2)   ids[3]: worker failed with exit 1 (task 3)
  //  ids[4]: nothing (task 4 never ran it)      ids[5]: task 5 still running
  auto exit_json = [&](int task, const std::string& id, int code) {
    write_file(runs + id + "/slurm_exit.json", "{\"job\":\"100_" + std::to_string(task) + "\",\"case_id\":\"" + id +
                                                   "\",\"exit_code\":" + std::to_string(code) +
                                                   ",\"host\":\"n1\",\"wall_s\":1.5,\"resumed\":false}\n");
  };
  auto fake = sh(f.env("FAKE_STEPS=1") + fake_worker() + " run " + runs + ids[0] + "/case.toml --out " + runs + ids[0] +
                 " --json");
  ASSERT_EQ(fake.code, 0) << fake.err;
  const std::string good = fake.out;
  write_file(runs + ids[0] + "/result.json", good);
  exit_json(0, ids[0], 0);
  write_file(runs + ids[1] + "/result.json", good.substr(0, good.size() / 2));
  exit_json(1, ids[1], 0);
  write_file(runs + ids[2] + "/checkpoint.txt", "3\n");
  exit_json(2, ids[2], 3);
  write_file(runs + ids[3] + "/stderr.log", "fake_worker: singular matrix\n");
  exit_json(3, ids[3], 1);
  // Job still live: only the complete result is ingested; nothing else is decided yet.
  f.live("100|1|RUNNING\n100|2|RUNNING\n100|3|RUNNING\n100|4|RUNNING\n100|5|RUNNING\n");
  r = sh(f.env() + exe() + " campaign collect --db " + db);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("ingested 1 result(s)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not ingested: " + runs + ids[1] + "/result.json"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("5 case(s) still in queued/running array tasks"), std::string::npos) << r.out;
  EXPECT_EQ(sql(db, "SELECT status, count(*) FROM cases GROUP BY 1 ORDER BY 1"), "done,1\nqueued,5\n");
  // Tasks 1-4 end; 5 still runs.
  f.live("100|5|RUNNING\n");
  r = sh(f.env() + exe() + " campaign collect --db " + db);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("ingested 0 result(s) (done 0, unstable 0), 2 failed, 1 interrupted (resumable), 1 lost"),
            std::string::npos) << r.out;
  auto status_of = [&](const std::string& id) {
    return sql(db, "SELECT status, resumable FROM cases WHERE case_id='" + id + "'");
  };
  EXPECT_EQ(status_of(ids[0]), "done,0\n");
  EXPECT_EQ(status_of(ids[1]), "failed,0\n");  // exit 0 but no valid result: not ingested, recorded as failed
  EXPECT_EQ(status_of(ids[2]), "queued,1\n");  // resumes from its checkpoint
  EXPECT_EQ(status_of(ids[3]), "failed,0\n");
  EXPECT_EQ(status_of(ids[4]), "queued,0\n");
  EXPECT_EQ(status_of(ids[5]), "queued,0\n");
  EXPECT_NE(sql(db, "SELECT error FROM cases WHERE case_id='" + ids[3] + "'").find("singular matrix"), std::string::npos);
  EXPECT_EQ(sql(db, "SELECT count(*) FROM results"), "1\n");
  const std::string once = dump(db);
  r = sh(f.env() + exe() + " campaign collect --db " + db);
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(dump(db), once);
  // Resubmission: the interrupted and lost cases (not the live one, not the failed ones) go to a new job,
  // the interrupted one with --resume; --retry-failed adds the failed ones.
  r = sh(f.env() + exe() + " campaign submit " + dir + "/c.toml --db " + db);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("submitted job 101: 2 case(s)"), std::string::npos) << r.out;
  EXPECT_EQ(sql(db, "SELECT case_id, resumed FROM slurm_tasks WHERE job_id='101' ORDER BY case_id"),
            sql(db, "SELECT case_id, case_id='" + ids[2] + "' FROM cases WHERE case_id IN ('" + ids[2] + "','" + ids[4] +
                        "') ORDER BY case_id"));
  f.live("100|5|RUNNING\n101|[0-1]|PENDING\n");  // squeue folds pending array ranges
  r = sh(f.env() + exe() + " campaign submit " + dir + "/c.toml --db " + db + " --retry-failed");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("submitted job 102: 2 case(s)"), std::string::npos) << r.out;
  // The half-written result was kept aside, so the task does not skip that case.
  EXPECT_FALSE(fs::exists(runs + ids[1] + "/result.json"));
}

TEST(SlurmSubmit, SigtermToTheTaskCheckpointsAndResubmissionResumes) {
  const std::string dir = fresh_dir("slurm_sigterm");
  write_file(dir + "/c.toml", kSix);
  const std::string db = dir + "/study.db";
  FakeSlurm f(dir);
  auto r = sh(f.env() + exe() + " campaign submit " + dir + "/c.toml --db " + db + " --cases-per-task 6");
  ASSERT_EQ(r.code, 0) << r.err;
  // Slurm's --signal=B:TERM reaches the batch shell; it forwards it to the worker, which checkpoints (exit 3).
  pid_t pid = spawn_sh(f.env("FAKE_STEPS=200 FAKE_STEP_S=0.02 SLURM_ARRAY_JOB_ID=100 SLURM_ARRAY_TASK_ID=0") + "bash " +
                       f.script(100));
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  kill(pid, SIGTERM);
  EXPECT_EQ(wait_child(pid, 30), 3);
  r = sh(f.env() + exe() + " campaign collect --db " + db);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("1 interrupted (resumable), 5 lost"), std::string::npos) << r.out;
  EXPECT_EQ(sql(db, "SELECT count(*) FROM cases WHERE status='queued' AND resumable=1"), "1\n");
  r = sh(f.env() + exe() + " campaign submit " + dir + "/c.toml --db " + db + " --cases-per-task 6");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sql(db, "SELECT sum(resumed) FROM slurm_tasks WHERE job_id='101'"), "1\n");
  auto t = run_task(f, f.script(101), 101, 0, "FAKE_STEPS=200 FAKE_STEP_S=0.001");
  EXPECT_EQ(t.code, 0) << t.out << t.err;
  r = sh(f.env() + exe() + " campaign collect --db " + db);
  EXPECT_NE(r.out.find("ingested 6 result(s)"), std::string::npos) << r.out;
  EXPECT_EQ(sql(db, "SELECT count(*) FROM attempts WHERE resumed=1 AND outcome='done'"), "1\n");
  EXPECT_EQ(sql(db, "SELECT count(*) FROM attempts WHERE outcome='interrupted'"), "1\n");
}

TEST(SlurmSubmit, BadInputChangesNothing) {
  const std::string dir = fresh_dir("slurm_bad_input");
  write_file(dir + "/c.toml", kSix);
  const std::string db = dir + "/study.db";
  // sbatch missing: one clear message, exit 2, no database created.
  // (PATH is an empty folder, so a Slurm installed on this machine stays hidden.)
  fs::create_directories(dir + "/empty");
  auto r = sh("env PATH=" + dir + "/empty " + fake_worker_env() + " " + exe() + " campaign submit " + dir +
              "/c.toml --db " + db);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("sbatch not found"), std::string::npos) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_FALSE(fs::exists(db));
  EXPECT_FALSE(fs::exists(db + ".runs"));
  FakeSlurm f(dir);
  for (const char* bad : {"--time 1h", "--time 01:00:00:00", "--cases-per-task 0", "--array-limit 0",
                                 "--threads-per-job 0", "--partition 'a b'", "--bogus"}) {
    r = sh(f.env() + exe() + " campaign submit " + dir + "/c.toml --db " + db + " " + bad);
    EXPECT_EQ(r.code, 2) << bad << ": " << r.err;
    EXPECT_EQ(count_lines(r.err), 1) << bad << ": " << r.err;
    EXPECT_FALSE(fs::exists(db)) << bad;
  }
  r = sh(f.env() + exe() + " campaign collect --db " + dir + "/missing.db");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("missing.db"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/missing.db"));
  // --dry-run prints the script and writes nothing.
  r = sh(f.env() + exe() + " campaign submit " + dir + "/c.toml --db " + db + " --dry-run --cases-per-task 2");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("#SBATCH --array=0-2\n"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(db));
  EXPECT_FALSE(fs::exists(f.script(100)));
}

TEST(SlurmSubmit, SchemaVersion1IsReadAsIsAndMigratedByAWriter) {
  const std::string dir = fresh_dir("slurm_migrate");
  write_file(dir + "/c.toml", kSix);
  const std::string db = dir + "/study.db";
  auto r = sh(campaign_cmd("FAKE_STEPS=1", dir + "/c.toml", db));
  ASSERT_EQ(r.code, 0) << r.err;
  // Make it a version-1 database, as an older capsim left it.
  r = sh("sqlite3 " + db + " 'DROP TABLE slurm_tasks; DROP TABLE slurm_jobs; PRAGMA user_version = 1;'");
  if (r.code != 0) GTEST_SKIP() << "sqlite3 command-line tool not available";
  const std::string results = sql(db, "SELECT * FROM results ORDER BY 1");
  // Readers take it as it is (no write).
  auto st = sh(exe() + " campaign status --db " + db);
  EXPECT_EQ(st.code, 0) << st.err;
  EXPECT_EQ(sql(db, "PRAGMA user_version"), "1\n");
  // A writer migrates it in one transaction, keeping everything.
  FakeSlurm f(dir);
  r = sh(f.env() + exe() + " campaign collect --db " + db);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sql(db, "PRAGMA user_version"), std::to_string(Store::expected_schema_version()) + "\n");
  EXPECT_EQ(sql(db, "SELECT count(*) FROM slurm_jobs"), "0\n");
  EXPECT_EQ(sql(db, "SELECT value FROM meta WHERE key='migrated_from'"), "1\n");
  EXPECT_EQ(sql(db, "SELECT * FROM results ORDER BY 1"), results);
  EXPECT_EQ(sql(db, "PRAGMA integrity_check"), "ok\n");
  // A newer version is refused.
  const std::string newer = std::to_string(Store::expected_schema_version() + 1);
  r = sh("sqlite3 " + db + " 'PRAGMA user_version = " + newer + ";'");
  r = sh(f.env() + exe() + " campaign collect --db " + db);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("schema version " + newer), std::string::npos) << r.err;
}

}  // namespace
}  // namespace capsim::campaign::testing
