// scripts/plot and scripts/table1: figures and Table 1 from a real (tiny) case file and a synthetic campaign
// database (tests/scripts/make_fixture.py, built on the real schema); clear errors on missing input.
// Skipped when /usr/bin/python3 lacks matplotlib, h5py or numpy (run scripts/setup).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

const std::string kPython = "/usr/bin/python3";
const std::string kSrc = CAPSIM_SOURCE_DIR;

struct Cmd {
  int code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

fs::path tmp_root() { return fs::path(CAPSIM_TEST_TMP) / "scripts"; }

Cmd sh(const std::string& cmd) {
  static int n = 0;
  fs::create_directories(tmp_root());
  const auto base = tmp_root() / ("sh_" + std::to_string(getpid()) + "_" + std::to_string(n++));
  const std::string full = "(" + cmd + ") >" + base.string() + ".out 2>" + base.string() + ".err";
  const int st = std::system(full.c_str());
  Cmd r;
  r.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  r.out = slurp(base.string() + ".out");
  r.err = slurp(base.string() + ".err");
  fs::remove(base.string() + ".out");
  fs::remove(base.string() + ".err");
  return r;
}

// Built by appending: `"'" + p.string() + "'"` trips GCC 12's false -Wrestrict positive once inlined.
std::string q(const fs::path& p) {
  std::string s(1, '\'');
  s += p.string();
  s += '\'';
  return s;
}
// The scripts read databases through `capsim query`: they are handed the capsim under test, wherever it was built.
std::string plot() { return kPython + " " + q(fs::path(kSrc) / "scripts" / "plot") + " --capsim " + q(CAPSIM_EXE_PATH); }
std::string table1() {
  return kPython + " " + q(fs::path(kSrc) / "scripts" / "table1") + " --capsim " + q(CAPSIM_EXE_PATH);
}
std::string mesh_check() { return kPython + " " + q(fs::path(kSrc) / "scripts" / "mesh_check"); }
std::string compare_campaigns() { return kPython + " " + q(fs::path(kSrc) / "scripts" / "compare_campaigns"); }

bool is_png(const fs::path& p) {
  const std::string s = slurp(p);
  return s.size() > 1000 && s.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0;
}

int count_lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

/// Shared fixture: one real level-1 run with snapshots (Skalak a/b = 2, Ca = 0.9) and the synthetic database.
class ScriptsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const Cmd probe = sh(kPython + " -c 'import matplotlib, h5py, numpy'");
    if (probe.code != 0) {
      skip_reason_ = "/usr/bin/python3 lacks matplotlib/h5py/numpy (run scripts/setup): " + probe.err;
      return;
    }
    // One fixture per process: ctest runs the tests of this suite as parallel processes.
    dir_ = tmp_root() / ("fixture_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const Cmd run = sh(std::string(CAPSIM_EXE_PATH) + " run " +
                       q(fs::path(kSrc) / "campaign/presets/cases/figure2_swinging.toml") +
                       " --set mesh.level=1 --set time.t_end=3 --set output.snapshot_interval=0.5 --threads 1 --out " +
                       q(dir_ / "case"));
    ASSERT_EQ(run.code, 0) << run.err;
    ASSERT_TRUE(fs::exists(dir_ / "case" / "case.h5"));
    const Cmd fx = sh(kPython + " " + q(fs::path(kSrc) / "tests/scripts/make_fixture.py") + " " + q(kSrc) + " " +
                      q(dir_ / "fixture.sqlite") + " " + q(dir_ / "case" / "case.h5"));
    ASSERT_EQ(fx.code, 0) << fx.err;
  }
  void SetUp() override {
    if (!skip_reason_.empty()) GTEST_SKIP() << skip_reason_;
  }
  static inline std::string skip_reason_;
  static inline fs::path dir_;
};

