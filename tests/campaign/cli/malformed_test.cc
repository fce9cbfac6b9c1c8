// Malformed campaign files: exit 2, one clear message naming the key or file, the database untouched.
#include <gtest/gtest.h>

#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

const std::string kGood = R"([campaign]
name = "good"
[defaults]
mesh.level = 1
[[grid]]
aspect_ratio = [0.5]
capillary_number = [0.02, 0.03]
)";

struct Bad {
  const char* what;
  std::string text;
  const char* expect;  // substring the message must contain (the key)
};

std::vector<Bad> bad_files() {
  const std::string head = "[campaign]\nname = \"bad\"\n";
  return {
      {"unknown top-level key", head + "[grids]\nx = 1\n[[grid]]\ncapillary_number = [0.1]\n", "grids"},
      {"unknown case key", head + "[defaults]\nmesh.lvl = 2\n[[grid]]\ncapillary_number = [0.1]\n", "mesh.lvl"},
      {"wrong type", head + "[[grid]]\ncapillary_number = [\"0.1\"]\n", "capillary_number"},
      {"wrong type in defaults", head + "[defaults]\nmesh.level = 1.5\n[[grid]]\ncapillary_number = [0.1]\n",
       "mesh.level"},
      {"empty axis", head + "[[grid]]\ncapillary_number = []\n", "capillary_number"},
      {"empty grid block", head + "[[grid]]\n", "[grid][1]"},
      {"no grid", head + "[defaults]\nmesh.level = 1\n", "[[grid]]"},
      {"negative Ca", head + "[[grid]]\ncapillary_number = [0.1, -0.2]\n", "capillary_number"},
      {"range with zero step", head + "[[grid]]\ncapillary_number = { start = 0.1, stop = 0.2, step = 0 }\n",
       "step"},
      {"range backwards", head + "[[grid]]\ncapillary_number = { start = 0.3, stop = 0.2, step = 0.01 }\n",
       "stop must be >= start"},
      {"range not a multiple", head + "[[grid]]\ncapillary_number = { start = 0.1, stop = 1.0, step = 0.2 }\n",
       "not a multiple"},
      {"range with a typo", head + "[[grid]]\ncapillary_number = { start = 0.1, stop = 0.2, stp = 0.1 }\n", "stp"},
      {"unknown law", head + "[[grid]]\nlaw = [\"mooney\"]\n", "mooney"},
      {"mesh level out of range", head + "[[grid]]\nmesh_level = [7]\n", "mesh_level"},
      {"Skalak C too small", head + "[[grid]]\nskalak_C = [-0.6]\n", "skalak_C"},
      {"unknown axis", head + "[[grid]]\nreynolds = [1]\n", "reynolds"},
      {"threshold out of range", head + "[[grid]]\ncapillary_number = [0.1]\n[analysis]\nD12_threshold = 1.5\n",
       "D12_threshold"},
      {"missing name", "[campaign]\n[[grid]]\ncapillary_number = [0.1]\n", "name"},
      {"TOML syntax error", head + "[[grid]]\ncapillary_number = [0.1,\n", "TOML syntax"},
      {"value the solver rejects", head + "[defaults]\nmesh.spheroid_map = \"bogus\"\n[[grid]]\ncapillary_number = [0.1]\n",
       "spheroid_map"},
      {"axis twice", head + "[[grid]]\nlaw = [\"skalak\"]\ncapsule.law = [\"skalak\"]\n", "twice"},
  };
}

TEST(Malformed, EveryKindExitsTwoAndLeavesTheDatabaseUntouched) {
  const std::string dir = fresh_dir("malformed");
  const std::string db = dir + "/study.db";
  write_file(dir + "/good.toml", kGood);
  auto r = sh(campaign_cmd("FAKE_STEPS=1", dir + "/good.toml", db, "--jobs 2"));
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string before = read_file(db);
  ASSERT_FALSE(before.empty());
  const auto runs_before = std::distance(fs::directory_iterator(db + ".runs"), fs::directory_iterator());
  const auto bad = bad_files();
  ASSERT_GE(bad.size(), 10u);
  for (std::size_t i = 0; i < bad.size(); ++i) {
    const std::string file = dir + "/bad" + std::to_string(i) + ".toml";
    write_file(file, bad[i].text);
    for (const std::string& target : {db, dir + "/fresh.db"}) {
      auto b = sh(campaign_cmd("", file, target, "--jobs 1"));
      EXPECT_EQ(b.code, 2) << bad[i].what << ": " << b.err;
      EXPECT_EQ(count_lines(b.err), 1) << bad[i].what << ": " << b.err;
      EXPECT_NE(b.err.find(bad[i].expect), std::string::npos) << bad[i].what << ": " << b.err;
      EXPECT_NE(b.err.find(file), std::string::npos) << bad[i].what << ": " << b.err;
    }
    EXPECT_FALSE(fs::exists(dir + "/fresh.db")) << bad[i].what;
    EXPECT_EQ(read_file(db), before) << bad[i].what;
  }
  // Missing file.
  auto m = sh(campaign_cmd("", dir + "/nope.toml", db));
  EXPECT_EQ(m.code, 2);
  EXPECT_NE(m.err.find("nope.toml"), std::string::npos) << m.err;
  // Bad options.
  EXPECT_EQ(sh(campaign_cmd("", dir + "/good.toml", db, "--jobs 0")).code, 2);
  EXPECT_EQ(sh(campaign_cmd("", dir + "/good.toml", db, "--order random")).code, 2);
  EXPECT_EQ(sh(exe() + " campaign run " + dir + "/good.toml").code, 2);  // no --db
  EXPECT_EQ(read_file(db), before);
  EXPECT_EQ(std::distance(fs::directory_iterator(db + ".runs"), fs::directory_iterator()), runs_before);
}

}  // namespace
}  // namespace capsim::campaign::testing
