// Case identities of the committed databases: every case stored under results/ (and in the store tests' fixture
// databases) must get back its own
// case_id when its identity is recomputed from the stored params_json with the solver version recorded in
// its row. A change to the key registry, the canonical form or the default values that altered an identity
// would orphan every finished result (the campaign would re-run them as new cases); this test catches it.
#include <sqlite3.h>

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "campaign/grid/case_params.h"

namespace capsim::campaign {
namespace {

namespace fs = std::filesystem;

struct StoredCase {
  std::string case_id, params_json, solver_version;
};

std::vector<StoredCase> stored_cases(const fs::path& db) {
  sqlite3* h = nullptr;
  std::vector<StoredCase> out;
  // Read-only and immutable: the test must never touch (or create a WAL beside) a committed file.
  const std::string uri = "file:" + db.string() + "?immutable=1";
  if (sqlite3_open_v2(uri.c_str(), &h, SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, nullptr) != SQLITE_OK) {
    ADD_FAILURE() << db << ": " << sqlite3_errmsg(h);
    sqlite3_close(h);
    return out;
  }
  sqlite3_stmt* st = nullptr;
  if (sqlite3_prepare_v2(h, "SELECT case_id, params_json, solver_version FROM cases", -1, &st, nullptr) != SQLITE_OK) {
    ADD_FAILURE() << db << ": " << sqlite3_errmsg(h);
  } else {
    auto text = [&](int col) { return std::string(reinterpret_cast<const char*>(sqlite3_column_text(st, col))); };
    while (sqlite3_step(st) == SQLITE_ROW) out.push_back({text(0), text(1), text(2)});
  }
  sqlite3_finalize(st);
  sqlite3_close(h);
  return out;
}

std::vector<fs::path> committed_databases() {
  std::vector<fs::path> dbs;
  const fs::path src(CAPSIM_SOURCE_DIR);
  for (const fs::path& dir : {src / "results", src / "tests" / "campaign" / "store" / "fixtures"})
    for (const auto& e : fs::recursive_directory_iterator(dir))
      if (e.is_regular_file() && e.path().extension() == ".sqlite") dbs.push_back(e.path());
  return dbs;
}

TEST(CommittedIdentity, EveryStoredCaseKeepsItsIdentity) {
  const auto dbs = committed_databases();
  // The Table 1 databases are committed deliverables: their absence is a failure, not a skip.
  for (const char* required : {"table1_mf_mixed.sqlite", "table1_certified.sqlite", "table1_paper.sqlite"}) {
    bool found = false;
    for (const auto& p : dbs) found = found || p.filename() == required;
    EXPECT_TRUE(found) << "results/" << required << " is missing";
  }
  std::size_t checked = 0;
  for (const auto& db : dbs) {
    const auto cases = stored_cases(db);
    EXPECT_FALSE(cases.empty()) << db;
    for (const auto& c : cases) {
      std::string id;
      try {
        id = CaseParams::from_json(c.params_json).identity(c.solver_version);
      } catch (const std::exception& e) {
        ADD_FAILURE() << db.filename() << " case " << c.case_id << " " << c.params_json << ": " << e.what();
        continue;
      }
      EXPECT_EQ(id, c.case_id) << db.filename() << ": " << c.params_json << " (solver " << c.solver_version << ")";
      ++checked;
    }
  }
  EXPECT_GT(checked, 100u) << "the committed databases hold more than 100 cases";
}

}  // namespace
}  // namespace capsim::campaign
