// Every committed campaign preset parses and expands (campaign/presets/**.toml; campaign/presets/cases holds
// case files for `capsim run`, not campaigns): a preset a user is told to run must not fail on a typo.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "campaign/common/bad_input.h"
#include "campaign/grid/campaign_spec.h"

namespace capsim::campaign {
namespace {

namespace fs = std::filesystem;

TEST(Presets, EveryCampaignPresetParsesAndExpands) {
  const fs::path root = fs::path(CAPSIM_SOURCE_DIR) / "campaign/presets";
  int checked = 0;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (!e.is_regular_file() || e.path().extension() != ".toml") continue;
    if (e.path().parent_path().filename() == "cases") continue;
    std::ifstream in(e.path());
    std::stringstream text;
    text << in.rdbuf();
    try {
      const CampaignSpec spec = parse_campaign(text.str(), e.path().string());
      EXPECT_FALSE(expand_grid(spec).empty()) << e.path();
    } catch (const BadInput& x) {
      ADD_FAILURE() << e.path() << ": " << x.what();
    }
    ++checked;
  }
  EXPECT_GE(checked, 10) << "the presets directory moved?";
}

}  // namespace
}  // namespace capsim::campaign
