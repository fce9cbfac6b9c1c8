// `capsim run` as users call it: bad input, the JSON contract, interruption and exact resume.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "campaign/common/exit_codes.h"
#include "campaign/grid/case_params.h"
#include "campaign/store/store.h"
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
  // The resumed run reports the whole case's cost, not only its own part's.
  EXPECT_EQ(ja["flow_evaluations"], jb["flow_evaluations"]);
  EXPECT_GT(jb["wall_s"].get<double>(), last_json_line(part.out)["wall_s"].get<double>());
}

TEST(RunCommand, ResumeRefusesACheckpointOfAnotherCase) {
  const std::string dir = fresh_dir("run_resume_other");
  write_file(dir + "/case.toml", kTinyCase);
  ASSERT_EQ(sh(run(dir + "/case.toml --out " + dir + "/o --threads 1 --quiet --stop-after 3")).code, 3);
  const CmdResult r = sh(run(dir + "/case.toml --out " + dir + "/o --threads 1 --quiet --resume --set flow.capillary_number=0.5"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("checkpoint"), std::string::npos) << r.err;
}

// Defect 10: an output folder that cannot be created is not bad input: its own exit code, one line that
// names the folder, no case run.
TEST(RunCommand, UnwritableOutputFolderHasItsOwnExitCode) {
  const std::string dir = fresh_dir("run_unwritable");
  write_file(dir + "/case.toml", kTinyCase);
  write_file(dir + "/plain_file", "");
  const CmdResult r = sh(run(dir + "/case.toml --out " + dir + "/plain_file/out --threads 1 --quiet --json"));
  EXPECT_EQ(r.code, kExitWriteFailed) << r.err;
  EXPECT_NE(r.err.find("plain_file/out"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  EXPECT_EQ(r.out, "") << "no result line";
}

// The worker's line of `capsim run --json` is what the store reads back: parameters checked, results stored.
TEST(RunCommand, StoreReadsTheJsonSummaryBack) {
  const std::string dir = fresh_dir("run_store_reads");
  write_file(dir + "/case.toml", kTinyCase);
  const CmdResult r = sh(run(dir + "/case.toml --out " + dir + "/out --threads 1 --quiet --json"));
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string line = r.out.substr(r.out.rfind('\n', r.out.size() - 2) + 1);
  const auto j = parse_result_line(line);
  ASSERT_TRUE(j.has_value()) << line;
  CaseParams p = CaseParams::defaults();
  p.set("capsule.aspect_ratio", 2.0);
  p.set("capsule.law", std::string("neo-hookean"));
  p.set("flow.capillary_number", 0.3);
  p.set("mesh.level", std::int64_t{1});
  EXPECT_EQ(result_mismatch(*j, p), "");
  p.set("flow.capillary_number", 0.5);
  EXPECT_EQ(result_mismatch(*j, p), "capillary_number 0.3");
}

// Defect 7: a result of another skalak_C does not belong to a Skalak case (it was accepted).
TEST(RunCommand, ResultOfAnotherSkalakCIsRejected) {
  CaseParams p = CaseParams::defaults();
  p.set("capsule.law", std::string("skalak"));
  p.set("capsule.skalak_C", 1.0);
  const nlohmann::json reported = {{"status", "done"},           {"capillary_number", p.capillary_number()},
                                   {"aspect_ratio", p.aspect_ratio()}, {"law", "skalak"},
                                   {"skalak_C", 2.0},                  {"mesh_level", p.mesh_level()}};
  const std::string line = reported.dump();
  const auto j = parse_result_line(line);
  ASSERT_TRUE(j.has_value()) << line;
  EXPECT_NE(result_mismatch(*j, p), "") << "skalak_C 2 reported for a case with skalak_C 1";
  nlohmann::json same = *j;
  same["skalak_C"] = 1.0;
  EXPECT_EQ(result_mismatch(same, p), "");
  // For the neo-Hookean law skalak_C is not a parameter of the case (nor of its identity).
  p.set("capsule.law", std::string("neo-hookean"));
  nlohmann::json nh = *j;
  nh["law"] = "neo-hookean";
  EXPECT_EQ(result_mismatch(nh, p), "");
}

// The hidden `capsim _summary` (test workers) prints the summary of the given fields with every contract key.
TEST(RunCommand, SummaryCommandPrintsTheCompleteSummary) {
  const CmdResult r = sh(exe() + " _summary status=done capillary_number=0.3 aspect_ratio=2 law=skalak skalak_C=1 "
                                 "mesh_level=2 min_D12=0.25 code_version=fake");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = last_json_line(r.out);
  EXPECT_EQ(j["min_D12"], 0.25);
  EXPECT_EQ(j["Ca"], 0.3);
  EXPECT_EQ(j["law"], "skalak");
  EXPECT_TRUE(j["period"].is_null());
  EXPECT_TRUE(j.contains("flow_evaluations"));
  EXPECT_EQ(sh(exe() + " _summary status=done law=skalak").code, kExitBadInput) << "parameters are required";
}

}  // namespace
}  // namespace capsim::campaign::testing