TEST_F(ScriptsTest, PlotsFigures1And2FromACaseFile) {
  const auto out = dir_ / "fig_case";
  fs::remove_all(out);
  const Cmd r = sh(plot() + " --case " + q(dir_ / "case" / "case.h5") + " --only 1,2 --frames 3 --out " + q(out));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(is_png(out / "figure1_profiles.png"));
  EXPECT_TRUE(is_png(out / "figure2_D12.png"));
  EXPECT_NE(r.out.find("wrote " + (out / "figure2_D12.png").string()), std::string::npos) << r.out;
  // --case-dir finds the same file; the section style works too.
  const Cmd r2 = sh(plot() + " --case-dir " + q(dir_ / "case") + " --only 1 --fig1-style section --out " +
                    q(out / "section"));
  ASSERT_EQ(r2.code, 0) << r2.err;
  EXPECT_TRUE(is_png(out / "section" / "figure1_profiles.png"));
}

TEST_F(ScriptsTest, PlotsFigure3AndFigure2FromTheDatabase) {
  const auto out = dir_ / "fig_db";
  fs::remove_all(out);
  const Cmd r = sh(plot() + " --db " + q(dir_ / "fixture.sqlite") + " --pdf --out " + q(out));
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* name : {"figure3a_min_D12", "figure3b_max_tau_min", "figure2_D12", "figure1_profiles"}) {
    EXPECT_TRUE(is_png(out / (std::string(name) + ".png"))) << name;
    EXPECT_GT(fs::file_size(out / (std::string(name) + ".pdf")), 1000u) << name;
  }
  EXPECT_NE(r.err.find("1 unstable case"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Ca = 0.1"), std::string::npos) << "missing figure-2 case not reported: " << r.err;
}

// Figures 4 and 5 (bending) from a real tiny bending campaign: level 1, κ_b = 0, 1e-3, 1e-2, γ̇t ≤ 1 (seconds);
// figure 5 from a committed study with full periods.
TEST_F(ScriptsTest, PlotsTheBendingFigureFromABendingCampaign) {
  const auto toml = dir_ / "bending.toml";
  {
    std::ofstream f(toml);
    f << "[campaign]\nname = 'tiny-bending'\n[defaults]\ntime.t_end = 1.0\ncapsule.aspect_ratio = 0.5\n"
         "flow.capillary_number = 0.05\nmesh.level = 1\n[[grid]]\nbending_modulus = [0.0, 1e-3, 1e-2]\n";
  }
  const auto db = dir_ / "bending.sqlite";
  const Cmd run = sh(std::string(CAPSIM_EXE_PATH) + " campaign run " + q(toml) + " --db " + q(db) +
                     " --jobs 1 --threads-per-job 1");
  ASSERT_EQ(run.code, 0) << run.err;
  const auto out = dir_ / "fig_bending";
  fs::remove_all(out);
  const Cmd r = sh(plot() + " --db " + q(db) + " --only 4,5 --out " + q(out));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(is_png(out / "bending_figure4.png"));
  // γ̇t ≤ 1 holds no full period: figure 5 (the answers against κ_b) says why it is not drawn.
  EXPECT_FALSE(fs::exists(out / "bending_figure5.png"));
  EXPECT_NE(r.err.find("figure 5: none of the bending cases"), std::string::npos) << r.err;
  const auto out5 = dir_ / "fig_bending5";
  fs::remove_all(out5);
  const Cmd f5 = sh(plot() + " --db " + q(fs::path(kSrc) / "results" / "bending" / "convergence.sqlite") +
                    " --only 5 --out " + q(out5));
  ASSERT_EQ(f5.code, 0) << f5.err;
  EXPECT_TRUE(is_png(out5 / "bending_figure5.png"));
  // A database without bending has nothing for figure 4: one note, exit 1.
  const Cmd none = sh(plot() + " --db " + q(dir_ / "fixture.sqlite") + " --only 4 --out " + q(out));
  EXPECT_EQ(none.code, 1) << none.err;
  EXPECT_NE(none.err.find("no finished case with a bending modulus"), std::string::npos) << none.err;
}

// Figure 6 (Table 1 against κ_b) from `capsim query table1 --format json` files, one per campaign: drawn when
// a row has κ_b > 0, a cell without a bracketed CaH named in a note; without any κ_b > 0 nothing to draw
// (exit 1), a corrupt file one message and exit 2.
TEST_F(ScriptsTest, PlotsTable1AgainstTheBendingModulus) {
  const auto kb0 = dir_ / "table1_kb0.json";
  const auto kb2 = dir_ / "table1_kb1e-2.json";
  std::ofstream(kb0) << R"([{"law": "neo-hookean", "aspect_ratio": 0.5, "ca_star_low": 0.025, "ca_star_high": 0.05,
      "ca_h": 0.6, "ca_star_low_err": 0.01, "ca_star_high_err": 0.008, "ca_h_err": 0.4, "bending_modulus": 0.0},
      {"law": "skalak", "aspect_ratio": 1.0, "ca_h": 2.46, "ca_h_err": 0.04}])";
  std::ofstream(kb2) << R"([{"law": "neo-hookean", "aspect_ratio": 0.5, "ca_star_low": 0.15, "ca_star_high": 0.2,
      "ca_h": 0.67, "ca_h_err": 0.13, "bending_modulus": 0.01},
      {"law": "skalak", "aspect_ratio": 1.0, "ca_h": null, "bending_modulus": 0.01}])";
  const auto out = dir_ / "fig6";
  fs::remove_all(out);
  const Cmd r = sh(plot() + " --table1 " + q(kb0) + " --table1 " + q(kb2) + " --only 6 --out " + q(out));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(is_png(out / "bending_figure6.png"));
  EXPECT_NE(r.err.find("Sk a/b 1 κ_b 0.01: CaH not bracketed"), std::string::npos) << r.err;
  const Cmd zero = sh(plot() + " --table1 " + q(kb0) + " --only 6 --out " + q(dir_ / "fig6_none"));
  EXPECT_EQ(zero.code, 1) << zero.err;
  EXPECT_NE(zero.err.find("no --table1 row has a bending modulus > 0"), std::string::npos) << zero.err;
  const auto junk = dir_ / "junk_table1.json";
  std::ofstream(junk) << "{not json";
  const Cmd bad = sh(plot() + " --table1 " + q(junk) + " --only 6 --out " + q(out));
  EXPECT_EQ(bad.code, 2) << bad.err;
  EXPECT_EQ(count_lines(bad.err), 1) << bad.err;
  EXPECT_NE(bad.err.find("junk_table1.json"), std::string::npos) << bad.err;
}

