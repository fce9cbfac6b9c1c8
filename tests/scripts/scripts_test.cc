// The plotting and Table-1 scripts on the committed quick database: they produce their outputs, and a
// missing input is one clear message with exit code 2.
#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

bool have_matplotlib() {
  return std::system("/usr/bin/python3 -c 'import matplotlib, h5py, numpy' >/dev/null 2>&1") == 0;
}

std::string db() { return std::string(CAPSIM_SOURCE_DIR) + "/results/table1_quick.sqlite"; }

TEST(Scripts, Table1PrintsOursBesideTheSeed) {
  const CmdResult r = sh("/usr/bin/python3 " + std::string(CAPSIM_SOURCE_DIR) + "/scripts/table1 --db " + db() +
                         " --capsim " + exe());
  ASSERT_EQ(r.code, 0) << r.err;
  // Layout of the seed's Table 1 (a Ca* and a CaH row per law, one column per a/b), seed values beside ours.
  EXPECT_NE(r.out.find("| law | | a/b = 0.5 | a/b = 1 | a/b = 2 |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| NH | Ca* |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| Sk, C = 1 | Ca* |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("seed [0.20, 0.25]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Agree: "), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << "capsim query and the database read differ: " << r.err;
  const CmdResult bad = sh("/usr/bin/python3 " + std::string(CAPSIM_SOURCE_DIR) + "/scripts/table1 --db /nonexistent.sqlite --capsim " + exe());
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("/nonexistent.sqlite"), std::string::npos);
}

TEST(Scripts, PlotWritesFigure3FromTheDatabase) {
  if (!have_matplotlib()) GTEST_SKIP() << "/usr/bin/python3 lacks matplotlib/h5py (scripts/setup installs them)";
  const std::string out = fresh_dir("plot_fig3");
  const CmdResult r = sh("/usr/bin/python3 " + std::string(CAPSIM_SOURCE_DIR) + "/scripts/plot --db " + db() +
                         " --only 3 --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_GT(fs::file_size(out + "/figure3a_min_D12.png"), 10000u);
  EXPECT_GT(fs::file_size(out + "/figure3b_max_tau_min.png"), 10000u);
  const CmdResult bad = sh("/usr/bin/python3 " + std::string(CAPSIM_SOURCE_DIR) + "/scripts/plot --db /nonexistent.sqlite --only 3 --out " + out);
  EXPECT_EQ(bad.code, 2) << bad.err;
}

}  // namespace
}  // namespace capsim::campaign::testing
