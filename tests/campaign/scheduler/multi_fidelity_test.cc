// A multi-fidelity campaign end to end (fake worker whose CaH converges at first order in h with a known
// limit): scan on level 1, answer on level 2, check on level 3, dt/2 check; the answer's error bar is the
// distance to the limit, and it is what `capsim query table1` reports.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <sstream>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>

#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

// The oblate NH grid of these tests, adaptive, to which each test adds its [analysis] levels (and dt_check).
const std::string kOblateGrid = R"([[grid]]
aspect_ratio = [0.5]
law = ["neo-hookean"]
capillary_number = [0.01, 0.02, 0.03, 0.04, 0.05, 0.1, 0.4, 0.8, 1.2]
[analysis]
adaptive = true
ca_tolerance = 0.005
max_rounds = 20
)";

// The two-cell campaign of the cell-scheduling tests: a prolate NH cell sampled at `prolate_ca` and the oblate grid,
// scan level 1, answer level 2, with the dt check; and the fake worker's fast settings for it.
std::string two_cell_spec(const std::string& prolate_ca) {
  return "[campaign]\nname = \"mf\"\n[[grid]]\naspect_ratio = [2.0]\nlaw = [\"neo-hookean\"]\ncapillary_number = [" +
         prolate_ca + "]\n" + kOblateGrid + "levels = [1, 2]\ndt_check = true\n";
}
const std::string kTwoCellEnv = "FAKE_STEPS=1 FAKE_STEP_S=0.001 FAKE_LEVEL_SHIFT=0.08";