// Figure 7 (the viscosity ratio) from the committed λ study: a figure and a table with a row per law × a/b × λ; a
// database of one λ is refused with one message (exit 2), as the figure needs a viscosity_ratio axis.
TEST_F(ScriptsTest, PlotsTheViscosityRatioFigureFromTheCommittedStudy) {
  const auto out = dir_ / "fig7";
  fs::remove_all(out);
  const auto db = fs::path(kSrc) / "results/viscosity_ratio/viscosity_ratio.sqlite";
  ASSERT_TRUE(fs::exists(db)) << "the committed study is a deliverable";
  fs::create_directories(out);
  fs::copy_file(db, out / "study.sqlite");  // queried read-only, but not in the source tree
  const Cmd r = sh(plot() + " --db " + q(out / "study.sqlite") + " --only 7 --out " + q(out));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(is_png(out / "viscosity_ratio_figure7.png"));
  const std::string table = slurp(out / "viscosity_ratio_table.md");
  EXPECT_EQ(count_lines(table), 2 + 2 * 3 * 4) << table;  // header, rule, 2 laws × 3 a/b × 4 λ
  for (const char* lam : {"| 0.2 |", "| 1 |", "| 5 |", "| 10 |"}) EXPECT_NE(table.find(lam), std::string::npos) << lam;
  const Cmd one = sh(plot() + " --db " + q(dir_ / "fixture.sqlite") + " --only 7 --out " + q(out / "one"));
  EXPECT_EQ(one.code, 2) << one.err;
  EXPECT_NE(one.err.find("one viscosity ratio only"), std::string::npos) << one.err;
}

