// End to end with the real solver (`capsim run` as the worker) on coarse settings: every case reaches a
// recorded outcome, results and files are where the store says, queries work.
#include <gtest/gtest.h>

#include "test_util.h"

namespace capsim::campaign::testing {
namespace {

bool solver_available() {
  auto r = sh(exe() + " run --help");
  return r.code == 0 && r.err.find("not available") == std::string::npos;
}

std::string csv_body(const std::string& db, const std::string& q) {
  auto r = sh(exe() + " query sql \"" + q + "\" --db " + db + " --format csv");
  EXPECT_EQ(r.code, 0) << q << ": " << r.err;
  auto nl = r.out.find('\n');
  return nl == std::string::npos ? "" : r.out.substr(nl + 1);
}

TEST(RealSolver, CoarseCampaignEndToEnd) {
  if (!solver_available()) GTEST_SKIP() << "capsim run is not available in this build yet";
  const std::string dir = fresh_dir("real_solver");
  const std::string db = dir + "/study.db";
  write_file(dir + "/c.toml", R"([campaign]
name = "real-coarse"
[defaults]
mesh.level = 1
time.t_end = 1.0
[[grid]]
aspect_ratio = [0.5, 2.0]
law = ["neo-hookean", "skalak"]
capillary_number = [0.1, 0.4]
)");
  // No CAPSIM_WORKER: the manager runs this capsim binary itself.
  auto r = sh("env -u CAPSIM_WORKER " + exe() + " campaign run " + dir + "/c.toml --db " + db + " --jobs 2");
  ASSERT_TRUE(r.code == 0 || r.code == 1) << r.err;
  // Every case has a recorded outcome; none is left queued or running.
  EXPECT_EQ(csv_body(db, "SELECT count(*) FROM cases WHERE status IN ('done','unstable','failed')"), "8\n");
  // Failures (if any) carry the worker's reason; done/unstable ones have a result row with the raw JSON.
  EXPECT_EQ(csv_body(db, "SELECT count(*) FROM cases WHERE status='failed' AND (error IS NULL OR error='')"), "0\n");
  EXPECT_EQ(csv_body(db, "SELECT count(*) FROM cases c WHERE status IN ('done','unstable') AND NOT EXISTS "
                         "(SELECT 1 FROM results r WHERE r.case_id=c.case_id AND r.raw_json LIKE '{%')"), "0\n");
  // The worker reported the parameters of its case and the code version the manager was built from.
  auto ver = sh(exe() + " --version");
  auto versions = csv_body(db, "SELECT DISTINCT code_version FROM results");
  if (!versions.empty()) EXPECT_NE(ver.out.find(versions.substr(0, versions.find('\n'))), std::string::npos);
  auto h5 = csv_body(db, "SELECT h5_path FROM cases WHERE status IN ('done','unstable') LIMIT 1");
  if (!h5.empty()) {
    h5.pop_back();
    EXPECT_TRUE(fs::exists(h5)) << h5;
  }
  // The case folder is self-contained: its case.toml runs again and gives the same parameters.
  auto id = csv_body(db, "SELECT case_id FROM cases ORDER BY case_id LIMIT 1");
  id.pop_back();
  auto again = sh(exe() + " run " + db + ".runs/" + id + "/case.toml --out " + dir + "/again --json");
  EXPECT_TRUE(again.code == 0 || again.code == 1) << again.err;
  // Re-running skips everything; queries answer.
  r = sh("env -u CAPSIM_WORKER " + exe() + " campaign run " + dir + "/c.toml --db " + db + " --jobs 2");
  EXPECT_EQ(csv_body(db, "SELECT count(*) FROM attempts"), "8\n");
  auto t1 = sh(exe() + " query table1 --db " + db + " --format json");
  EXPECT_EQ(t1.code, 0) << t1.err;
  EXPECT_NE(t1.out.find("\"ca_star_low\""), std::string::npos);
  EXPECT_EQ(sh(exe() + " campaign status --db " + db).code, 0);
}

}  // namespace
}  // namespace capsim::campaign::testing
