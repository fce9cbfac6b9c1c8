// `capsim bench flow`: the fields of its JSON, phases that add up to the evaluation, and bad input
// with exit code 2. Times are not asserted (they depend on the machine); only their consistency is.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

TEST(BenchFlow, JsonHasTheRatiosAndPhasesOfEveryScene) {
  const CmdResult r = sh(exe() + " bench flow --level 1 --threads 1 --repeat 3 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  for (const char* k : {"level", "nodes", "threads", "evaluation_ms", "regular_sum_ms", "overhead_ratio"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["level"], 1);
  EXPECT_EQ(j["nodes"], 162);
  EXPECT_EQ(j["threads"], 1);
  ASSERT_EQ(j["scenes"].size(), 3u);
  const auto& sym = j["scenes"][0];
  const auto& gen = j["scenes"][1];
  const auto& cen = j["scenes"][2];
  EXPECT_EQ(sym["scene"], "symmetric");
  EXPECT_EQ(cen["scene"], "central");
  EXPECT_TRUE(sym["used_symmetry"].get<bool>());
  EXPECT_FALSE(sym["used_central"].get<bool>());
  EXPECT_FALSE(gen["used_symmetry"].get<bool>());
  EXPECT_TRUE(cen["used_symmetry"].get<bool>());
  EXPECT_TRUE(cen["used_central"].get<bool>());
  EXPECT_LT(sym["targets"].get<int>(), gen["targets"].get<int>());
  EXPECT_LT(cen["targets"].get<int>(), sym["targets"].get<int>());
  EXPECT_EQ(gen["targets"], 162);
  for (const auto& s : {sym, gen, cen}) {
    double phases = 0.0;
    for (const char* k : {"membrane_ms", "load_ms", "layout_ms", "regular_ms", "far_ms", "singular_ms", "near_ms",
                          "volume_ms"}) {
      ASSERT_TRUE(s.contains(k)) << k;
      EXPECT_GE(s[k].get<double>(), 0.0) << k;
      phases += s[k].get<double>();
    }
    EXPECT_GT(s["singular_ms"].get<double>(), 0.0);
    // The named phases account for the evaluation: other_ms is what they miss (mean evaluation − phases).
    EXPECT_GE(s["other_ms"].get<double>(), -1e-9);
    EXPECT_NEAR(s["overhead_ratio"].get<double>(),
                s["evaluation_ms"].get<double>() / s["regular_sum_ms"].get<double>(), 1e-9);
    EXPECT_GT(phases, 0.0);
  }
}

TEST(BenchFlow, BadOptionsExitTwoWithOneMessage) {
  // (--level is mesh.level: the registry's range, 0..6, is the one checked.)
  for (const char* args : {"--level 9", "--level -1", "--level x", "--threads", "--frobnicate", "--repeat 0"}) {
    const CmdResult r = sh(exe() + " bench flow " + args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_NE(r.err.find("capsim bench"), std::string::npos) << args << ": " << r.err;
  }
  EXPECT_EQ(sh(exe() + " bench nosuch").code, 2);
  // Case keys are checked by the key registry: the message names the key.
  for (const auto& [args, key] : std::vector<std::pair<std::string, std::string>>{
           {"--precision half", "numerics.kernel_precision"},
           {"--bending -1", "capsule.bending_modulus"},
           {"--level 9", "mesh.level"}}) {
    const CmdResult r = sh(exe() + " bench flow " + args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_NE(r.err.find(key), std::string::npos) << args << ": " << r.err;
  }
}

}  // namespace
}  // namespace capsim::campaign::testing
