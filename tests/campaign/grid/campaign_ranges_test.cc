// A campaign checks every case key against the same range as a case file (duffy_order was once
// 2..64 in a case file but unchecked in a campaign grid), when the campaign file is parsed, with the
// campaign's "FILE: KEY: problem" message.
#include <string>

#include <gtest/gtest.h>

#include "campaign/common/bad_input.h"
#include "campaign/grid/campaign_spec.h"

namespace capsim::campaign {
namespace {

std::string parse_error(const std::string& grid) {
  try {
    (void)parse_campaign("[campaign]\nname = 'r'\n[[grid]]\n" + grid, "r.toml");
  } catch (const BadInput& e) {
    return e.what();
  }
  return "";
}

TEST(CampaignRanges, GridValuesOutsideTheCaseKeyRangeAreRejectedWhenParsed) {
  for (const char* axis : {"numerics.duffy_order = [1]", "numerics.duffy_order = [65]",
                           "numerics.regular_degree = [3]", "numerics.membrane_degree = [2]",
                           "flow.capillary_number = [1e308]", "mesh_level = [4294967299]",
                           "time.t_end = [1e300]"}) {
    const std::string why = parse_error(axis);
    EXPECT_NE(why.find("r.toml: [grid][1]."), std::string::npos) << axis << " -> '" << why << "'";
  }
  EXPECT_EQ(parse_error("numerics.duffy_order = [2, 64]\n"), "");
}

TEST(CampaignRanges, DefaultsAreCheckedToo) {
  try {
    (void)parse_campaign("[campaign]\nname = 'r'\n[defaults]\nnumerics.duffy_order = 1\n[[grid]]\nlaw = ['skalak']\n",
                         "r.toml");
    FAIL() << "duffy_order = 1 accepted in [defaults]";
  } catch (const BadInput& e) {
    EXPECT_NE(std::string(e.what()).find("[defaults] numerics.duffy_order"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace capsim::campaign
