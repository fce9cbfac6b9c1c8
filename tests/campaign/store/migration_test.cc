// Schema 2 -> 3 (transitions keyed by group; 4, 5, 6 and 7 add columns): a committed version-2 database is read as it
// is, and a writer migrates it in one transaction without changing what `capsim query table1` gives. Schema 6 -> 7
// (the regime-based transition Ca_TS): a committed version-6 database migrates in place, its rows without Ca_TS until
// `capsim campaign analyse` recomputes them.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "campaign/store/store.h"
#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

// A copy of the committed fixture database `name` in a fresh scratch folder (the test must never write the fixture).
std::string copy_of_fixture(const std::string& name, const std::string& scratch) {
  const fs::path committed = fs::path(CAPSIM_SOURCE_DIR) / "tests" / "campaign" / "store" / "fixtures" / name;
  EXPECT_TRUE(fs::exists(committed)) << committed;
  const std::string db = fresh_dir(scratch) + "/" + name;
  fs::copy_file(committed, db);
  return db;
}

TEST(Migration, Version2DatabaseMigratesToGroupKeysAndKeepsTable1) {
  // The quick preset's campaign as it was first run (level 2, schema version 2), kept as the fixture.
  const std::string db = copy_of_fixture("schema_v2_quick.sqlite", "migration_v2");
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
  // Version 7 adds the regime-based transition in place: none until analysed again.
  EXPECT_EQ(sql(db, "SELECT count(*) FROM transitions WHERE ca_ts_low IS NULL AND ca_ts_high IS NULL "
                    "AND ca_ts_note IS NULL"),
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

// The quick preset's cases (level 2) report their regimes: migrated and analysed by this build, each spheroid's
// transitions row holds the bracket between its largest tumbling and smallest swinging Ca, read back by the store
// and printed by `query table1` (a third line per law in markdown, three fields in JSON) and `query transitions`.
TEST(Migration, AnalysedVersion2DatabaseGainsTheRegimeTransition) {
  const std::string db = copy_of_fixture("schema_v2_quick.sqlite", "migration_v2_regime");
  auto r = sh(exe() + " campaign analyse --db " + db);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sql(db, "PRAGMA user_version"), std::to_string(Store::expected_schema_version()) + "\n");
  // The fixture's level-2 regimes (0.01-0.04 tumbling, 0.05 on swinging for both oblate laws; NH prolate
  // tumbling to 0.2, Skalak to 0.3), with the unknown ones at large Ca skipped.
  EXPECT_EQ(sql(db, "SELECT law, aspect_ratio, ca_ts_low, ca_ts_high, coalesce(ca_ts_note,'-') FROM transitions "
                    "ORDER BY law, aspect_ratio"),
            "neo-hookean,0.5,0.04,0.05,\"skipped unknown at Ca=2, 3\"\n"
            "neo-hookean,1,,,-\n"
            "neo-hookean,2,0.2,0.25,\"skipped unknown at Ca=1, 1.5, 2\"\n"
            "skalak,0.5,0.04,0.05,-\n"
            "skalak,1,,,-\n"
            "skalak,2,0.3,0.35,skipped unknown at Ca=2\n");
  {
    auto store = Store::open_readonly(db);
    for (const auto& t : store->transitions(*store->find_campaign(*store->latest_campaign()))) {
      EXPECT_EQ(t.ca_ts_low.has_value(), t.aspect_ratio != 1.0) << t.law << " " << t.aspect_ratio;
      EXPECT_EQ(t.ca_ts_high.has_value(), t.aspect_ratio != 1.0) << t.law << " " << t.aspect_ratio;
    }
  }
  r = sh(exe() + " query table1 --db " + db);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("| | Ca_TS ∈ (0.04, 0.05) (regime) |  | Ca_TS ∈ (0.2, 0.25) (regime) |\n"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("| | Ca_TS ∈ (0.04, 0.05) (regime) |  | Ca_TS ∈ (0.3, 0.35) (regime) |\n"), std::string::npos)
      << r.out;
  r = sh(exe() + " query table1 --db " + db + " --format json");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const auto& row : nlohmann::json::parse(r.out)) {
    ASSERT_TRUE(row.contains("ca_ts_low") && row.contains("ca_ts_high") && row.contains("ca_ts_note")) << row;
    if (row.at("aspect_ratio") == 2.0 && row.at("law") == "skalak") {
      EXPECT_EQ(row.at("ca_ts_low"), 0.3);
      EXPECT_EQ(row.at("ca_ts_high"), 0.35);
      EXPECT_EQ(row.at("ca_ts_note"), "skipped unknown at Ca=2");
    }
    if (row.at("aspect_ratio") == 1.0) {
      EXPECT_TRUE(row.at("ca_ts_low").is_null() && row.at("ca_ts_note").is_null()) << row;
    }
  }
  r = sh(exe() + " query transitions --db " + db + " --format csv");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.substr(0, r.out.find('\n')).find(",ca_ts_low,ca_ts_high,ca_ts_note"), std::string::npos) << r.out;
}

