// End to end with the real solver (`capsim run` as the worker) on coarse settings: every case finishes,
// results and files are where the store says, a case folder reruns to the same parameters, queries work.
// Every check is unconditional: a run that finishes nothing fails here.
#include <algorithm>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "campaign/grid/case_params.h"
#include "campaign/store/store.h"
#include "test_util.h"

namespace capsim::campaign::testing {
namespace {

std::string csv_body(const std::string& db, const std::string& q) {
  auto r = sh(exe() + " query sql \"" + q + "\" --db " + db + " --format csv");
  EXPECT_EQ(r.code, 0) << q << ": " << r.err;
  auto nl = r.out.find('\n');
  return nl == std::string::npos ? "" : r.out.substr(nl + 1);
}

TEST(RealSolver, CoarseCampaignEndToEnd) {
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
  // No CAPSIM_WORKER: the manager runs this capsim binary itself. At these coarse settings every case
  // finishes (a blow-up would be a regression too): the campaign must succeed outright.
  auto r = sh("env -u CAPSIM_WORKER " + exe() + " campaign run " + dir + "/c.toml --db " + db + " --jobs 2");
  ASSERT_EQ(r.code, 0) << r.err;
  // Every case has a recorded outcome; none failed, none is left queued or running.
  ASSERT_EQ(csv_body(db, "SELECT count(*) FROM cases WHERE status='done'"), "8\n")
      << csv_body(db, "SELECT case_id, status, error FROM cases");
  // Every finished case has its result row with the worker's raw JSON and the metrics of its summary.
  EXPECT_EQ(csv_body(db, "SELECT count(*) FROM results r JOIN cases c USING(case_id) WHERE r.raw_json LIKE '{%' "
                         "AND r.steps > 0 AND r.t_final > 0.9 AND r.dt > 0"), "8\n");
  // The worker reported the code version the manager was built from.
  const auto ver = sh(exe() + " --version");
  const auto versions = csv_body(db, "SELECT DISTINCT code_version FROM results");
  ASSERT_EQ(std::count(versions.begin(), versions.end(), '\n'), 1) << versions;
  EXPECT_NE(ver.out.find(versions.substr(0, versions.find('\n'))), std::string::npos) << ver.out << " vs " << versions;
  // The files are where the store says.
  const auto h5 = csv_body(db, "SELECT h5_path FROM cases ORDER BY case_id");
  ASSERT_EQ(std::count(h5.begin(), h5.end(), '\n'), 8);
  std::istringstream paths(h5);
  for (std::string path; std::getline(paths, path);) EXPECT_TRUE(fs::exists(path)) << path;
  // The case folder is self-contained: its case.toml runs again and reports the parameters the store holds.
  auto id = csv_body(db, "SELECT case_id FROM cases ORDER BY case_id LIMIT 1");
  ASSERT_FALSE(id.empty());
  id.pop_back();
  const auto again = sh(exe() + " run " + db + ".runs/" + id + "/case.toml --out " + dir + "/again --json --quiet");
  ASSERT_EQ(again.code, 0) << again.err;
  const auto line = again.out.substr(again.out.rfind('\n', again.out.size() - 2) + 1);
  auto params = csv_body(db, "SELECT params_json FROM cases WHERE case_id='" + id + "'");
  ASSERT_FALSE(params.empty());
  params.pop_back();
  if (params.size() >= 2 && params.front() == '"') params = params.substr(1, params.size() - 2);  // CSV quoting
  std::string unquoted;
  for (std::size_t i = 0; i < params.size(); ++i) {
    unquoted += params[i];
    if (params[i] == '"' && i + 1 < params.size() && params[i + 1] == '"') ++i;
  }
  const auto j = parse_result_line(line);
  ASSERT_TRUE(j.has_value()) << line;
  EXPECT_EQ(result_mismatch(*j, CaseParams::from_json(unquoted)), "") << line;
  // Re-running skips everything; queries answer.
  r = sh("env -u CAPSIM_WORKER " + exe() + " campaign run " + dir + "/c.toml --db " + db + " --jobs 2");
  EXPECT_EQ(csv_body(db, "SELECT count(*) FROM attempts"), "8\n");
  auto t1 = sh(exe() + " query table1 --db " + db + " --format json");
  EXPECT_EQ(t1.code, 0) << t1.err;
  EXPECT_NE(t1.out.find("\"ca_star_low\""), std::string::npos);
  EXPECT_EQ(sh(exe() + " campaign status --db " + db).code, 0);
}

// The physical axes end to end with the real solver: a campaign over the viscosity ratio (and the bending
// modulus) runs, every case echoes the parameters its identity holds (the store checks each result against the
// case: a worker that reported λ = 1 for a λ = 5 case was refused as a mismatch before the check used the solver's
// own list, CaseParameters::of), and the queries tell the values apart.
TEST(RealSolver, PhysicalAxesEndToEnd) {
  const std::string dir = fresh_dir("real_solver_axes");
  const std::string db = dir + "/study.db";
  write_file(dir + "/c.toml", R"([campaign]
name = "real-axes"
[defaults]
mesh.level = 1
time.t_end = 0.5
[[grid]]
aspect_ratio = [2.0]
law = ["skalak"]
viscosity_ratio = [0.5, 5.0]
bending_modulus = [0.0, 0.01]
capillary_number = [0.3]
)");
  auto r = sh("env -u CAPSIM_WORKER " + exe() + " campaign run " + dir + "/c.toml --db " + db + " --jobs 2");
  ASSERT_EQ(r.code, 0) << r.err << csv_body(db, "SELECT case_id, status, error FROM cases");
  ASSERT_EQ(csv_body(db, "SELECT count(*) FROM cases WHERE status='done'"), "4\n");
  // Each λ's cases solved the second-kind equation (λ ≠ 1: GMRES iterations recorded), and report their λ.
  auto q = sh(exe() + " query cases --db " + db + " --viscosity-ratio 5 --format json");
  ASSERT_EQ(q.code, 0) << q.err;
  const auto five = nlohmann::json::parse(q.out);
  ASSERT_EQ(five.size(), 2u) << q.out;
  for (const auto& c : five) {
    EXPECT_EQ(c["summary"]["viscosity_ratio"].get<double>(), 5.0) << c.dump();
    EXPECT_GT(c["gmres_iterations_mean"].get<double>(), 0.0) << c.dump();
  }
  // Table 1 of one λ and one κ_b; without the choice it names the options.
  q = sh(exe() + " query table1 --db " + db);
  EXPECT_EQ(q.code, 2) << q.out;
  q = sh(exe() + " query table1 --db " + db + " --viscosity-ratio 0.5 --bending-modulus 0.01");
  EXPECT_EQ(q.code, 0) << q.err;
  EXPECT_NE(q.out.find("Viscosity ratio λ (inner/outer) = 0.5"), std::string::npos) << q.out;
  EXPECT_NE(q.out.find("Bending modulus κ_b = 0.01"), std::string::npos) << q.out;
}

}  // namespace
}  // namespace capsim::campaign::testing
