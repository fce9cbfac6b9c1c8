// The committed Table 1 files are what `capsim query table1 --format json` gives on the committed campaign
// databases (issue 5: "capsim query table1 --db results/table1.sqlite --format json reproduces the committed
// table"). The database is copied first so that the query cannot touch the repository's file.
#include <algorithm>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

// With `reanalyse`, the copy's transitions are first recomputed by this build's analysis (`capsim campaign
// analyse`): then the test also fails when a change to the analysis moves a committed answer, not only when
// the JSON lags the stored rows. (The paper-resolution and quick databases predate today's analysis and are
// compared as stored.)
void expect_query_reproduces(const std::string& db_name, const std::string& json_name, const std::string& campaign = "",
                             std::size_t rows = 6, bool reanalyse = false) {
  const fs::path results = fs::path(CAPSIM_SOURCE_DIR) / "results";
  // Both files are committed deliverables: a missing one is a failure, not a reason to skip.
  ASSERT_TRUE(fs::exists(results / db_name)) << "results/" << db_name << " is missing";
  ASSERT_TRUE(fs::exists(results / json_name)) << "results/" << json_name << " is missing";
  // One scratch folder per committed file: several databases share a file name (table1_mf_mixed.json in three
  // folders), and ctest -j runs their tests at once.
  std::string scratch = fs::path(json_name).replace_extension().string();
  std::replace(scratch.begin(), scratch.end(), '/', '_');
  const std::string dir = fresh_dir("committed_" + scratch);
  const std::string copy = dir + "/" + fs::path(db_name).filename().string();
  fs::copy_file(results / db_name, copy);
  if (reanalyse) {
    const CmdResult a = sh(exe() + " campaign analyse --db " + copy);
    ASSERT_EQ(a.code, 0) << a.err;
  }
  const std::string which = campaign.empty() ? "" : " --campaign " + campaign;
  const CmdResult r = sh(exe() + " query table1 --db " + copy + which + " --format json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto ours = nlohmann::json::parse(r.out);
  const auto committed = nlohmann::json::parse(read_file((results / json_name).string()));
  ASSERT_TRUE(ours.is_array());
  EXPECT_EQ(ours.size(), rows) << "two laws x three aspect ratios, or the cells the campaign has";
  EXPECT_EQ(ours, committed) << "results/" << json_name << " is stale: regenerate it with capsim query table1";
}

TEST(CommittedResults, PaperTableIsWhatTheDatabaseGives) { expect_query_reproduces("table1.sqlite", "table1.json"); }

TEST(CommittedResults, QuickTableIsWhatTheDatabaseGives) {
  expect_query_reproduces("table1_quick.sqlite", "table1_quick.json");
}

TEST(CommittedResults, MultiFidelityTableIsWhatTheDatabaseGives) {
  expect_query_reproduces("table1_mf.sqlite", "table1_mf.json", "", 6, true);
}

// What scripts/run computes since 2026-12-05 (the same preset with the Stokeslet sum in mixed precision).
TEST(CommittedResults, MixedPrecisionMultiFidelityTableIsWhatTheDatabaseGives) {
  expect_query_reproduces("table1_mf_mixed.sqlite", "table1_mf_mixed.json", "", 6, true);
}

// scripts/run itself, timed on an AVX-512 machine (results/main_command_avx512/README.md).
TEST(CommittedResults, MainCommandRunOnAvx512IsWhatTheDatabaseGives) {
  expect_query_reproduces("main_command_avx512/table1_mf_mixed.sqlite", "main_command_avx512/table1_mf_mixed.json", "",
                          6, true);
}

// The same with [analysis] stop_for_answer, timed on the same machine (results/main_command_stop_for_answer/).
TEST(CommittedResults, MainCommandRunWithStopForAnswerIsWhatTheDatabaseGives) {
  expect_query_reproduces("main_command_stop_for_answer/table1_mf_mixed.sqlite",
                          "main_command_stop_for_answer/table1_mf_mixed.json", "", 6, true);
}

// The main preset with time.rkc_safety = 1.0: the stability sweep on its cases (results/rkc_safety_sweep/).
TEST(CommittedResults, RkcSafetySweepIsWhatTheDatabaseGives) {
  expect_query_reproduces("rkc_safety_sweep/table1_mf_mixed_rkc1.sqlite", "rkc_safety_sweep/table1_mf_mixed_rkc1.json",
                          "", 6, true);
}

// scripts/run with the load options, timed from a fresh clone (results/main_command_15min/README.md).
TEST(CommittedResults, MainCommandRunWithTheLoadOptionsIsWhatTheDatabaseGives) {
  expect_query_reproduces("main_command_15min/before_central.sqlite", "main_command_15min/before_central.json", "", 6,
                          true);
}

// scripts/run with the central symmetry in the boundary integral and the membrane (12 min 36 s from a fresh clone;
// results/main_command_15min/README.md).
TEST(CommittedResults, MainCommandRunWithTheCentralSymmetryIsWhatTheDatabaseGives) {
  expect_query_reproduces("main_command_15min/central_d3c2b57.sqlite", "main_command_15min/central_d3c2b57.json", "",
                          6, true);
}

// scripts/run with the central symmetry in the load solve too (10 min 38 s from a fresh clone).
TEST(CommittedResults, MainCommandRunWithTheSymmetricLoadSolveIsWhatTheDatabaseGives) {
  expect_query_reproduces("main_command_15min/table1_mf_mixed.sqlite", "main_command_15min/table1_mf_mixed.json", "",
                          6, true);
}

// A time-step experiment on the main preset, not adopted (results/main_command_15min/README.md): every case at
// time.dt_accuracy 0.04. (Its sibling ca_star_dt004.sqlite mixes two accuracy steps in one level, which only the
// reverted option's grouping joined: this build's analysis splits it, so its JSON is that commit's.)
TEST(CommittedResults, TimeStepExperimentOfTheMainPresetIsWhatTheDatabaseGives) {
  expect_query_reproduces("main_command_15min/all_dt004.sqlite", "main_command_15min/all_dt004.json", "", 6, true);
}

// The certified campaign shares its database with the multi-fidelity one it continues; the query's default
// campaign is the most recently run, the certified one.
TEST(CommittedResults, CertifiedTableIsWhatTheDatabaseGives) {
  expect_query_reproduces("table1_certified.sqlite", "table1_certified.json", "", 6, true);
}

// Figure 6 (results/bending/README.md §8.2) is drawn from these two query outputs; their databases hold
// several campaigns each, so the campaign is named.
TEST(CommittedResults, BendingTableIsWhatTheDatabaseGives) {
  expect_query_reproduces("bending/table1_bending.sqlite", "bending/table1_kb1e-3.json", "table1-bending-1e-3");
}

// κ_b = 1e-2: the campaign is complete (2026-12-05); the committed file is its final state.
TEST(CommittedResults, StifferBendingTableIsWhatTheDatabaseGives) {
  expect_query_reproduces("bending/table1_bending.sqlite", "bending/table1_kb1e-2.json", "table1-bending-1e-2");
}

TEST(CommittedResults, OblateTransitionAtSmallBendingIsWhatTheDatabaseGives) {
  expect_query_reproduces("bending/oblate_regime.sqlite", "bending/oblate_regime_kb1e-4.json",
                          "bending-oblate-regime-1e-4", 1);
}

}  // namespace
}  // namespace capsim::campaign::testing
