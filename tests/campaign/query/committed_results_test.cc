// The committed answers (results/README.md) against this build: each committed Table 1 file is what
// `capsim query table1 --format json` gives on its committed campaign database, after this build's analysis
// has recomputed the transitions from the stored case rows (`capsim campaign analyse`), so a change to the
// analysis or the renderer that moved a committed answer fails here; and the main command's answer agrees with
// the seed's Table 1 cell by cell (results/seed_table1.json), as scripts/run prints it. The database is copied
// first so that nothing can touch the repository's file.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

const fs::path kResults = fs::path(CAPSIM_SOURCE_DIR) / "results";

// `capsim query table1` of a scratch copy of results/DB_NAME (of `campaign`, else the latest campaign; with the
// table1 `options`, e.g. one λ), after `capsim campaign analyse` when `reanalyse`. Null on failure (recorded).
nlohmann::json query_table1(const std::string& db_name, const std::string& campaign, bool reanalyse,
                            const std::string& options = "") {
  // A committed deliverable: a missing one is a failure, not a reason to skip.
  if (!fs::exists(kResults / db_name)) {
    ADD_FAILURE() << "results/" << db_name << " is missing";
    return {};
  }
  // One scratch folder per database and campaign: ctest -j runs the tests at once.
  std::string scratch = fs::path(db_name).replace_extension().string() + "_" + campaign + options;
  for (char& ch : scratch)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '.' && ch != '_') ch = '_';
  const std::string dir = fresh_dir("committed_" + scratch);
  const std::string copy = dir + "/" + fs::path(db_name).filename().string();
  fs::copy_file(kResults / db_name, copy);
  const std::string which = campaign.empty() ? "" : " --campaign " + campaign;
  if (reanalyse) {
    const CmdResult a = sh(exe() + " campaign analyse --db " + copy + which);
    if (a.code != 0) {
      ADD_FAILURE() << "campaign analyse: " << a.err;
      return {};
    }
  }
  const CmdResult r = sh(exe() + " query table1 --db " + copy + which + " " + options + " --format json");
  if (r.code != 0) {
    ADD_FAILURE() << "query table1: " << r.err;
    return {};
  }
  return nlohmann::json::parse(r.out);
}

// Distance from x to the interval [from, to] (0 inside it).
double distance_to(double x, double from, double to) { return std::max({from - x, x - to, 0.0}); }

// With `reanalyse`, the transitions are first recomputed by this build's analysis: the test then fails when a
// change to the analysis moves a committed answer, not only when the JSON lags the stored rows. (The paper
// preset's database predates today's analysis and is compared as stored: a check of the renderer alone.)
void expect_query_reproduces(const std::string& db_name, const std::string& json_name, const std::string& campaign = "",
                             std::size_t rows = 6, bool reanalyse = true, const std::string& options = "") {
  ASSERT_TRUE(fs::exists(kResults / json_name)) << "results/" << json_name << " is missing";
  const auto ours = query_table1(db_name, campaign, reanalyse, options);
  const auto committed = nlohmann::json::parse(read_file((kResults / json_name).string()));
  ASSERT_TRUE(ours.is_array());
  EXPECT_EQ(ours.size(), rows) << "two laws x three aspect ratios, or the cells the campaign has";
  EXPECT_EQ(ours, committed) << "results/" << json_name << " is stale: regenerate it with capsim query table1";
}

// The main command's answer (results/table1/README.md).
TEST(CommittedResults, MainCommandTableIsWhatThisBuildComputesFromItsDatabase) {
  expect_query_reproduces("table1/table1_mf_mixed.sqlite", "table1/table1_mf_mixed.json");
}

