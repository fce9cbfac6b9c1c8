// A campaign over the initial orientation (grid axes tilt and azimuth): each case's result echoes its tilt and
// azimuth (driver::CaseParameters), the store checks them against the case like every parameter, and query cases
// shows the orientation with what the axis ended doing (final_tilt, regime, tilt_growth_rate) and the membrane's
// spin rate about it (final_spin_rate).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

// The rows of a read-only query as CSV, without the header.
std::string csv_body(const std::string& db, const std::string& q) {
  auto r = sh(exe() + " query sql \"" + q + "\" --db " + db + " --format csv");
  EXPECT_EQ(r.code, 0) << q << ": " << r.err;
  auto nl = r.out.find('\n');
  return nl == std::string::npos ? "" : r.out.substr(nl + 1);
}

TEST(OrientationAxes, TiltedCasesAreStoredWithoutAMismatch) {
  const std::string dir = fresh_dir("orientation_axes");
  const std::string db = dir + "/study.db";
  write_file(dir + "/g.toml", prolate_campaign("tilt-axis", "tilt = [0.0, 5.0]\nazimuth = [0.0, 30.0]\n"));
  auto r = sh(campaign_cmd("FAKE_STEPS=1 FAKE_STEP_S=0.001", dir + "/g.toml", db, "--jobs 2"));
  ASSERT_EQ(r.code, 0) << r.err << csv_body(db, "SELECT case_id, status, error FROM cases");
  EXPECT_EQ(csv_body(db, "SELECT count(*) FROM cases WHERE status='done'"), "16\n")
      << csv_body(db, "SELECT status, error FROM cases");
  auto q = sh(exe() + " query cases --db " + db + " --format json");
  ASSERT_EQ(q.code, 0) << q.err;
  const auto all = nlohmann::json::parse(q.out);
  ASSERT_EQ(all.size(), 16u);
  int tilted = 0, turned = 0;
  for (const auto& c : all) {
    // The orientation columns: from the case's parameters (0 where the key is at its default), echoed by the result.
    EXPECT_EQ(c["tilt"].get<double>(), c["summary"]["tilt"].get<double>()) << c.dump();
    EXPECT_EQ(c["azimuth"].get<double>(), c["summary"]["azimuth"].get<double>()) << c.dump();
    tilted += c["tilt"].get<double>() == 5.0;
    turned += c["azimuth"].get<double>() == 30.0;
    for (const char* column : {"regime", "final_tilt", "tilt_growth_rate", "tilt_growth_rate_error", "final_spin_rate"})
      EXPECT_TRUE(c.contains(column)) << column;
  }
  EXPECT_EQ(tilted, 8);
  EXPECT_EQ(turned, 8);
  // The tables for reading show the columns too.
  q = sh(exe() + " query cases --db " + db);
  ASSERT_EQ(q.code, 0) << q.err;
  for (const char* column : {"| tilt", "| azimuth", "| final_tilt", "| regime", "| tilt_growth_rate", "| final_spin_rate"})
    EXPECT_NE(q.out.find(column), std::string::npos) << column << "\n" << q.out;
}

// A worker that reports the default orientation for a tilted case is refused, naming the tilt; the in-plane cases of
// the same campaign (which it reports correctly) are stored.
TEST(OrientationAxes, AResultWithAnotherTiltIsRefused) {
  const std::string dir = fresh_dir("orientation_axes_mismatch");
  const std::string db = dir + "/study.db";
  write_file(dir + "/g.toml", prolate_campaign("tilt-mismatch", "tilt = [0.0, 5.0]\n"));
  sh(campaign_cmd("FAKE_STEPS=1 FAKE_STEP_S=0.001 FAKE_DROP_ORIENTATION=1", dir + "/g.toml", db, "--jobs 2"));
  // (The axis stores its value in every case's parameters, 0 included: '"capsule.tilt":0.0'.)
  EXPECT_EQ(csv_body(db, "SELECT count(*) FROM cases WHERE status='done' AND params_json LIKE '%tilt__0.0%'"), "4\n");
  EXPECT_EQ(csv_body(db, "SELECT count(*) FROM cases WHERE status='failed' AND params_json LIKE '%tilt__5.0%' "
                         "AND error LIKE '%differ from the case: tilt 0%'"),
            "4\n")
      << csv_body(db, "SELECT status, error FROM cases");
}

}  // namespace
}  // namespace capsim::campaign::testing
