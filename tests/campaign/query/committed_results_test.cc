// The committed Table 1 files are what `capsim query table1 --format json` gives on the committed campaign
// databases (issue 5: "capsim query table1 --db results/table1.sqlite --format json reproduces the committed
// table"). The database is copied first so that the query cannot touch the repository's file.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

void expect_query_reproduces(const std::string& db_name, const std::string& json_name) {
  const fs::path results = fs::path(CAPSIM_SOURCE_DIR) / "results";
  // Both files are committed deliverables: a missing one is a failure, not a reason to skip.
  ASSERT_TRUE(fs::exists(results / db_name)) << "results/" << db_name << " is missing";
  ASSERT_TRUE(fs::exists(results / json_name)) << "results/" << json_name << " is missing";
  const std::string dir = fresh_dir("committed_" + db_name);
  const std::string copy = dir + "/" + db_name;
  fs::copy_file(results / db_name, copy);
  const CmdResult r = sh(exe() + " query table1 --db " + copy + " --format json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto ours = nlohmann::json::parse(r.out);
  const auto committed = nlohmann::json::parse(read_file((results / json_name).string()));
  ASSERT_TRUE(ours.is_array());
  EXPECT_EQ(ours.size(), 6u) << "two laws x three aspect ratios";
  EXPECT_EQ(ours, committed) << "results/" << json_name << " is stale: regenerate it with capsim query table1";
}

TEST(CommittedResults, PaperTableIsWhatTheDatabaseGives) { expect_query_reproduces("table1.sqlite", "table1.json"); }

TEST(CommittedResults, QuickTableIsWhatTheDatabaseGives) {
  expect_query_reproduces("table1_quick.sqlite", "table1_quick.json");
}

TEST(CommittedResults, MultiFidelityTableIsWhatTheDatabaseGives) {
  expect_query_reproduces("table1_mf.sqlite", "table1_mf.json");
}

// The certified campaign shares its database with the multi-fidelity one it continues; the query's default
// campaign is the most recently run, the certified one.
TEST(CommittedResults, CertifiedTableIsWhatTheDatabaseGives) {
  expect_query_reproduces("table1_certified.sqlite", "table1_certified.json");
}

}  // namespace
}  // namespace capsim::campaign::testing
