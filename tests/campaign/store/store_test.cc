// The database: schema version check, corrupt/foreign files, read-only queries.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include "campaign/store/store.h"

#include <nlohmann/json.hpp>

#include "campaign/grid/case_params.h"
#include "capsim/schema_sql.h"
#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

const std::string kTiny = R"([campaign]
name = "tiny"
[defaults]
mesh.level = 1
[[grid]]
aspect_ratio = [0.5, 2.0]
capillary_number = [0.02, 0.03]
)";

std::string make_db(const std::string& dir) {
  write_file(dir + "/tiny.toml", kTiny);
  auto r = sh(campaign_cmd("FAKE_STEPS=1", dir + "/tiny.toml", dir + "/study.db", "--jobs 2"));
  EXPECT_EQ(r.code, 0) << r.err;
  return dir + "/study.db";
}

TEST(Store, SchemaVersionComesFromTheEmbeddedDdl) {
  EXPECT_EQ(Store::expected_schema_version(), 7);  // schemas/007_regime_transition_v7.sql
  EXPECT_NE(std::string(kSchemaSql).find("CREATE TABLE IF NOT EXISTS transitions"), std::string::npos);
}

TEST(Store, CreatesSchemaOnceWithWal) {
  const std::string dir = fresh_dir("store_create");
  const std::string db = make_db(dir);
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open_v2(db.c_str(), &h, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  sqlite3_stmt* st = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(h, "PRAGMA journal_mode", -1, &st, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_step(st), SQLITE_ROW);
  EXPECT_STREQ(reinterpret_cast<const char*>(sqlite3_column_text(st, 0)), "wal");
  sqlite3_finalize(st);
  sqlite3_close(h);
  auto r = sh(exe() + " query sql \"PRAGMA user_version; PRAGMA integrity_check\" --db " + db + " --format csv");
  EXPECT_NE(r.out.find(std::to_string(Store::expected_schema_version()) + "\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("ok"), std::string::npos) << r.out;
}

TEST(Store, OtherSchemaVersionIsRefusedAndNothingIsOverwritten) {
  const std::string dir = fresh_dir("store_version");
  const std::string db = make_db(dir);
  exec_sql(db, "PRAGMA user_version = 99");
  const std::string before = read_file(db);
  auto r = sh(campaign_cmd("", dir + "/tiny.toml", db));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("schema version 99"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(db), std::string::npos) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  for (const char* q : {" query table1", " query cases", " campaign status"}) {
    auto s = sh(exe() + std::string(q) + " --db " + db);
    EXPECT_EQ(s.code, 2) << q;
    EXPECT_NE(s.err.find("schema version 99"), std::string::npos) << s.err;
  }
  EXPECT_EQ(read_file(db), before);
}

TEST(Store, CorruptOrForeignFilesAreRefusedAndNothingIsOverwritten) {
  const std::string dir = fresh_dir("store_corrupt");
  const std::string good = make_db(dir);
  write_file(dir + "/tiny.toml", kTiny);
  // 1. Not a database at all.
  std::string garbage;
  for (int i = 0; i < 500; ++i) garbage += "this is not a database ";
  write_file(dir + "/garbage.db", garbage);
  // 2. A real database with a damaged page.
  std::string damaged = read_file(good);
  ASSERT_GT(damaged.size(), 3 * 4096u);
  for (std::size_t i = 4096 + 8; i < 3 * 4096; ++i) damaged[i] = static_cast<char>(0xA5 ^ (i * 7));
  write_file(dir + "/damaged.db", damaged);
  // 3. A database of another application.
  exec_sql(dir + "/foreign.db", "CREATE TABLE t(x); INSERT INTO t VALUES (1);");
  // 4. A truncated database.
  write_file(dir + "/truncated.db", read_file(good).substr(0, 100));
  for (const std::string name : {"garbage.db", "damaged.db", "foreign.db", "truncated.db"}) {
    const std::string db = dir + "/" + name;
    const std::string before = read_file(db);
    auto r = sh(campaign_cmd("", dir + "/tiny.toml", db));
    EXPECT_EQ(r.code, 2) << name << ": " << r.err;
    EXPECT_NE(r.err.find(db), std::string::npos) << name << ": " << r.err;
    EXPECT_EQ(count_lines(r.err), 1) << name << ": " << r.err;
    auto q = sh(exe() + " query cases --db " + db);
    EXPECT_EQ(q.code, 2) << name << ": " << q.err;
    EXPECT_EQ(read_file(db), before) << name;
    EXPECT_FALSE(fs::exists(db + ".runs")) << name;
  }
}

// `query cases` carries each case's cost and keys, so that scripts (compare_campaigns) need no SQL of their own:
// core_s is the worker's wall × threads, params every key of the case, flow_evaluations the worker's count.
TEST(Store, QueryCasesGivesTheCostAndTheKeysOfEachCase) {
  const std::string dir = fresh_dir("store_query_cases");
  const std::string db = make_db(dir);
  auto r = sh(exe() + " query cases --db " + db + " --format json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto rows = nlohmann::json::parse(r.out);
  ASSERT_EQ(rows.size(), 4u) << r.out;
  for (const auto& c : rows) {
    ASSERT_EQ(c.at("status"), "done") << c.dump();
    EXPECT_GE(c.at("threads").get<int>(), 1) << c.dump();
    EXPECT_NEAR(c.at("core_s").get<double>(), c.at("wall_s").get<double>() * c.at("threads").get<int>(), 1e-9)
        << c.dump();
    EXPECT_TRUE(c.contains("flow_evaluations")) << c.dump();
    const auto p = nlohmann::json::parse(c.at("params").get<std::string>());
    EXPECT_EQ(p.at("flow.capillary_number").get<double>(), c.at("capillary_number").get<double>()) << c.dump();
    EXPECT_EQ(p.at("mesh.level").get<int>(), c.at("mesh_level").get<int>()) << c.dump();
  }
}

// A database written under an earlier cost estimator (an est_cost ∝ 1/Ca) is ordered by
// today's once a campaign run opens it: every case's est_cost becomes CaseParams::estimated_cost.
TEST(Store, ARunRefreshesTheCostEstimatesOfItsCases) {
  const std::string dir = fresh_dir("store_refresh_estimates");
  const std::string db = make_db(dir);
  exec_sql(db, "UPDATE cases SET est_cost = 1");
  ASSERT_EQ(sh(campaign_cmd("FAKE_STEPS=1", dir + "/tiny.toml", db, "--jobs 1")).code, 0);
  auto store = Store::open_readonly(db);
  Stmt s(store->db(), "SELECT params_json, est_cost FROM cases");
  int n = 0;
  while (s.step()) {
    EXPECT_EQ(*s.real(1), CaseParams::from_json(s.text(0)).estimated_cost()) << s.text(0);
    EXPECT_NE(*s.real(1), 1.0);
    ++n;
  }
  EXPECT_EQ(n, 4);
}

// The regime-based transition goes into the transitions table and comes back as it went in: the bracket, or
// none with the note that says why.
TEST(Store, TransitionsKeepTheRegimeTransition) {
  const std::string dir = fresh_dir("store_regime_transition");
  const std::string db = make_db(dir);
  auto store = Store::open_for_write(db);
  const std::int64_t id = *store->find_campaign("tiny");
  Transition bracket;
  bracket.group_key = "{\"a\":1}";
  bracket.law = "neo-hookean";
  bracket.aspect_ratio = 2.0;
  bracket.ca_ts_low = 0.213;
  bracket.ca_ts_high = 0.25;
  Transition none = bracket;
  none.group_key = "{\"a\":2}";
  none.aspect_ratio = 0.5;
  none.ca_ts_low = none.ca_ts_high = std::nullopt;
  none.ca_ts_note = "tumbles at every sampled Ca (0.02 to 5)";
  store->save_transitions(id, {bracket, none});
  const auto rows = store->transitions(id);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].aspect_ratio, 0.5);
  EXPECT_FALSE(rows[0].ca_ts_low);
  EXPECT_FALSE(rows[0].ca_ts_high);
  EXPECT_EQ(rows[0].ca_ts_note, none.ca_ts_note);
  EXPECT_EQ(rows[1].ca_ts_low, 0.213);
  EXPECT_EQ(rows[1].ca_ts_high, 0.25);
  EXPECT_EQ(rows[1].ca_ts_note, "");
  EXPECT_EQ(sql(db, "SELECT count(*) FROM transitions WHERE ca_ts_note IS NULL"), "1\n") << "no note: NULL";
}

TEST(Store, SqlQueriesAreReadOnly) {
  const std::string dir = fresh_dir("store_readonly");
  const std::string db = make_db(dir);
  const std::string before = read_file(db);
  for (const char* w : {"DELETE FROM cases", "UPDATE cases SET status='queued'", "DROP TABLE results",
                               "INSERT INTO meta VALUES('a','b')", "SELECT 1; DELETE FROM results",
                               "PRAGMA user_version = 5", "CREATE TABLE x(y)"}) {
    auto r = sh(exe() + " query sql \"" + std::string(w) + "\" --db " + db);
    EXPECT_EQ(r.code, 2) << w << ": " << r.err;
    EXPECT_NE(r.err.find("refused"), std::string::npos) << w << ": " << r.err;
  }
  EXPECT_EQ(read_file(db), before);
  auto r = sh(exe() + " query sql \"SELECT count(*) AS n FROM results\" --db " + db + " --format json");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"n\": 4"), std::string::npos) << r.out;
  EXPECT_EQ(sh(exe() + " query sql \"SELEC nonsense\" --db " + db).code, 2);
  EXPECT_EQ(sh(exe() + " query cases --db " + dir + "/missing.db").code, 2);
  EXPECT_FALSE(fs::exists(dir + "/missing.db"));
  EXPECT_EQ(sh(exe() + " query cases --format xml --db " + db).code, 2);
}

}  // namespace
}  // namespace capsim::campaign::testing