// Figure 8 (the regime map) from the committed stability study, its two levels given as two databases: a figure and a
// table with a row per law × a/b × Ca × level and a column per starting tilt; a database without a tilted case is
// refused with one message (exit 2), and so are several databases for another figure.
TEST_F(ScriptsTest, PlotsTheRegimeMapFromTwoLevels) {
  const auto out = dir_ / "fig8";
  fs::remove_all(out);
  fs::create_directories(out);
  for (const char* name : {"stability.sqlite", "stability_level3.sqlite"}) {
    const auto db = fs::path(kSrc) / "results/stability" / name;
    ASSERT_TRUE(fs::exists(db)) << "the committed study is a deliverable";
    fs::copy_file(db, out / name);  // queried read-only, but not in the source tree
  }
  const std::string dbs = " --db " + q(out / "stability.sqlite") + " --db " + q(out / "stability_level3.sqlite");
  const Cmd r = sh(plot() + dbs + " --only 8 --out " + q(out));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(is_png(out / "regime_map_figure8.png"));
  const std::string table = slurp(out / "regime_map_table.md");
  EXPECT_EQ(count_lines(table), 2 + 12 * 2) << table;  // header, rule, 12 cells × Ca on 2 levels
  EXPECT_NE(table.find("| from 5° |"), std::string::npos) << table;
  EXPECT_NE(table.find("| Sk | 2 | 0.1 | 3 | kayaking"), std::string::npos) << table;
  const Cmd flat = sh(plot() + " --db " + q(dir_ / "fixture.sqlite") + " --only 8 --out " + q(out / "flat"));
  EXPECT_EQ(flat.code, 2) << flat.err;
  EXPECT_NE(flat.err.find("no finished case started off the shear plane"), std::string::npos) << flat.err;
  const Cmd other = sh(plot() + dbs + " --only 3 --out " + q(out / "other"));
  EXPECT_EQ(other.code, 2) << other.err;
  EXPECT_NE(other.err.find("several --db are for figure 8 alone"), std::string::npos) << other.err;
}

TEST_F(ScriptsTest, Table1FromTheDatabaseComparesCellByCell) {
  const auto md = dir_ / "table1.md";
  fs::remove(md);
  const Cmd r = sh(table1() + " --db " + q(dir_ / "fixture.sqlite") + " --out " + q(md));
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string t = slurp(md);
  EXPECT_EQ(t, r.out);
  EXPECT_NE(t.find("Agree: 3, disagree: 2, missing: 5."), std::string::npos) << t;
  EXPECT_NE(t.find("| a/b = 0.5 | a/b = 1 | a/b = 2 |"), std::string::npos) << t;
  EXPECT_NE(t.find("✓ [0.03, 0.05] · seed [0.02, 0.04]"), std::string::npos) << t;  // seed values from the json
  EXPECT_NE(t.find("✗ [0.30, 0.35] · seed [0.20, 0.25]"), std::string::npos) << t;
  EXPECT_NE(t.find("not sampled"), std::string::npos) << t;
  EXPECT_NE(t.find("min_D12 never below 0.05"), std::string::npos) << t;
  EXPECT_NE(t.find("seed 2.5 "), std::string::npos) << t;  // with the digits the seed printed
}

