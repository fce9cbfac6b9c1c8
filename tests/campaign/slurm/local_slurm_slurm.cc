// Label `slurm` (not in the default suite): campaigns submitted to a real Slurm (scripts/setup-slurm starts
// a single-node one), waited for, collected; the database then equals the one `campaign run` produces for
// the same file. Skips with a message when Slurm is not available.
//  - RealSolver...: the real solver (`capsim run`, mesh level 1, t_end 20: about 2 s per case) as the worker.
//  - FakeWorker...: the fake worker (slow steps) so the SIGTERM path is deterministic: Slurm signals the
//    batch shell (scancel --batch --signal=TERM, what --signal=B:TERM@60 does before the time limit), the
//    worker checkpoints, collect requeues it resumable, a resubmission resumes it.
#include <gtest/gtest.h>

#include <cmath>
#include <regex>

#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

std::string slurm_unavailable() {
  auto r = sh("sinfo -h -o %T");
  if (r.code != 0) return "sinfo not available or no controller (" + r.err + "); start one with scripts/setup-slurm";
  if (r.out.find("idle") == std::string::npos && r.out.find("mix") == std::string::npos &&
      r.out.find("alloc") == std::string::npos)
    return "no usable Slurm node (sinfo: " + r.out + ")";
  return "";
}

std::string job_of(const std::string& submit_out) {
  std::smatch m;
  if (std::regex_search(submit_out, m, std::regex(R"(submitted job (\d+))"))) return m[1];
  return "";
}

/// Waits until squeue no longer lists @p job (or its state is @p until, if given); false on timeout.
bool wait_job(const std::string& job, double timeout_s, const std::string& until = "") {
  auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < deadline) {
    auto r = sh("squeue -h -r -j " + job + " -o %T");
    if (r.out.empty() && until.empty()) return true;
    if (!until.empty() && r.out.find(until) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }
  return false;
}

/// Compares two CSV tables cell by cell, numbers to a relative 1e-10.
void expect_same_table(const std::string& a, const std::string& b) {
  std::istringstream ia(a), ib(b);
  std::string la, lb;
  int row = 0;
  while (true) {
    bool ga = static_cast<bool>(std::getline(ia, la)), gb = static_cast<bool>(std::getline(ib, lb));
    ASSERT_EQ(ga, gb) << "row count differs at row " << row << "\n" << a << "\nvs\n" << b;
    if (!ga) break;
    std::vector<std::string> ca, cb;
    std::string cell;
    for (std::istringstream s(la); std::getline(s, cell, ',');) ca.push_back(cell);
    for (std::istringstream s(lb); std::getline(s, cell, ',');) cb.push_back(cell);
    ASSERT_EQ(ca.size(), cb.size()) << la << " vs " << lb;
    for (std::size_t i = 0; i < ca.size(); ++i) {
      char* ea = nullptr;
      char* eb = nullptr;
      double x = std::strtod(ca[i].c_str(), &ea), y = std::strtod(cb[i].c_str(), &eb);
      if (!ca[i].empty() && !cb[i].empty() && *ea == '\0' && *eb == '\0')
        EXPECT_LE(std::fabs(x - y), 1e-10 * std::max(1.0, std::fabs(y))) << "row " << row << " col " << i;
      else
        EXPECT_EQ(ca[i], cb[i]) << "row " << row << " col " << i;
    }
    ++row;
  }
}

const char* kCasesQuery = "SELECT c.case_id, c.status, c.params_json, c.solver_version, r.status, r.min_D12, "
                          "r.max_tau_min, r.mean_D12, r.period, r.regime, r.volume_drift, r.steps, r.dt, r.t_final "
                          "FROM cases c LEFT JOIN results r USING(case_id) ORDER BY 1";
const char* kTransitionsQuery = "SELECT law, aspect_ratio, skalak_C, mesh_level, n_samples, ca_star_low, ca_star_high, "
                                "ca_h, ca_h_low, ca_h_high, method, note FROM transitions ORDER BY 1, 2, 3";