TEST(MultiFidelity, ScanAnswerCheckAndTheErrorBarOfCaH) {
  const std::string dir = fresh_dir("multi_fidelity");
  const std::string db = dir + "/study.db";
  write_file(dir + "/mf.toml", "[campaign]\nname = \"mf\"\n" + kOblateGrid + "levels = [1, 2, 3]\ndt_check = true\n");
  // CaH of level L = 0.70 − 0.8 · 2^-L − 10 dt²: 0.30 / 0.50 / 0.60 on levels 1 / 2 / 3 (dt 0.01), limit 0.699.
  const std::string env = "FAKE_STEPS=1 FAKE_STEP_S=0.001 FAKE_LEVEL_SHIFT=0.8 FAKE_DT_COEF=10";
  auto r = sh(campaign_cmd(env, dir + "/mf.toml", db, "--jobs 2"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("multi-fidelity: level 2"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("mesh check on level 3"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("dt/2 check on level 2"), std::string::npos) << r.err;
  // The cheap dt check before the check level's long cases (an interruption among them keeps the dt part).
  EXPECT_LT(r.err.find("dt/2 check on level 2"), r.err.find("mesh check on level 3")) << r.err;
  EXPECT_NE(r.err.find("cases per mesh level"), std::string::npos) << r.err;
  // CaH's level-2 answer is bracketed to ≈ its error 0.2, not to ca_tolerance: bisections were saved.
  const auto saved_at = r.err.find("numerical error saved ");
  ASSERT_NE(saved_at, std::string::npos) << r.err;
  EXPECT_GT(std::stoi(r.err.substr(saved_at + std::string("numerical error saved ").size())), 0) << r.err;

  auto rows = nlohmann::json::parse(
      sh(exe() + " query sql \"SELECT mesh_level, role, method, ca_h, ca_h_low, ca_h_high, ca_h_err, ca_h_err_source, "
                 "error_levels, error_note FROM transitions ORDER BY mesh_level, role\" --db " + db + " --format json")
          .out);
  ASSERT_EQ(rows.size(), 4u) << rows.dump(1);
  EXPECT_EQ(rows[0]["role"], "scan");
  EXPECT_EQ(rows[1]["role"], "answer");
  EXPECT_EQ(rows[2]["role"], "dt_check");
  EXPECT_EQ(rows[3]["role"], "mesh_check");
  const auto& answer = rows[1];
  EXPECT_EQ(answer["method"], "multi-fidelity");
  EXPECT_EQ(answer["mesh_level"], 2);
  // The answer level re-bracketed (the scan's bracket (0.1, 0.4) holds 0.30, not 0.50) and refined only to
  // the error: the bracket is narrower than the first one but not below what the mesh resolves.
  const double lo = answer["ca_h_low"], hi = answer["ca_h_high"], cah = answer["ca_h"], err = answer["ca_h_err"];
  EXPECT_NEAR(cah, 0.70 - 0.2 - 0.001, 1e-9);
  EXPECT_LE(lo, cah);
  EXPECT_GE(hi, cah);
  EXPECT_GT(hi - lo, 0.005) << "refined below the numerical error";
  // Richardson over levels 1–3 gives exactly the distance to the limit (first order, ratio 1/2).
  EXPECT_NEAR(err, 0.2, 1e-9) << answer["error_note"];
  EXPECT_EQ(answer["ca_h_err_source"], "mesh");
  EXPECT_EQ(answer["error_levels"], "1,2,3");
  EXPECT_LE(std::fabs(0.699 - cah), err + 1e-9);
  EXPECT_NE(answer["error_note"].get<std::string>().find("dt 0.001"), std::string::npos) << answer["error_note"];

  // The query reports the answer level with its errors (the other roles serve the error only).
  auto q = sh(exe() + " query table1 --db " + db + " --format json");
  ASSERT_EQ(q.code, 0) << q.err;
  auto t = nlohmann::json::parse(q.out);
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t[0]["mesh_level"], 2);
  EXPECT_NEAR(t[0]["ca_h_err"].get<double>(), 0.2, 1e-9);
  EXPECT_EQ(t[0]["error_levels"], "1,2,3");
  EXPECT_TRUE(t[0]["ca_star_low_err"].is_number()) << t[0].dump();
  // The fake worker records no period spreads: the error has its mesh and dt parts, not the periods one, so it
  // is a lower bound and says so (schemas/006).
  EXPECT_EQ(t[0]["ca_h_err_lacks"], "periods") << t[0].dump();
  auto md = sh(exe() + " query table1 --db " + db + " --format md");
  EXPECT_NE(md.out.find("CaH = 0.5 ± 0.2† |"), std::string::npos) << md.out;
  EXPECT_NE(md.out.find("† a lower bound: this error lacks a part that had no data (periods: period spread not recorded)"), std::string::npos)
      << md.out;
  auto csv = sh(exe() + " query table1 --db " + db + " --format csv");
  EXPECT_NE(csv.out.find("ca_h_err"), std::string::npos) << csv.out;

  // Resumable and idempotent: a second run adds nothing.
  const auto before = sh(exe() + " query sql \"SELECT count(*) AS n FROM cases\" --db " + db + " --format json").out;
  r = sh(campaign_cmd(env, dir + "/mf.toml", db, "--jobs 2"));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sh(exe() + " query sql \"SELECT count(*) AS n FROM cases\" --db " + db + " --format json").out, before);
}

// The honesty check (scripts/table1 --error-check): the answer of a two-level campaign
// (levels 1–2) with its error, against the value a third level gives (levels 1–2–3). Fake CaH of level L:
// 0.699 − 0.8 · 2^-L, so level 2 says 0.499 ± 0.2 (the level 1 → 2 difference) and level 3 gives 0.599: within,
// half an error off. With the answer shifted by more than its error the check must say so.
TEST(MultiFidelity, ErrorCheckPlacesTheFinerLevelAgainstTheTwoLevelErrorBar) {
  const std::string dir = fresh_dir("multi_fidelity_error_check");
  const std::string& grid = kOblateGrid;
  write_file(dir + "/two.toml", "[campaign]\nname = \"two\"\n" + grid + "levels = [1, 2]\n");
  write_file(dir + "/three.toml", "[campaign]\nname = \"three\"\n" + grid + "levels = [1, 2, 3]\n");
  const std::string env = "FAKE_STEPS=1 FAKE_STEP_S=0.001 FAKE_LEVEL_SHIFT=0.8";
  ASSERT_EQ(sh(campaign_cmd(env, dir + "/two.toml", dir + "/two.db", "--jobs 2")).code, 0);
  ASSERT_EQ(sh(campaign_cmd(env, dir + "/three.toml", dir + "/three.db", "--jobs 2")).code, 0);
  auto q = sh(exe() + " query table1 --db " + dir + "/two.db --format json");
  ASSERT_EQ(q.code, 0) << q.err;
  write_file(dir + "/two.json", q.out);
  // The answer's value on the other level its mesh error compared, at full precision: level 1's CaH, one
  // error (the level 1 -> 2 difference) below the level-2 answer.
  const auto two = nlohmann::json::parse(q.out);
  ASSERT_TRUE(two[0]["level_answers"].is_object()) << q.out;
  EXPECT_NEAR(two[0]["level_answers"]["ca_h"]["1"].get<double>(),
              two[0]["ca_h"].get<double>() - two[0]["ca_h_err"].get<double>(), 1e-12) << q.out;
  const std::string table1 =
      "/usr/bin/python3 " + std::string(CAPSIM_SOURCE_DIR) + "/scripts/table1 --capsim " + exe();
  auto r = sh(table1 + " --db " + dir + "/three.db --error-check " + dir + "/two.json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("| CaH | 0.5 ± 0.2 (1,2) | 0.60 | 0.50 errors | within |"), std::string::npos) << r.out;
  // The fake's Ca* edges do not move with the level: the crossing 0.015 lies at the edge of 0.018 ± 0.003.
  EXPECT_NE(r.out.find("3 of 3 level-3 values lie within"), std::string::npos) << r.out;
  // The same check against a coarse CaH moved down by 0.35: (0.599 − 0.149) / 0.2 = 2.25 errors, outside.
  auto moved = nlohmann::json::parse(q.out);
  moved[0]["ca_h"] = moved[0]["ca_h"].get<double>() - 0.35;
  write_file(dir + "/moved.json", moved.dump());
  r = sh(table1 + " --db " + dir + "/three.db --error-check " + dir + "/moved.json");
  EXPECT_NE(r.out.find("2.25 errors | **outside** |"), std::string::npos) << r.out;
  // Without a finer level there is nothing to check, and it says so.
  r = sh(table1 + " --db " + dir + "/two.db --error-check " + dir + "/two.json");
  EXPECT_NE(r.out.find("nothing to check"), std::string::npos) << r.out;
  EXPECT_EQ(sh(table1 + " --json " + dir + "/two.json --error-check " + dir + "/two.json").code, 2);
  // Transitions analysed before the level values were stored (schema 4) are refused with what to do.
  ASSERT_EQ(sh("sqlite3 " + dir + "/three.db 'UPDATE transitions SET level_answers = NULL'").code, 0);
  r = sh(table1 + " --db " + dir + "/three.db --error-check " + dir + "/two.json");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("capsim campaign analyse"), std::string::npos) << r.err;
}

// Rounds are sequential, so a worker left without a queued case used to wait for the round's last case — on
// the certified Table 1 a level-4 case of hours. Once only check-level cases run, the free worker now takes the
// next round's cases (analysis/multi_fidelity.h, rounds_may_overlap).
// Fake CaH of level L = 0.70 − 0.08 · 2^-L: level 3's CaH lies above level 2's final bracket, so the check
// level's second round runs the answer level's next sample outwards (0.8). With the Ca* check case at 0.015
// slow, that case starts while 0.015 still runs; the cases and the answers are those of the plain run.
TEST(MultiFidelity, AFreeWorkerTakesTheCheckLevelsNextCaseWhileALongOneRuns) {
  const std::string dir = fresh_dir("multi_fidelity_top_up");
  write_file(dir + "/mf.toml", "[campaign]\nname = \"mf\"\n" + kOblateGrid + "levels = [1, 2, 3]\n");
  const std::string env = "FAKE_STEPS=1 FAKE_STEP_S=0.001 FAKE_LEVEL_SHIFT=0.08";
  auto level3 = [&](const std::string& db) {
    return sh(exe() + " query sql \"SELECT capillary_number AS ca, started_at, finished_at FROM cases WHERE mesh_level = 3 "
                      "ORDER BY capillary_number\" --db " + db + " --format json").out;
  };
  auto rounds = [](const std::string& err) {
    int n = 0;
    for (auto at = err.find("capsim campaign: round "); at != std::string::npos;
         at = err.find("capsim campaign: round ", at + 1))
      ++n;
    return n;
  };
  auto r = sh(campaign_cmd(env, dir + "/mf.toml", dir + "/plain.db", "--jobs 2"));
  ASSERT_EQ(r.code, 0) << r.err;
  const int plain_rounds = rounds(r.err);
  const auto plain = nlohmann::json::parse(level3(dir + "/plain.db"));
  std::vector<double> plain_ca;
  for (const auto& c : plain) plain_ca.push_back(c["ca"]);
  // The scenario the test needs: 0.015 in the first check round, 0.8 the outwards case of the second.
  ASSERT_EQ(plain_ca, (std::vector<double>{0.015, 0.018, 0.04, 0.045, 0.663, 0.68, 0.8})) << r.err;
  ASSERT_NE(r.err.find("round 6, multi-fidelity: mesh check on level 3: 1 case(s) added"), std::string::npos) << r.err;

  r = sh(campaign_cmd(env + " FAKE_SLOW_CA=0.015 FAKE_SLOW_LEVEL=3 FAKE_SLOW_STEP_S=3", dir + "/mf.toml",
                      dir + "/top_up.db", "--jobs 2"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("round 6, multi-fidelity: mesh check on level 3, while 1 case(s) run or wait: 1 case(s) added"),
            std::string::npos) << r.err;
  EXPECT_EQ(rounds(r.err), plain_rounds) << "a top-up round counts towards max_rounds like the others: " << r.err;
  const auto top_up = nlohmann::json::parse(level3(dir + "/top_up.db"));
  ASSERT_EQ(top_up.size(), plain.size());
  EXPECT_LT(top_up[6]["started_at"].get<std::string>(), top_up[0]["finished_at"].get<std::string>())
      << "0.8 starts while 0.015 runs: " << top_up.dump();
  auto table = [&](const std::string& db) { return sh(exe() + " query table1 --db " + db + " --format json").out; };
  EXPECT_EQ(table(dir + "/top_up.db"), table(dir + "/plain.db"));

  // One worker, cheapest first: the check round's six cases are queued, the largest Ca (the cheapest) run first,
  // and once 0.663 and 0.68 are done the cell calls for 0.8. It joins the queue at once (everything left is a
  // check-level case) and, the cheapest, runs next — not after the four Ca* check cases (hours each on a real
  // level 4). The same cases and answers as the plain run.
  r = sh(campaign_cmd(env, dir + "/mf.toml", dir + "/one.db", "--jobs 1 --order shortest"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sql(dir + "/one.db", "SELECT c.capillary_number FROM attempts a JOIN cases c USING(case_id) "
                                 "WHERE c.mesh_level = 3 ORDER BY a.attempt_id"),
            "0.68\n0.663\n0.8\n0.045\n0.04\n0.018\n0.015\n")
      << r.err;
  EXPECT_NE(r.err.find("mesh check on level 3, while 4 case(s) run or wait: 1 case(s) added"), std::string::npos)
      << r.err;
  EXPECT_EQ(rounds(r.err), plain_rounds) << r.err;
  EXPECT_EQ(table(dir + "/one.db"), table(dir + "/plain.db"));
}

// Cells advance independently: a cell whose own cases are done takes its next round while another cell's cases
// still run, instead of waiting for the round of every cell to end. Two cells (oblate and prolate NH, answer level
// 2, dt check); one oblate scan case is slow: the prolate cell's answer level runs meanwhile, and the campaign ends
// with the same cases and the same Table 1 as a run without the slow case, and as one with a single worker.
TEST(MultiFidelity, ACellTakesItsNextRoundWhileAnotherCellsCasesRun) {
  const std::string dir = fresh_dir("multi_fidelity_cells");
  write_file(dir + "/mf.toml", two_cell_spec("0.1, 0.15, 0.2, 0.25, 0.3, 0.4, 0.6"));
  const std::string& env = kTwoCellEnv;
  auto cases = [&](const std::string& db) {
    return sql(db, "SELECT aspect_ratio, mesh_level, capillary_number, params_json FROM cases "
                   "ORDER BY aspect_ratio, mesh_level, capillary_number, params_json");
  };
  auto table = [&](const std::string& db) { return sh(exe() + " query table1 --db " + db + " --format json").out; };
  auto r = sh(campaign_cmd(env, dir + "/mf.toml", dir + "/plain.db", "--jobs 2"));
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_EQ(sql(dir + "/plain.db", "SELECT COUNT(*) FROM transitions WHERE role = 'dt_check' AND aspect_ratio = 2"),
            "1\n") << "the prolate cell has its dt check: " << r.err;

  // The oblate scan case lasts 10 s: long enough for the other worker to finish several prolate cases even when
  // ctest runs other suites beside this one (4 s was not, at a load average of 2 to 17).
  r = sh(campaign_cmd(env + " FAKE_SLOW_CA=0.8 FAKE_SLOW_LEVEL=1 FAKE_SLOW_STEP_S=10", dir + "/mf.toml",
                      dir + "/slow.db", "--jobs 2"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("dt/2 check on level 2, while "), std::string::npos) << r.err;
  const std::string slow_end = sql(dir + "/slow.db", "SELECT finished_at FROM cases WHERE aspect_ratio = 0.5 AND "
                                                     "mesh_level = 1 AND capillary_number = 0.8");
  const std::string prolate_answers_before = sql(
      dir + "/slow.db", "SELECT COUNT(*) FROM cases WHERE aspect_ratio = 2 AND mesh_level = 2 AND finished_at < '" +
                            slow_end.substr(0, slow_end.size() - 1) + "'");
  EXPECT_GT(std::stoi(prolate_answers_before), 3) << "the prolate answer level ran while the oblate scan case did";
  EXPECT_EQ(cases(dir + "/slow.db"), cases(dir + "/plain.db"));
  EXPECT_EQ(table(dir + "/slow.db"), table(dir + "/plain.db"));

  r = sh(campaign_cmd(env, dir + "/mf.toml", dir + "/one.db", "--jobs 1"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find(", while "), std::string::npos) << "a cell went ahead while the other's scan waited: " << r.err;
  // The coarser levels first: a scan case gates its cell's answer level, so none waits behind answer cases.
  const std::string levels = sql(dir + "/one.db", "SELECT c.mesh_level FROM attempts a JOIN cases c USING(case_id) "
                                                  "ORDER BY a.attempt_id");
  EXPECT_EQ(levels.find('1', levels.find('2')), std::string::npos) << levels;
  EXPECT_EQ(cases(dir + "/one.db"), cases(dir + "/plain.db"));
  EXPECT_EQ(table(dir + "/one.db"), table(dir + "/plain.db"));
}

// A cell's next round waits for the last case of its round, so the queue keeps a cell's round together and
// takes the cell with the most queued work first (Runner::order_by_level_and_cell). Longest first across cells
// had spread a round over the queue: on the main command a cell's cheap cases waited ≈ 11 min behind the other
// cells' long ones and its later rounds ran alone at the end (results/benchmarks.md). Two cells,
// one worker: the oblate cell has the most scan work, the prolate one the single longest scan case (Ca 0.005).
TEST(MultiFidelity, ACellsRoundRunsAsOneBlockTheCellWithTheMostQueuedWorkFirst) {
  const std::string dir = fresh_dir("multi_fidelity_cell_blocks");
  write_file(dir + "/mf.toml", two_cell_spec("0.005, 0.15, 0.2, 0.3, 0.6"));
  const std::string db = dir + "/one.db";
  auto r = sh(campaign_cmd(kTwoCellEnv, dir + "/mf.toml", db, "--jobs 1"));
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_NE(r.err.find(", while "), std::string::npos)
      << "a cell took a round while the other's cases waited: " << r.err;

  // The scenario: the cell with the most scan work (the estimate; no case has finished to calibrate it) is not
  // the one with the longest scan case, which longest first starts with.
  const std::string work = sql(db, "SELECT aspect_ratio FROM cases WHERE mesh_level = 1 GROUP BY aspect_ratio "
                                   "ORDER BY SUM(est_cost) DESC LIMIT 1");
  ASSERT_EQ(work, "0.5\n");
  ASSERT_EQ(sql(db, "SELECT aspect_ratio FROM cases WHERE mesh_level = 1 ORDER BY est_cost DESC LIMIT 1"), "2\n");

  // The cases in the order they started, each with its round: a cell's cases added at once (one top-up) were
  // all created after the same set of its cases had finished, and before any of their own finished.
  const std::string started = sql(
      db, "SELECT c.aspect_ratio || ' level ' || c.mesh_level || ' after ' || (SELECT COUNT(*) FROM cases d "
          "WHERE d.aspect_ratio = c.aspect_ratio AND d.finished_at <= c.created_at) || ' of its cases' "
          "FROM attempts a JOIN cases c USING(case_id) ORDER BY a.attempt_id");
  std::vector<std::string> rounds;  // one entry per block of consecutive starts of one round
  std::istringstream lines(started);
  for (std::string line; std::getline(lines, line);)
    if (rounds.empty() || rounds.back() != line) rounds.push_back(line);
  ASSERT_GT(rounds.size(), 4u) << started;
  EXPECT_EQ(rounds.front().substr(0, 4), "0.5 ") << "the cell with the most queued work first:\n" << started;
  std::set<std::string> seen;
  for (const auto& round : rounds)
    EXPECT_TRUE(seen.insert(round).second) << "another cell's case started within the round " << round << ":\n"
                                           << started;
}

}  // namespace
}  // namespace capsim::campaign::testing
