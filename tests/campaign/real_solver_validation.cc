// Validation (slow, real solver): SIGTERM a running campaign, resume it, and check that the resumed cases
// end with the same outcome as an uninterrupted campaign of the same cases.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "test_util.h"

namespace capsim::campaign::testing {
namespace {

const std::string kCampaign = R"([campaign]
name = "real-interrupt"
[defaults]
mesh.level = 2
time.t_end = 20.0
output.checkpoint_interval = 0.5
[[grid]]
aspect_ratio = [0.5, 2.0]
law = ["skalak"]
capillary_number = [0.2, 0.6]
)";

nlohmann::json results(const std::string& db) {
  auto r = sh(exe() + " query sql \"SELECT c.case_id, c.status, r.min_D12, r.max_tau_min, r.steps, r.t_final "
                      "FROM cases c LEFT JOIN results r USING(case_id) ORDER BY c.case_id\" --db " + db +
              " --format json");
  EXPECT_EQ(r.code, 0) << r.err;
  return nlohmann::json::parse(r.out);
}

TEST(RealSolverValidation, InterruptedCampaignResumesToTheSameResults) {
  if (sh(exe() + " run --help").code != 0) GTEST_SKIP() << "capsim run not available";
  const std::string dir = fresh_dir("real_interrupt");
  write_file(dir + "/c.toml", kCampaign);
  const std::string ref_db = dir + "/reference.db", db = dir + "/interrupted.db";
  auto ref = sh("env -u CAPSIM_WORKER " + exe() + " campaign run " + dir + "/c.toml --db " + ref_db + " --jobs 2");
  ASSERT_TRUE(ref.code == 0 || ref.code == 1) << ref.err;

  pid_t mgr = spawn_sh("env -u CAPSIM_WORKER " + exe() + " campaign run " + dir + "/c.toml --db " + db + " --jobs 2");
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  kill(mgr, SIGTERM);
  const int code = wait_child(mgr, 300);
  if (code != 3) GTEST_SKIP() << "the campaign finished (exit " << code << ") before the signal: cases too short";
  auto r = sh("env -u CAPSIM_WORKER " + exe() + " campaign run " + dir + "/c.toml --db " + db + " --jobs 2");
  ASSERT_TRUE(r.code == 0 || r.code == 1) << r.err;
  auto a = results(ref_db), b = results(db);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i]["case_id"], b[i]["case_id"]);
    EXPECT_EQ(a[i]["status"], b[i]["status"]) << a[i]["case_id"];
    for (const char* k : {"min_D12", "max_tau_min", "t_final"})
      if (a[i][k].is_number() && b[i][k].is_number()) {
        EXPECT_NEAR(a[i][k].get<double>(), b[i][k].get<double>(), 1e-9 * (1 + std::fabs(a[i][k].get<double>())))
            << a[i]["case_id"] << " " << k;
      }
  }
}

}  // namespace
}  // namespace capsim::campaign::testing