TEST(Migration, Version6DatabaseMigratesToTheRegimeTransition) {
  // The main command's version-2 database (schema 6; the fixture kept when results/table1/ was re-run), on a copy.
  const std::string db = copy_of_fixture("table1_mf_mixed_v2.sqlite", "migration_v6");
  ASSERT_EQ(sql(db, "PRAGMA user_version"), "6\n") << "the committed database is of schema 6";
  const std::string rows_before = sql(db, "SELECT count(*) FROM transitions");
  const auto table1 = [&](const std::string& format) {
    auto r = sh(exe() + " query table1 --db " + db + " --format " + format);
    EXPECT_EQ(r.code, 0) << r.err;
    return r.out;
  };
  const std::string json_before = table1("json"), md_before = table1("md");
  // Read as it is: no regime transition yet, and markdown says how to get one.
  for (const auto& row : nlohmann::json::parse(json_before))
    EXPECT_TRUE(row.at("ca_ts_low").is_null() && row.at("ca_ts_high").is_null() && row.at("ca_ts_note").is_null());
  EXPECT_NE(md_before.find("| | Ca_TS not analysed (capsim campaign analyse) |  | Ca_TS not analysed"),
            std::string::npos)
      << md_before;
  auto r = sh("env PATH=/usr/bin:/bin " + exe() + " campaign collect --db " + db);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sql(db, "PRAGMA user_version"), "7\n");
  EXPECT_EQ(sql(db, "SELECT value FROM meta WHERE key='migrated_from'"), "6\n");
  EXPECT_EQ(sql(db, "SELECT count(*) FROM transitions WHERE ca_ts_low IS NULL AND ca_ts_high IS NULL "
                    "AND ca_ts_note IS NULL"),
            rows_before);
  EXPECT_EQ(sql(db, "PRAGMA integrity_check"), "ok\n");
  EXPECT_EQ(table1("json"), json_before);
  EXPECT_EQ(table1("md"), md_before);
  // Analysed again, every spheroid's answer has a bracket or a note, the Ca* and CaH answers untouched.
  r = sh(exe() + " campaign analyse --db " + db);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sql(db, "SELECT count(*) FROM transitions WHERE aspect_ratio <> 1 AND role = 'answer' AND "
                    "ca_ts_low IS NULL AND ca_ts_note IS NULL"),
            "0\n");
  auto after = nlohmann::json::parse(table1("json"));
  auto before = nlohmann::json::parse(json_before);
  for (auto* rows : {&after, &before})
    for (auto& row : *rows)
      for (const char* k : {"ca_ts_low", "ca_ts_high", "ca_ts_note"}) row.erase(k);
  EXPECT_EQ(after, before);
}

}  // namespace
}  // namespace capsim::campaign::testing
