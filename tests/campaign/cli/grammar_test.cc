// One command-line grammar: every sub-command of `capsim` answers --help (exit 0, its usage on stdout) and
// refuses what it does not know with one line and exit code 2; `capsim bench flow` takes any case key with
// --set, read and checked as `capsim run --set` reads them.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "campaign/common/exit_codes.h"
#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

int lines_of(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

// Every sub-command, as typed after `capsim`.
const std::vector<std::string> kCommands = {
    "run", "_summary", "campaign", "campaign run", "campaign submit", "campaign collect", "campaign import",
    "campaign analyse", "campaign status", "query", "query table1", "query cases", "query transitions", "query sql",
    "bench", "bench kernel", "bench flow", "keys"};

TEST(Grammar, EverySubcommandAnswersHelp) {
  for (const auto& cmd : kCommands) {
    const CmdResult r = sh(exe() + " " + cmd + " --help");
    EXPECT_EQ(r.code, 0) << cmd << ": " << r.err;
    EXPECT_EQ(r.err, "") << cmd;
    // The usage of the command asked for (a sub-command's own, not its parent's), with its options.
    EXPECT_NE(r.out.find("capsim " + cmd), std::string::npos) << cmd << ":\n" << r.out;
    EXPECT_NE(r.out.find("--help"), std::string::npos) << cmd << ":\n" << r.out;
  }
  const CmdResult flow = sh(exe() + " bench flow --help");
  for (const char* option : {"--set", "--level", "--json", "--threads", "--repeat"})
    EXPECT_NE(flow.out.find(option), std::string::npos) << option << ":\n" << flow.out;
  EXPECT_EQ(sh(exe() + " bench kernel --help").out.find("--set"), std::string::npos) << "kernel has no scene";
}

TEST(Grammar, AnUnknownOptionIsOneLineAndExitTwo) {
  for (const auto& cmd : kCommands) {
    const CmdResult r = sh(exe() + " " + cmd + " --frobnicate");
    EXPECT_EQ(r.code, kExitBadInput) << cmd << ": " << r.err;
    EXPECT_EQ(lines_of(r.err), 1) << cmd << ":\n" << r.err;
    EXPECT_NE(r.err.find("capsim"), std::string::npos) << cmd << ": " << r.err;
    EXPECT_EQ(r.out, "") << cmd;
  }
  for (const char* args : {"bench", "bench nosuch", "keys", "keys --format html", "query", "campaign"}) {
    const CmdResult r = sh(exe() + " " + args);
    EXPECT_EQ(r.code, kExitBadInput) << args << ": " << r.err;
    EXPECT_EQ(lines_of(r.err), 1) << args << ":\n" << r.err;
  }
}

TEST(Grammar, KeysPrintsTheRegistryTable) {
  const CmdResult r = sh(exe() + " keys --format md");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("mesh.level"), std::string::npos);
  EXPECT_NE(r.out.find("numerics.kernel_precision"), std::string::npos);
}

nlohmann::json bench_flow(const std::string& args) {
  const CmdResult r = sh(exe() + " bench flow --threads 1 --repeat 1 --json " + args);
  EXPECT_EQ(r.code, 0) << args << ": " << r.err;
  return r.code == 0 ? nlohmann::json::parse(r.out) : nlohmann::json::object();
}

// A case key with no option of its own reaches the benchmark's scene: numerics.regular_degree changes the
// regular quadrature, so the scene has more sources; mesh.level set with --set is the level --level sets.
TEST(Grammar, BenchFlowTakesAnyCaseKeyWithSet) {
  const auto plain = bench_flow("--set mesh.level=1");
  const auto finer = bench_flow("--set mesh.level=1 --set numerics.regular_degree=6");
  const auto shorthand = bench_flow("--level 1");
  ASSERT_FALSE(plain.empty());
  ASSERT_FALSE(finer.empty());
  ASSERT_FALSE(shorthand.empty());
  EXPECT_EQ(plain["level"], 1);
  EXPECT_EQ(plain["nodes"], 162);
  EXPECT_EQ(shorthand["nodes"], 162);
  const int n4 = plain["scenes"][1]["sources"], n6 = finer["scenes"][1]["sources"];
  EXPECT_GT(n6, n4) << "numerics.regular_degree=6 did not reach the scene";
  EXPECT_EQ(plain["scenes"][1]["sources"], shorthand["scenes"][1]["sources"]);
  EXPECT_EQ(finer["overrides"], nlohmann::json({"mesh.level=1", "numerics.regular_degree=6"}));
  // --set comes after the shorthands: it wins.
  EXPECT_EQ(bench_flow("--level 2 --set mesh.level=1")["level"], 1);
  EXPECT_EQ(bench_flow("--set numerics.kernel_precision=mixed --level 1")["kernel_precision"], "mixed");
}

// Bad --set values get run's messages (the key registry's), one line, exit 2.
TEST(Grammar, BenchFlowRefusesBadKeysAsRunDoes) {
  for (const auto& [set, expect] : std::vector<std::pair<std::string, std::string>>{
           {"mesh.level=9", "mesh.level"},
           {"nosuch.key=1", "unknown key 'nosuch.key'"},
           {"level", "expected section.key=value"},
           {"capsule.law=hookean", "capsule.law"}}) {
    const CmdResult bench = sh(exe() + " bench flow --set " + set);
    EXPECT_EQ(bench.code, kExitBadInput) << set;
    EXPECT_EQ(lines_of(bench.err), 1) << set << ":\n" << bench.err;
    EXPECT_NE(bench.err.find(expect), std::string::npos) << set << ": " << bench.err;
    const CmdResult run = sh(exe() + " run - --set " + set);
    EXPECT_EQ(run.code, kExitBadInput) << set;
    // The same words after each command's name.
    EXPECT_EQ(bench.err.substr(bench.err.find(':')), run.err.substr(run.err.find(':'))) << bench.err << run.err;
  }
}

}  // namespace
}  // namespace capsim::campaign::testing
