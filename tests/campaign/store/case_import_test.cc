// `capsim campaign import`: finished cases of another database taken over by identity
// (campaign/store/case_import.h).
#include <gtest/gtest.h>
#include <sqlite3.h>

#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

// Four cases on mesh level 1; Ca 0.02 and 0.03 fail in the target (FAKE_FAIL_CA), so it holds them unfinished.
const std::string kGrid = R"([campaign]
name = "overlap"
[defaults]
mesh.level = 1
[[grid]]
aspect_ratio = [0.5]
capillary_number = [0.02, 0.03, 0.04, 0.05]
)";

// The files that differ between two snapshots (the contents are binary: only their names are worth printing).
std::string changed_files(const std::map<std::string, std::string>& a, const std::map<std::string, std::string>& b) {
  std::string out;
  for (const auto& [k, v] : a)
    if (!b.count(k) || b.at(k) != v) out += k + " ";
  for (const auto& [k, v] : b)
    if (!a.count(k)) out += k + " ";
  return out;
}

// What both databases store, and every other file of the test's folder: the database files themselves, and the
// SQLite and lock files beside them, change bytes when merely opened, so the databases count by their rows.
std::map<std::string, std::string> stored_state(const std::string& dir, const std::vector<std::string>& dbs) {
  std::map<std::string, std::string> out;
  for (const auto& [k, v] : folder_snapshot(dir)) {
    const bool sidecar = k.ends_with("-wal") || k.ends_with("-shm") || k.ends_with(".lock") || k.ends_with(".db");
    if (!sidecar) out[k] = v;
  }
  for (const auto& db : dbs)
    for (const char* table : {"cases", "results", "attempts", "campaign_cases", "transitions"})
      out[db + ":" + table] = sql(db, std::string("SELECT * FROM ") + table + " ORDER BY 1, 2");
  return out;
}

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

struct Pair {
  std::string dir, source, target;
};

// The source ran every case (with a level shift, so its results differ from what the target would compute);
// the target's run failed two of them.
Pair make_pair(const std::string& name) {
  Pair p{fresh_dir(name), "", ""};
  p.source = p.dir + "/source.db";
  p.target = p.dir + "/target.db";
  write_file(p.dir + "/c.toml", kGrid);
  EXPECT_EQ(sh(campaign_cmd("FAKE_STEPS=1 FAKE_LEVEL_SHIFT=0.1", p.dir + "/c.toml", p.source, "--jobs 2")).code, 0);
  const auto t = sh(campaign_cmd("FAKE_STEPS=1 FAKE_FAIL_CA=0.02,0.03", p.dir + "/c.toml", p.target, "--jobs 2"));
  EXPECT_NE(t.code, 2) << t.err;
  EXPECT_EQ(trimmed(sql(p.target, "SELECT count(*) FROM cases WHERE status='failed'")), "2");
  return p;
}

std::string import_cmd(const Pair& p, const std::string& extra = "") {
  return exe() + " campaign import --db " + p.target + " --from " + p.source + " " + extra;
}

TEST(CampaignImport, TakesOverTheFinishedCasesOfTheSameIdentityWithTheirResultAndFiles) {
  const Pair p = make_pair("import_takes_over");
  const auto before = stored_state(p.dir, {p.source, p.target});
  // A dry run lists them and changes nothing.
  const auto dry = sh(import_cmd(p, "--dry-run"));
  ASSERT_EQ(dry.code, 0) << dry.err;
  EXPECT_EQ(count_lines(dry.out), 3) << dry.out;  // two cases and the summary
  EXPECT_NE(dry.out.find("would take 2 of 2 unfinished case(s)"), std::string::npos) << dry.out;
  EXPECT_EQ(changed_files(stored_state(p.dir, {p.source, p.target}), before), "");

  const auto r = sh(import_cmd(p));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("took 2 of 2 unfinished case(s)"), std::string::npos) << r.out;
  EXPECT_EQ(trimmed(sql(p.target, "SELECT count(*) FROM cases WHERE status='done'")), "4");
  // The result is the source's line as it was, not one the target computed.
  const std::string q = "SELECT group_concat(raw_json, '|') FROM (SELECT r.raw_json FROM results r JOIN cases c "
                        "ON c.case_id=r.case_id WHERE c.capillary_number IN (0.02, 0.03) ORDER BY r.case_id)";
  EXPECT_EQ(sql(p.target, q), sql(p.source, q));
  EXPECT_EQ(trimmed(sql(p.target, "SELECT count(*) FROM attempts WHERE outcome='imported' AND error LIKE "
                                  "'imported from %source.db'")),
            "2");
  // The case folder's files came along (not a checkpoint), into the target's own runs folder.
  const std::string id = trimmed(sql(p.target, "SELECT case_id FROM cases WHERE capillary_number=0.02"));
  const std::string folder = trimmed(sql(p.target, "SELECT out_dir FROM cases WHERE case_id='" + id + "'"));
  EXPECT_EQ(folder.rfind(p.target + ".runs/", 0), 0u) << folder;
  EXPECT_TRUE(fs::exists(folder + "/stdout.log")) << folder;
  EXPECT_EQ(read_file(folder + "/stdout.log"), read_file(p.source + ".runs/" + id + "/stdout.log"));
  EXPECT_FALSE(fs::exists(folder + "/checkpoint.txt"));
  // The transitions were recomputed with the four samples.
  EXPECT_EQ(trimmed(sql(p.target, "SELECT max(n_samples) FROM transitions")), "4");
  // Idempotent: nothing is left to take.
  const auto again = sh(import_cmd(p));
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_NE(again.out.find("took 0 of 0 unfinished case(s)"), std::string::npos) << again.out;
}