// A sphere whose max τmin is negative at every sampled Ca (the NH sphere with κ_b = 1e-2, results/bending/README.md
// §6) has no CaH below its samples: it is compressed below CaL as well. The cell says so instead of "< Ca".
TEST_F(ScriptsTest, Table1DoesNotBoundTheCaHOfAnAllCompressedSphere) {
  const auto db = dir_ / "sphere.sqlite";
  fs::copy_file(dir_ / "fixture.sqlite", db, fs::copy_options::overwrite_existing);
  const Cmd ins = sh("sqlite3 " + q(db) +
                     " \"INSERT INTO transitions(campaign_id, law, aspect_ratio, skalak_C, mesh_level, d12_threshold, "
                     "n_samples, ca_h_high, method, note, updated_at) VALUES (1, 'neo-hookean', 1.0, -1.0, 1, 0.05, 3, "
                     "0.267, 'grid', 'max_tau_min < 0 at the smallest sampled Ca', '2026-01-01T00:00:00Z')\"");
  if (ins.code != 0) GTEST_SKIP() << "sqlite3 command-line tool not available";
  const Cmd r = sh(table1() + " --db " + q(db));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("| none ≥ 0 · seed 0.63 <sup>"), std::string::npos) << r.out;  // missing, not ✗
  EXPECT_NE(r.out.find("no tension window [CaL, CaH] sampled"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("< 0.27"), std::string::npos) << r.out;
  // As the analysis now stores it: no bound, the reason in the note.
  const Cmd now = sh("sqlite3 " + q(db) +
                     " \"UPDATE transitions SET ca_h_high = NULL, note = 'max_tau_min < 0 at every sampled Ca (0.267 to "
                     "0.8): no tension window [CaL, CaH] sampled, and a sphere is compressed below CaL too, so no bound "
                     "on CaH' WHERE ca_h_high = 0.267\"");
  ASSERT_EQ(now.code, 0) << now.err;
  const Cmd r2 = sh(table1() + " --db " + q(db));
  ASSERT_EQ(r2.code, 0) << r2.err;
  EXPECT_NE(r2.out.find("| none ≥ 0 · seed 0.63 <sup>"), std::string::npos) << r2.out;
  EXPECT_NE(r2.out.find("max τmin < 0 at every sampled Ca (0.267 to 0.8): no tension window"), std::string::npos)
      << r2.out;
}

TEST_F(ScriptsTest, Table1FromCapsimQueryJson) {
  const auto js = dir_ / "table1.json";
  const Cmd j = sh(std::string(CAPSIM_EXE_PATH) + " query table1 --db " + q(dir_ / "fixture.sqlite") +
                   " --format json > " + q(js));
  ASSERT_EQ(j.code, 0) << j.err;
  const Cmd r = sh(table1() + " --json " + q(js));
  ASSERT_EQ(r.code, 0) << r.err;
  // Without the database the CaH lower bound of NH a/b = 2 is unknown: missing instead of disagreeing.
  EXPECT_NE(r.out.find("Agree: 3, disagree: 1, missing: 6."), std::string::npos) << r.out;
  const Cmd piped = sh("cat " + q(js) + " | " + table1() + " --json -");
  ASSERT_EQ(piped.code, 0) << piped.err;
  EXPECT_NE(piped.out.find("Agree: 3, disagree: 1, missing: 6."), std::string::npos);
}

// Answers with errors (capsim query table1 of a schema-4 database) print "x ± e" and say how far the seed is,
// counted from the nearest value the seed's number allows (results/seed_table1.json): a CaH to its printed
// digits, a Ca* edge to the seed's sampling step outwards. Each expected distance differs from the one
// counted from the printed value, so the test fails if the rounding or the step is ignored.
TEST_F(ScriptsTest, Table1PrintsErrorsAndHowFarTheSeedIs) {
  const auto js = dir_ / "table1_err.json";
  {
    std::ofstream f(js);
    f << R"([{"law": "neo-hookean", "aspect_ratio": 0.5, "ca_star_low": 0.026, "ca_star_high": 0.056,
              "ca_h": 0.6034, "ca_star_low_err": 0.003, "ca_star_high_err": 0.004, "ca_h_err": 0.047},
             {"law": "skalak", "aspect_ratio": 1.0, "ca_h": 2.46, "ca_h_err": 0.004, "ca_h_err_lacks": "mesh,dt"},
             {"law": "skalak", "aspect_ratio": 2.0, "ca_star_low": 0.216, "ca_star_high": 0.369,
              "ca_h": 1.31, "ca_h_err": 0.12}])";
  }
  const Cmd r = sh(table1() + " --json " + q(js));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("0.60 ± 0.05 · seed 0.70"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("[0.026 ± 0.003, 0.056 ± 0.004]"), std::string::npos) << r.out;
  // Lower edge: seed 0.02 sampled at step 0.01, crossing in [0.01, 0.02]: (0.026 - 0.02) / 0.003.
  EXPECT_NE(r.out.find("lower edge: seed 2.0 errors away"), std::string::npos) << r.out;
  // Upper edge: seed 0.04, crossing in [0.04, 0.05]: (0.056 - 0.05) / 0.004 (4.0 from the printed 0.04).
  EXPECT_NE(r.out.find("upper edge: seed 1.5 errors away"), std::string::npos) << r.out;
  // CaH 0.70 printed to 0.01, so in [0.695, 0.705]: (0.695 - 0.6034) / 0.047 (2.1 from the printed 0.70).
  EXPECT_NE(r.out.find("seed 1.9 errors away"), std::string::npos) << r.out;
  // CaH 2.4 printed to 0.1, so in [2.35, 2.45]: (2.46 - 2.45) / 0.004 (15 from the printed 2.4).
  EXPECT_NE(r.out.find("seed 2.5 errors away"), std::string::npos) << r.out;
  // That error lacks its mesh and dt parts (schemas/006): marked as a lower bound, the others are not.
  EXPECT_NE(r.out.find("2.460 ± 0.004† · seed 2.4"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("† error a lower bound (no mesh, dt data)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("0.60 ± 0.05†"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1.3 ± 0.2 · seed 1.4 "), std::string::npos) << r.out;  // the seed's digits
  EXPECT_NE(r.out.find("seed within our error"), std::string::npos) << r.out;  // |1.31 - 1.40| < 0.12
}

