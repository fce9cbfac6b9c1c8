// The fixed-shape Keller–Skalak threshold that scripts/plot draws in figure 7 (scripts/keller_skalak.py): its rigid
// (Jeffery) and spherical limits and its agreement with Roscoe (1967) are checked by tests/scripts/
// keller_skalak_check.py, run here so that the default suite runs them. Skipped when /usr/bin/python3 lacks numpy.
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

struct Outcome {
  int code = -1;
  std::string output;
};

// The command's exit code and its stdout and stderr together (unittest reports on stderr).
Outcome run(const std::string& cmd) {
  fs::create_directories(fs::path(CAPSIM_TEST_TMP) / "scripts");
  const auto log = fs::path(CAPSIM_TEST_TMP) / "scripts" / ("keller_skalak_" + std::to_string(getpid()) + ".log");
  const std::string full = "(" + cmd + ") >'" + log.string() + "' 2>&1";
  const int st = std::system(full.c_str());
  Outcome r;
  r.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  std::ifstream in(log);
  std::stringstream ss;
  ss << in.rdbuf();
  r.output = ss.str();
  fs::remove(log);
  return r;
}

TEST(KellerSkalak, LimitsAndRoscoeAgreementHold) {
  const std::string python = "/usr/bin/python3";
  if (run(python + " -c 'import numpy'").code != 0) GTEST_SKIP() << python << " lacks numpy (run scripts/setup)";
  const auto check = fs::path(CAPSIM_SOURCE_DIR) / "tests" / "scripts" / "keller_skalak_check.py";
  const Outcome r = run(python + " '" + check.string() + "'");
  EXPECT_EQ(r.code, 0) << r.output;
}

}  // namespace