// A database committed without its case folders (or copied from another machine): the result comes without its
// time series, the command says so, and the target keeps the folder it had for the case.
TEST(CampaignImport, WithoutTheSourceFoldersTheResultComesAloneAndTheTargetKeepsItsFolder) {
  const Pair p = make_pair("import_no_folders");
  const std::string q = "SELECT out_dir FROM cases WHERE capillary_number=0.02";
  const std::string folder = trimmed(sql(p.target, q));
  ASSERT_FALSE(folder.empty());
  fs::rename(p.source + ".runs", p.dir + "/elsewhere");
  const auto r = sh(import_cmd(p));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(count_lines(r.out), 4) << r.out;  // two cases, the summary, the transitions line
  EXPECT_NE(r.out.find("its case folder was not found, so no time series file"), std::string::npos) << r.out;
  EXPECT_EQ(trimmed(sql(p.target, q)), folder);
  EXPECT_EQ(trimmed(sql(p.target, "SELECT count(*) FROM cases WHERE status='done' AND h5_path IS NULL AND "
                                  "capillary_number IN (0.02, 0.03)")),
            "2");
}

// A runs folder that cannot be created (its parent is a file): exit 4 with one message, and since a case's files
// are copied before its row changes, nothing was imported.
TEST(CampaignImport, AnUnwritableRunsFolderIsAWriteFailureThatChangesNothing) {
  const Pair p = make_pair("import_unwritable");
  write_file(p.dir + "/a_file", "x");
  const auto before = stored_state(p.dir, {p.source, p.target});
  const auto r = sh(import_cmd(p, "--runs-dir " + p.dir + "/a_file/runs"));
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.err.find("cannot copy a case folder"), std::string::npos) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_EQ(changed_files(stored_state(p.dir, {p.source, p.target}), before), "");
}

TEST(CampaignImport, AnAlteredSourceCaseRefusesTheWholeImport) {
  const Pair p = make_pair("import_altered");
  // A source row whose parameters no longer hash to its identity (Ca edited by hand).
  exec_sql(p.source, "UPDATE cases SET params_json=replace(params_json, '0.03', '0.035') WHERE capillary_number=0.03");
  const auto before = stored_state(p.dir, {p.source, p.target});
  const auto r = sh(import_cmd(p));
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.err.find("do not hash to its identity"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nothing was imported"), std::string::npos) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_EQ(changed_files(stored_state(p.dir, {p.source, p.target}), before), "");
}

TEST(CampaignImport, BadArgumentsAndARunningManagerAreRefusedWithExit2) {
  const Pair p = make_pair("import_bad");
  const auto before = stored_state(p.dir, {p.source, p.target});
  const auto missing = sh(exe() + " campaign import --db " + p.target + " --from " + p.dir + "/nothing.db");
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("nothing.db: no such database"), std::string::npos) << missing.err;
  const auto itself = sh(exe() + " campaign import --db " + p.target + " --from " + p.target);
  EXPECT_EQ(itself.code, 2);
  EXPECT_NE(itself.err.find("is the database itself"), std::string::npos) << itself.err;
  const auto no_campaign = sh(import_cmd(p, "--campaign nope"));
  EXPECT_EQ(no_campaign.code, 2);
  EXPECT_NE(no_campaign.err.find("no campaign named 'nope'"), std::string::npos) << no_campaign.err;
  // A manager holds the lock (flock(1) takes the same lock as `campaign run`).
  const auto locked = sh("flock " + p.target + ".lock " + import_cmd(p));
  EXPECT_EQ(locked.code, 2);
  EXPECT_NE(locked.err.find("another campaign manager is running"), std::string::npos) << locked.err;
  EXPECT_EQ(changed_files(stored_state(p.dir, {p.source, p.target}), before), "");
}

}  // namespace
}  // namespace capsim::campaign::testing