// A campaign with a bending axis has two rows per cell: scripts/table1 names the option instead of picking one,
// and with it compares that κ_b's answers, saying that the seed's membrane has no bending stiffness.
TEST_F(ScriptsTest, Table1ChoosesOneBendingModulus) {
  const auto js = dir_ / "table1_kb.json";
  {
    std::ofstream f(js);
    f << R"([{"law": "skalak", "aspect_ratio": 1.0, "ca_h": 2.46, "ca_h_err": 0.04, "bending_modulus": 0.001},
             {"law": "skalak", "aspect_ratio": 1.0, "ca_h": 2.59, "ca_h_err": 0.07, "bending_modulus": 0.01}])";
  }
  const Cmd both = sh(table1() + " --json " + q(js));
  EXPECT_EQ(both.code, 2) << both.out;
  EXPECT_NE(both.err.find("--bending-modulus"), std::string::npos) << both.err;
  const Cmd one = sh(table1() + " --json " + q(js) + " --bending-modulus 0.01");
  ASSERT_EQ(one.code, 0) << one.err;
  EXPECT_NE(one.out.find("2.59 ± 0.07 · seed 2.4"), std::string::npos) << one.out;
  EXPECT_NE(one.out.find("κ_b = 0.01; the seed's membrane has none"), std::string::npos) << one.out;
  const Cmd none = sh(table1() + " --json " + q(js) + " --bending-modulus 0.1");
  EXPECT_EQ(none.code, 2) << none.out;
}

TEST_F(ScriptsTest, MissingInputsExitTwoWithOneMessage) {
  const auto nope = dir_ / "does-not-exist";
  for (const std::string& cmd :
       {plot() + " --db " + q(nope / "x.sqlite"), plot() + " --case " + q(nope / "case.h5"),
        plot() + " --case-dir " + q(nope), table1() + " --db " + q(nope / "x.sqlite"),
        table1() + " --json " + q(nope / "t.json"),
        table1() + " --db " + q(dir_ / "fixture.sqlite") + " --seed " + q(nope / "seed.json")}) {
    const Cmd r = sh(cmd + " --out " + q(dir_ / "unused"));
    EXPECT_EQ(r.code, 2) << cmd << "\n" << r.err;
    EXPECT_EQ(count_lines(r.err), 1) << cmd << "\n" << r.err;
    EXPECT_NE(r.err.find("does-not-exist"), std::string::npos) << r.err;
  }
  // Not a database / not a case file.
  const auto junk = dir_ / "junk.sqlite";
  std::ofstream(junk) << "not sqlite\n";
  const Cmd r = sh(plot() + " --db " + q(junk));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  const Cmd r2 = sh(plot() + " --case " + q(junk));
  EXPECT_EQ(r2.code, 2) << r2.err;
}