TEST(LocalSlurm, RealSolverCampaignSubmittedCollectedEqualsCampaignRun) {
  if (auto why = slurm_unavailable(); !why.empty()) GTEST_SKIP() << why;
  const std::string dir = fresh_dir("local_slurm_real");
  write_file(dir + "/c.toml", R"([campaign]
name = "slurm-real"
[defaults]
mesh.level = 1
time.t_end = 20.0
[[grid]]
aspect_ratio = [0.5]
law = ["neo-hookean", "skalak"]
capillary_number = [0.05, 0.1, 0.2]
)");
  const std::string db = dir + "/slurm.db", ref = dir + "/local.db";
  auto r = sh("env -u CAPSIM_WORKER " + exe() + " campaign submit " + dir + "/c.toml --db " + db +
              " --cases-per-task 2 --array-limit 2 --time 00:10:00");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string job = job_of(r.out);
  ASSERT_FALSE(job.empty()) << r.out;
  EXPECT_NE(r.out.find("3 array task(s)"), std::string::npos) << r.out;
  auto st = sh(exe() + " campaign status --db " + db);
  EXPECT_NE(st.out.find("slurm job " + job), std::string::npos) << st.out;
  ASSERT_TRUE(wait_job(job, 900)) << "job " << job << " did not finish";
  r = sh(exe() + " campaign collect --db " + db);
  ASSERT_EQ(r.code, 0) << r.err;
  std::printf("%s", r.out.c_str());
  EXPECT_NE(r.out.find("ingested 6 result(s)"), std::string::npos) << r.out
      << read_file(db + ".runs/" + sql(db, "SELECT case_id FROM cases LIMIT 1").substr(0, 16) + "/stderr.log");
  const std::string once = sql(db, kCasesQuery) + sql(db, "SELECT * FROM attempts ORDER BY 1");
  r = sh(exe() + " campaign collect --db " + db);
  EXPECT_EQ(sql(db, kCasesQuery) + sql(db, "SELECT * FROM attempts ORDER BY 1"), once);
  r = sh("env -u CAPSIM_WORKER " + exe() + " campaign run " + dir + "/c.toml --db " + ref + " --jobs 2 --threads-per-job 1");
  ASSERT_TRUE(r.code == 0 || r.code == 1) << r.err;
  expect_same_table(sql(db, kCasesQuery), sql(ref, kCasesQuery));
  expect_same_table(sql(db, kTransitionsQuery), sql(ref, kTransitionsQuery));
  EXPECT_EQ(sql(db, "SELECT count(*) FROM cases WHERE status IN ('done','unstable')"), "6\n");
  // The comparison is not vacuous: the runs are long enough for a period and real diagnostics.
  EXPECT_EQ(sql(db, "SELECT count(*) FROM results WHERE min_D12 IS NOT NULL AND period IS NOT NULL"), "6\n");
  EXPECT_EQ(sql(db, "PRAGMA integrity_check"), "ok\n");
}

TEST(LocalSlurm, FakeWorkerSigtermFromSlurmCheckpointsAndResubmissionResumes) {
  if (auto why = slurm_unavailable(); !why.empty()) GTEST_SKIP() << why;
  const std::string dir = fresh_dir("local_slurm_sigterm");
  write_file(dir + "/c.toml", R"([campaign]
name = "slurm-sigterm"
[defaults]
mesh.level = 1
[[grid]]
aspect_ratio = [0.5, 2.0]
law = ["neo-hookean", "skalak"]
capillary_number = [0.02, 0.2]
)");
  const std::string db = dir + "/slurm.db", ref = dir + "/local.db";
  const std::string env = "env " + fake_worker_env() + " FAKE_STEPS=100 ";
  auto r = sh(env + "FAKE_STEP_S=0.1 " + exe() + " campaign submit " + dir + "/c.toml --db " + db +
              " --cases-per-task 4");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string job = job_of(r.out);
  ASSERT_FALSE(job.empty()) << r.out;
  ASSERT_TRUE(wait_job(job, 120, "RUNNING"));
  std::this_thread::sleep_for(std::chrono::seconds(2));
  auto st = sh(exe() + " campaign status --db " + db);
  EXPECT_NE(st.out.find("RUNNING"), std::string::npos) << st.out;
  // What Slurm does before the time limit with --signal=B:TERM@60: SIGTERM to the batch shell.
  r = sh("scancel --batch --signal=TERM " + job);
  EXPECT_EQ(r.code, 0) << r.err;
  ASSERT_TRUE(wait_job(job, 120));
  r = sh(exe() + " campaign collect --db " + db);
  ASSERT_EQ(r.code, 0) << r.err;
  std::printf("after SIGTERM: %s", r.out.c_str());
  EXPECT_NE(r.out.find("2 interrupted (resumable), 6 lost"), std::string::npos) << r.out;
  EXPECT_EQ(sql(db, "SELECT count(*) FROM cases WHERE status='queued' AND resumable=1"), "2\n");
  // Resubmit: the interrupted cases continue from their checkpoints.
  r = sh(env + "FAKE_STEP_S=0.005 " + exe() + " campaign submit " + dir + "/c.toml --db " + db + " --cases-per-task 4");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string job2 = job_of(r.out);
  ASSERT_TRUE(wait_job(job2, 300));
  r = sh(exe() + " campaign collect --db " + db);
  ASSERT_EQ(r.code, 0) << r.err;
  std::printf("after resubmission: %s", r.out.c_str());
  EXPECT_NE(r.out.find("ingested 8 result(s)"), std::string::npos) << r.out;
  EXPECT_EQ(sql(db, "SELECT count(*) FROM attempts WHERE resumed=1 AND outcome='done'"), "2\n");
  EXPECT_EQ(sql(db, "SELECT count(*) FROM slurm_tasks WHERE job_id='" + job2 + "' AND resumed=1"), "2\n");
  r = sh(env + "FAKE_STEP_S=0.001 " + exe() + " campaign run " + dir + "/c.toml --db " + ref + " --jobs 2");
  ASSERT_EQ(r.code, 0) << r.err;
  expect_same_table(sql(db, kCasesQuery), sql(ref, kCasesQuery));
  expect_same_table(sql(db, kTransitionsQuery), sql(ref, kTransitionsQuery));
}

}  // namespace
}  // namespace capsim::campaign::testing