// The seed agreement scripts/run reports ("Agree: 12"), from this build's analysis of the committed rows: a
// cell's Ca* agrees when our interval and the seed's overlap (or, for the spheres, neither has a transition),
// its CaH when within the seed file's relative tolerance of the seed's value. Beyond agreement, the seed lies
// within each of our 14 answers ± its error, once its numbers are read as what they can mean
// (results/seed_table1.json, "criterion"): a CaH to its printed digits, a Ca* edge to the seed's sampling step
// outwards (its lower crossing of 0.05 lies in [low - step, low], its upper one in [high, high + step]).
TEST(CommittedResults, MainCommandAnswerAgreesWithTheSeedInEveryCell) {
  const auto ours = query_table1("table1/table1_mf_mixed.sqlite", "", true);
  ASSERT_TRUE(ours.is_array());
  const auto seed = nlohmann::json::parse(read_file((kResults / "seed_table1.json").string()));
  const double tol = seed.at("ca_h_rel_tolerance").get<double>();
  int agreed = 0;
  for (const auto& s : seed.at("cells")) {
    const std::string cell = s.at("law").get<std::string>() + " a/b " + s.at("aspect_ratio").dump();
    const auto row = std::find_if(ours.begin(), ours.end(), [&](const nlohmann::json& r) {
      return r.at("law") == s.at("law") && r.at("aspect_ratio").get<double>() == s.at("aspect_ratio").get<double>();
    });
    ASSERT_NE(row, ours.end()) << cell << ": no answer";
    bool ca_star_agrees = true;
    if (s.at("ca_star_low").is_null()) {
      ca_star_agrees = row->at("ca_star_low").is_null() && row->at("ca_star_high").is_null();
      EXPECT_TRUE(ca_star_agrees) << cell << ": the seed has no Ca*, we have " << *row;
    } else {
      ASSERT_FALSE(row->at("ca_star_low").is_null() || row->at("ca_star_high").is_null()) << cell << ": no Ca*";
      const double lo = row->at("ca_star_low").get<double>(), hi = row->at("ca_star_high").get<double>();
      const double seed_lo = s.at("ca_star_low").get<double>(), seed_hi = s.at("ca_star_high").get<double>();
      ca_star_agrees = lo <= seed_hi && seed_lo <= hi;
      EXPECT_TRUE(ca_star_agrees) << cell << ": Ca* [" << lo << ", " << hi << "] against the seed's " << s;
      const double step = s.at("ca_step").get<double>();
      const auto expect_seed_within_error = [&](const std::string& edge, double seed_from, double seed_to) {
        const double err = row->at(edge + "_err").get<double>();
        EXPECT_GT(err, 0) << cell << " " << edge;
        EXPECT_LE(distance_to(row->at(edge).get<double>(), seed_from, seed_to), err) << cell << " " << edge;
      };
      expect_seed_within_error("ca_star_low", seed_lo - step, seed_lo);
      expect_seed_within_error("ca_star_high", seed_hi, seed_hi + step);
    }
    ASSERT_FALSE(row->at("ca_h").is_null()) << cell << ": no CaH";
    const double ca_h = row->at("ca_h").get<double>(), seed_ca_h = s.at("ca_h").get<double>();
    const bool ca_h_agrees = std::abs(ca_h - seed_ca_h) <= tol * seed_ca_h;
    EXPECT_TRUE(ca_h_agrees) << cell << ": CaH " << ca_h << " against the seed's " << seed_ca_h;
    const double half = s.at("ca_h_precision").get<double>() / 2, ca_h_err = row->at("ca_h_err").get<double>();
    EXPECT_GT(ca_h_err, 0) << cell;
    EXPECT_LE(distance_to(ca_h, seed_ca_h - half, seed_ca_h + half), ca_h_err) << cell << " CaH";
    agreed += ca_star_agrees && ca_h_agrees;
  }
  EXPECT_EQ(agreed, 6) << "all six cells (twelve entries) agree";
}

// The certified campaign shares its database with the multi-fidelity one it continues; the query's default
// campaign is the most recently run, the certified one (results/table1_certified/README.md).
TEST(CommittedResults, CertifiedTableIsWhatThisBuildComputesFromItsDatabase) {
  expect_query_reproduces("table1_certified/table1_certified.sqlite", "table1_certified/table1_certified.json");
}

// Its levels 2-3 answers, against which the certified table checks the error bars (table1_mf.md there).
TEST(CommittedResults, LevelsTwoAndThreeTableIsWhatThisBuildComputesFromTheCertifiedDatabase) {
  expect_query_reproduces("table1_certified/table1_certified.sqlite", "table1_certified/table1_mf.json", "table1-mf");
}

TEST(CommittedResults, PaperTableIsWhatTheDatabaseGives) {
  expect_query_reproduces("table1_paper/table1_paper.sqlite", "table1_paper/table1_paper.json", "", 6, false);
}

// Figure 6 (results/bending/README.md §8.2) is drawn from these two query outputs; their databases hold
// several campaigns each, so the campaign is named.
TEST(CommittedResults, BendingTableIsWhatTheDatabaseGives) {
  expect_query_reproduces("bending/table1_bending.sqlite", "bending/table1_kb1e-3.json", "table1-bending-1e-3");
}

TEST(CommittedResults, StifferBendingTableIsWhatTheDatabaseGives) {
  expect_query_reproduces("bending/table1_bending.sqlite", "bending/table1_kb1e-2.json", "table1-bending-1e-2");
}

TEST(CommittedResults, OblateTransitionAtSmallBendingIsWhatTheDatabaseGives) {
  expect_query_reproduces("bending/oblate_regime.sqlite", "bending/oblate_regime_kb1e-4.json",
                          "bending-oblate-regime-1e-4", 1);
}

// The viscosity-ratio study (results/viscosity_ratio/README.md): each λ's Table 1 as committed.
TEST(CommittedResults, ViscosityRatioStudyTablesAreWhatThisBuildComputesFromItsDatabase) {
  for (const char* lambda : {"0.2", "1", "5", "10"})
    expect_query_reproduces("viscosity_ratio/viscosity_ratio.sqlite",
                            std::string("viscosity_ratio/table1_lambda") + lambda + ".json", "", 6, true,
                            std::string("--viscosity-ratio ") + lambda);
}

}  // namespace
}  // namespace capsim::campaign::testing