TEST_F(ScriptsTest, MeshCheckComparesRunsOverOneWindow) {
  const auto h5 = dir_ / "case" / "case.h5";
  // The same file twice: identical rows. The fixture run stops at t = 3 without a period, so the window
  // is given; it must end at --t1 and be --period long.
  const Cmd r = sh(mesh_check() + " A=" + q(h5) + " B=" + q(h5) + " --period 1 --t1 2.5");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("Common window: t in [1.50, 2.50] (period 1.00)"), std::string::npos) << r.out;
  const auto row = [&](const std::string& label) {
    const auto b = r.out.find("\n| " + label + " | ");
    EXPECT_NE(b, std::string::npos) << r.out;
    const auto e = r.out.find('\n', b + 1);
    return r.out.substr(b + 4 + label.size(), e - b - 4 - label.size());
  };
  EXPECT_EQ(row("A"), row("B"));
  EXPECT_NE(row("A").find("| 1 |"), std::string::npos) << "mesh level of the fixture (1) not shown: " << r.out;
  EXPECT_NE(row("A").find("— / —"), std::string::npos) << "no period: the reported values are missing";
  // The window values, computed here independently from the raw series: min D12 and max τmin over
  // [1.5, 2.5], then max τmin over [0.5, 1.5] (the k = 2 window).
  const Cmd ref = sh(kPython + " -c \"import h5py, numpy as np; f = h5py.File('" + h5.string() +
                     "', 'r'); t = f['timeseries/t'][:]; d = f['timeseries/D12'][:]; m = f['timeseries/tau_min'][:];"
                     " w = (t >= 1.5) & (t <= 2.5); v = (t >= 0.5) & (t <= 1.5);"
                     " print('| %.4f | %+.4f |' % (d[w].min(), m[w].max())); print('| %+.4f, %+.4f |' % (m[w].max(), m[v].max()))\"");
  ASSERT_EQ(ref.code, 0) << ref.err;
  const auto nl = ref.out.find('\n');
  ASSERT_NE(nl, std::string::npos) << ref.out;
  const std::string window_cells = ref.out.substr(0, nl);                                   // "| D12 | τ |"
  const std::string per_window = ref.out.substr(nl + 1, ref.out.find('\n', nl + 1) - nl - 1);  // "| τ1, τ2 |"
  EXPECT_NE(row("A").find(window_cells), std::string::npos) << window_cells << " not in\n" << r.out;
  EXPECT_NE(row("A").find(per_window), std::string::npos) << per_window << " not in\n" << r.out;
  // Without a period in the file and none given, one clear message and exit code 2.
  const Cmd no_period = sh(mesh_check() + " A=" + q(h5));
  EXPECT_EQ(no_period.code, 2) << no_period.err;
  EXPECT_NE(no_period.err.find("--period"), std::string::npos) << no_period.err;
  for (const std::string& bad : {" A=" + q(dir_ / "does-not-exist.h5"), std::string(" just-a-path.h5")}) {
    const Cmd b = sh(mesh_check() + bad + " --period 1");
    EXPECT_EQ(b.code, 2) << bad << "\n" << b.err;
  }
  // --plot draws the series into a PNG; an unwritable path is bad input.
  const auto png = dir_ / "mesh_check.png";
  const Cmd p = sh(mesh_check() + " A=" + q(h5) + " B=" + q(h5) + " --period 1 --t1 2.5 --plot " + q(png));
  ASSERT_EQ(p.code, 0) << p.err;
  EXPECT_TRUE(is_png(png));
  const Cmd unwritable = sh(mesh_check() + " A=" + q(h5) + " --period 1 --plot " + q(dir_ / "no-such-dir" / "x.png"));
  EXPECT_EQ(unwritable.code, 2) << unwritable.err;
}

