// Schema 2 -> 3 (transitions keyed by group; 4, 5 and 6 add columns): a committed version-2 database is read as it is, and a writer
// migrates it in one transaction without changing what `capsim query table1` gives.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "campaign/store/store.h"
#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

TEST(Migration, Version2DatabaseMigratesToGroupKeysAndKeepsTable1) {
  // The quick preset's campaign as it was first run (level 2, schema version 2), kept as the fixture.
  const fs::path committed =
      fs::path(CAPSIM_SOURCE_DIR) / "tests" / "campaign" / "store" / "fixtures" / "schema_v2_quick.sqlite";
  ASSERT_TRUE(fs::exists(committed)) << committed;
  const std::string dir = fresh_dir("migration_v2");
  const std::string db = dir + "/quick.sqlite";
  fs::copy_file(committed, db);
  ASSERT_EQ(sql(db, "PRAGMA user_version"), "2\n") << "the committed database is the version-2 fixture";
  const std::string rows_before = sql(db, "SELECT count(*) FROM transitions");
  const auto table1 = [&] {
    auto r = sh(exe() + " query table1 --db " + db + " --format json");
    EXPECT_EQ(r.code, 0) << r.err;
    auto rows = nlohmann::json::parse(r.out);
    for (auto& row : rows) row.erase("group_key");  // what the migration adds (checked below); the rest stays
    return rows;
  };
  const auto before = table1();
  // A writer (collect: no Slurm job, nothing to ingest) migrates.
  auto r = sh("env PATH=/usr/bin:/bin " + exe() + " campaign collect --db " + db);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sql(db, "PRAGMA user_version"), std::to_string(Store::expected_schema_version()) + "\n");
  EXPECT_EQ(sql(db, "SELECT value FROM meta WHERE key='migrated_from'"), "2\n");
  // Version 4 adds the role and error columns in place: migrated rows answer, without errors yet.
  EXPECT_EQ(sql(db, "SELECT count(*) FROM transitions WHERE role='answer' AND ca_h_err IS NULL"), rows_before);
  // Version 5 adds the level values (level_answers) in place: none until the campaign is analysed again.
  EXPECT_EQ(sql(db, "SELECT count(*) FROM transitions WHERE level_answers IS NULL"), rows_before);
  // Version 6 adds the missing parts of each error in place: none known until analysed again.
  EXPECT_EQ(sql(db, "SELECT count(*) FROM transitions WHERE ca_h_err_lacks IS NULL AND ca_star_low_err_lacks IS NULL "
                    "AND ca_star_high_err_lacks IS NULL"),
            rows_before);
  EXPECT_EQ(sql(db, "SELECT count(*) FROM transitions"), rows_before);
  // Every migrated row has a distinct group key naming its law, a/b and level.
  EXPECT_EQ(sql(db, "SELECT count(DISTINCT group_key) FROM transitions"), rows_before);
  {
    auto store = Store::open_readonly(db);
    const auto rows = store->transitions(*store->find_campaign(*store->latest_campaign()));
    ASSERT_EQ(std::to_string(rows.size()) + "\n", rows_before);
    for (const auto& t : rows) {
      const auto key = nlohmann::json::parse(t.group_key);
      EXPECT_EQ(key.at("capsule.law"), t.law);
      EXPECT_EQ(key.at("capsule.aspect_ratio").get<double>(), t.aspect_ratio);
      EXPECT_EQ(key.at("mesh.level").get<int>(), t.mesh_level);
    }
  }
  EXPECT_EQ(sql(db, "PRAGMA integrity_check"), "ok\n");
  EXPECT_EQ(table1(), before);
}

}  // namespace
}  // namespace capsim::campaign::testing
