// capsim waits passively for OpenMP work unless the user chose a policy: spinning threads take the cores
// from whatever shares them (campaign/cli/main.cc; measured in results/benchmarks.md, "Sharing the cores").
#include <gtest/gtest.h>

#include "tests/campaign/test_util.h"

namespace capsim::campaign::testing {
namespace {

// GNU OpenMP prints its settings each time the program is loaded when OMP_DISPLAY_ENV is set; the last
// block is the one the run uses.
std::string last_wait_policy(const std::string& err) {
  const auto at = err.rfind("OMP_WAIT_POLICY = '");
  if (at == std::string::npos) return "";
  const auto begin = at + 19;
  return err.substr(begin, err.find('\'', begin) - begin);
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(WaitPolicy, PassiveWhenTheUserSetNone) {
  const CmdResult r = sh("env -u OMP_WAIT_POLICY OMP_DISPLAY_ENV=true " + exe() + " --version");
  ASSERT_EQ(r.code, 0) << r.err;
  if (r.err.find("OMP_WAIT_POLICY") == std::string::npos && r.out.find("OMP_WAIT_POLICY") == std::string::npos)
    GTEST_SKIP() << "this OpenMP runtime does not display its settings (OMP_DISPLAY_ENV)";
  const std::string all = r.out + r.err;
  EXPECT_EQ(count(all, "OPENMP DISPLAY ENVIRONMENT BEGIN"), 2) << "capsim must re-execute itself once:\n" << all;
  EXPECT_EQ(last_wait_policy(all), "PASSIVE") << all;
  EXPECT_NE(r.out.find("capsim "), std::string::npos) << "the command itself still runs: " << r.out;
}

TEST(WaitPolicy, TheUsersChoiceStands) {
  const CmdResult r = sh("OMP_WAIT_POLICY=active OMP_DISPLAY_ENV=true " + exe() + " --version");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string all = r.out + r.err;
  if (all.find("OMP_WAIT_POLICY") == std::string::npos) GTEST_SKIP() << "runtime does not display its settings";
  EXPECT_EQ(count(all, "OPENMP DISPLAY ENVIRONMENT BEGIN"), 1) << all;
  EXPECT_EQ(last_wait_policy(all), "ACTIVE") << all;
}

}  // namespace
}  // namespace capsim::campaign::testing
