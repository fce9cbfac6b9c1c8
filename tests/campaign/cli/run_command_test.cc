// `capsim run` as users call it: bad input, the JSON contract, interruption and exact resume.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "solver/io/checkpoint.h"
#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

std::string run(const std::string& args) { return exe() + " run " + args; }

nlohmann::json last_json_line(const std::string& out) {
  const auto end = out.find_last_not_of('\n');
  const auto begin = out.rfind('\n', end);
  return nlohmann::json::parse(out.substr(begin == std::string::npos ? 0 : begin + 1, end + 1));
}

struct BadCase {
  const char* name;
  const char* file_text;  // nullptr: the file does not exist
  const char* extra;
  const char* must_mention;
};

class RunBadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(RunBadInput, ExitsWithCode2AndNamesTheKey) {
  const BadCase& c = GetParam();
  const std::string dir = fresh_dir(std::string("run_bad_") + c.name);
  const std::string file = dir + "/case.toml";
  if (c.file_text) write_file(file, c.file_text);
  const CmdResult r = sh(run(file + " --out " + dir + "/out " + c.extra));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(c.must_mention), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out/case.h5")) << "nothing may run on bad input";
}

INSTANTIATE_TEST_SUITE_P(
    Cases, RunBadInput,
    ::testing::Values(BadCase{"unknown_key", "[capsule]\nradius = 2\n", "", "capsule.radius"},
                      BadCase{"unknown_section", "[fluid]\nCa = 2\n", "", "fluid.Ca"},
                      BadCase{"wrong_type", "[flow]\ncapillary_number = \"fast\"\n", "", "flow.capillary_number"},
                      BadCase{"negative_ca", "[flow]\ncapillary_number = -0.1\n", "", "flow.capillary_number"},
                      BadCase{"level", "[mesh]\nlevel = 9\n", "", "mesh.level"},
                      BadCase{"law", "[capsule]\nlaw = \"mooney\"\n", "", "capsule.law"},
                      BadCase{"skalak_C", "[capsule]\nskalak_C = -0.5\n", "", "capsule.skalak_C"},
                      BadCase{"aspect_ratio", "[capsule]\naspect_ratio = 0\n", "", "capsule.aspect_ratio"},
                      BadCase{"dt_word", "[time]\ndt = \"soon\"\n", "", "time.dt"},
                      BadCase{"syntax", "[flow\ncapillary_number = 1\n", "", "case.toml"},
                      BadCase{"missing_file", nullptr, "", "case.toml"},
                      BadCase{"bad_override", "", "--set flow.capillary_number=abc", "flow.capillary_number"},
                      BadCase{"unknown_override", "", "--set flow.speed=1", "flow.speed"}),
    [](const auto& info) { return std::string(info.param.name); });

const char* kTinyCase =
    "[capsule]\naspect_ratio = 2.0\nlaw = \"neo-hookean\"\n[flow]\ncapillary_number = 0.3\n"
    "[mesh]\nlevel = 1\n[time]\nt_end = 1.5\ncheck_interval = 0.5\n[output]\ncheckpoint_interval = 0.5\n";

TEST(RunCommand, JsonSummaryHasTheContractKeys) {
  const std::string dir = fresh_dir("run_json");
  write_file(dir + "/case.toml", kTinyCase);
  const CmdResult r = sh(run(dir + "/case.toml --out " + dir + "/out --threads 1 --json"));
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = last_json_line(r.out);
  for (const char* key : {"status", "capillary_number", "aspect_ratio", "law", "skalak_C", "mesh_level", "min_D12",
                          "max_tau_min", "mean_D12", "period", "regime", "volume_drift", "steps", "dt", "t_final",
                          "wall_s", "code_version"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["status"], "done");
  EXPECT_EQ(j["law"], "neo-hookean");
  EXPECT_EQ(j["mesh_level"], 1);
  EXPECT_NEAR(j["t_final"].get<double>(), 1.5, j["dt"].get<double>());
  EXPECT_LT(std::abs(j["volume_drift"].get<double>()), 1e-2);
  EXPECT_TRUE(fs::exists(dir + "/out/case.h5"));
  // The effective configuration is echoed with every key.
  EXPECT_NE(r.err.find("dt_factor"), std::string::npos);
}

// A run stopped part-way (as by SIGTERM) and resumed ends bitwise where an uninterrupted run ends.
TEST(RunCommand, ResumeAfterInterruptionMatchesUninterruptedRun) {
  const std::string dir = fresh_dir("run_resume");
  write_file(dir + "/case.toml", kTinyCase);
  const CmdResult full = sh(run(dir + "/case.toml --out " + dir + "/full --threads 1 --json --quiet"));
  ASSERT_EQ(full.code, 0) << full.err;

  const CmdResult part = sh(run(dir + "/case.toml --out " + dir + "/part --threads 1 --json --quiet --stop-after 37"));
  ASSERT_EQ(part.code, 3) << part.err;
  EXPECT_EQ(last_json_line(part.out)["status"], "interrupted");
  const CmdResult rest = sh(run(dir + "/case.toml --out " + dir + "/part --threads 1 --json --quiet --resume"));
  ASSERT_EQ(rest.code, 0) << rest.err;

  const auto a = io::read_checkpoint(dir + "/full/checkpoint.h5");
  const auto b = io::read_checkpoint(dir + "/part/checkpoint.h5");
  EXPECT_EQ(a.step, b.step);
  EXPECT_TRUE(a.positions == b.positions) << "final positions differ";
  EXPECT_TRUE(a.series == b.series) << "time series differ";
  const auto ja = last_json_line(full.out), jb = last_json_line(rest.out);
  EXPECT_EQ(ja["steps"], jb["steps"]);
  EXPECT_EQ(ja["volume_drift"], jb["volume_drift"]);
}

TEST(RunCommand, ResumeRefusesACheckpointOfAnotherCase) {
  const std::string dir = fresh_dir("run_resume_other");
  write_file(dir + "/case.toml", kTinyCase);
  ASSERT_EQ(sh(run(dir + "/case.toml --out " + dir + "/o --threads 1 --quiet --stop-after 3")).code, 3);
  const CmdResult r = sh(run(dir + "/case.toml --out " + dir + "/o --threads 1 --quiet --resume --set flow.capillary_number=0.5"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("checkpoint"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace capsim::campaign::testing