// scripts/compare_campaigns: two copies of the fixture database whose cases get real parameters, B's with an
// extra key (as a mixed-precision rerun has) and one min D12 moved by 0.0123. Matched without that key, every
// finished case pairs up, the largest difference is that one, at that case; without --ignore nothing matches
// (exit 2); a missing database is exit 2 with one message.
TEST_F(ScriptsTest, CompareCampaignsPairsTheSameCasesAndFindsTheLargestDifference) {
  const auto a = dir_ / "cmp_a.sqlite", b = dir_ / "cmp_b.sqlite";
  const std::string prep =
      "import json, shutil, sqlite3, sys\n"
      "for path, extra in ((sys.argv[1], {}), (sys.argv[2], {'numerics.kernel_precision': 'mixed'})):\n"
      "    shutil.copy(sys.argv[3], path)\n"
      "    con = sqlite3.connect(path)\n"
      "    for cid, law, ar, ca in con.execute('SELECT case_id, law, aspect_ratio, capillary_number FROM cases').fetchall():\n"
      "        p = dict({'capsule.law': law, 'capsule.aspect_ratio': ar, 'flow.capillary_number': ca, 'mesh.level': 1}, **extra)\n"
      "        con.execute('UPDATE cases SET params_json = ? WHERE case_id = ?', (json.dumps(p), cid))\n"
      "    if extra:\n"
      "        con.execute(\"UPDATE results SET min_D12 = min_D12 + 0.0123 WHERE case_id = 'case0003'\")\n"
      "    con.commit()\n";
  std::ofstream(dir_ / "cmp_prep.py") << prep;
  const Cmd made = sh(kPython + " " + q(dir_ / "cmp_prep.py") + " " + q(a) + " " + q(b) + " " + q(dir_ / "fixture.sqlite"));
  ASSERT_EQ(made.code, 0) << made.err;
  const Cmd r = sh(compare_campaigns() + " " + q(a) + " " + q(b) + " --ignore numerics.kernel_precision --capsim " +
                   q(CAPSIM_EXE_PATH));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("22 cases finished in both"), std::string::npos) << r.out;  // 23 cases, one unstable
  EXPECT_NE(r.out.find("| min_D12 | 1.23e-02 | NH a/b 0.5 Ca 0.05 L1 |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| max_tau_min | 0.00e+00 |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Only in A (0)"), std::string::npos) << r.out;
  const Cmd unmatched = sh(compare_campaigns() + " " + q(a) + " " + q(b) + " --capsim " + q(CAPSIM_EXE_PATH));
  EXPECT_EQ(unmatched.code, 2) << unmatched.out;
  EXPECT_NE(unmatched.err.find("--ignore"), std::string::npos) << unmatched.err;
  const Cmd missing = sh(compare_campaigns() + " " + q(dir_ / "does-not-exist.sqlite") + " " + q(b));
  EXPECT_EQ(missing.code, 2);
  EXPECT_EQ(count_lines(missing.err), 1) << missing.err;
}

TEST(SeedTable1, HoldsTheSeedValues) {
  // results/seed_table1.json is the one place of the seed's Table 1; spot-check it against the paper.
  const std::string s = slurp(fs::path(kSrc) / "results" / "seed_table1.json");
  ASSERT_FALSE(s.empty());
  for (const char* cell :
       {R"("law": "neo-hookean", "aspect_ratio": 0.5, "ca_star_low": 0.02, "ca_star_high": 0.04, "ca_h": 0.70)",
        R"("law": "neo-hookean", "aspect_ratio": 1.0, "ca_star_low": null, "ca_star_high": null, "ca_h": 0.63)",
        R"("law": "neo-hookean", "aspect_ratio": 2.0, "ca_star_low": 0.20, "ca_star_high": 0.25, "ca_h": 0.35)",
        R"("aspect_ratio": 0.5, "ca_star_low": 0.02, "ca_star_high": 0.05, "ca_h": 2.5)",
        R"("aspect_ratio": 1.0, "ca_star_low": null, "ca_star_high": null, "ca_h": 2.4)",
        R"("aspect_ratio": 2.0, "ca_star_low": 0.25, "ca_star_high": 0.35, "ca_h": 1.4)"})
    EXPECT_NE(s.find(cell), std::string::npos) << cell;
}

}  // namespace
