// The `capsim` executable: a thin dispatcher over the sub-commands in commands.h.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "campaign/cli/commands.h"
#include "capsim/version.h"

namespace {

void print_usage() {
  std::printf(
      "capsim %s (%s): elastic capsules in simple shear flow (FEM membrane + boundary integrals)\n\n"
      "usage:\n"
      "  capsim run CASE.toml [--set key=value]... [--out DIR] [--threads N] [--resume] [--json]\n"
      "  capsim campaign run CAMPAIGN.toml --db FILE [--jobs J] [--threads-per-job T] [--dry-run]\n"
      "  capsim campaign submit CAMPAIGN.toml --db FILE [--array-limit K] [--partition P] [--time HH:MM:SS]\n"
      "                         [--cases-per-task M] [--dry-run]\n"
      "  capsim campaign collect --db FILE\n"
      "  capsim campaign import --db FILE --from OTHER.sqlite [--campaign NAME] [--dry-run]\n"
      "  capsim campaign status --db FILE\n"
      "  capsim query table1|cases|transitions|sql ... --db FILE [--format md|csv|json]\n"
      "  capsim bench kernel [--json] [--threads T] [--repeat R]\n"
      "  capsim bench flow [--set key=value]... [--level L] [--bending KB] [--precision double|mixed] [--json]\n"
      "                    [--threads T] [--repeat R]\n"
      "  capsim keys --format md\n"
      "  capsim --version\n"
      "every command answers --help\n",
      capsim::kVersion, capsim::kGitCommit);
}

// OpenMP threads that spin while they wait for work take the cores from whatever else runs on them: with GNU
// OpenMP's default (spinning) wait, a case beside a second one slows down many times more than the sharing
// explains (measured in results/benchmarks.md, "Sharing the cores"). Campaign workers, Slurm tasks and users
// share cores all the time, so capsim waits passively unless the user chose otherwise. libgomp reads
// OMP_WAIT_POLICY once, when the program is loaded, so the only way to set it from inside is to set it and
// start this program again (once: the variable is then set). If the re-exec fails, capsim runs as it is.
void wait_passively_unless_told_otherwise(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr) return;
  setenv("OMP_WAIT_POLICY", "passive", 1);
  execv("/proc/self/exe", argv);
}

}  // namespace

int main(int argc, char** argv) {
  wait_passively_unless_told_otherwise(argv);
  if (argc < 2) {
    print_usage();
    return capsim::kExitBadInput;
  }
  const std::string cmd = argv[1];
  const std::vector<std::string> rest(argv + 2, argv + argc);
  if (cmd == "--version" || cmd == "version") {
    std::printf("capsim %s (commit %s)\n", capsim::kVersion, capsim::kGitCommit);
    return 0;
  }
  if (cmd == "--help" || cmd == "-h" || cmd == "help") {
    print_usage();
    return 0;
  }
  try {
    if (cmd == "run") return capsim::cli::run_command(rest);
    if (cmd == "_summary") return capsim::cli::summary_command(rest);
    if (cmd == "campaign") return capsim::cli::campaign_command(rest);
    if (cmd == "query") return capsim::cli::query_command(rest);
    if (cmd == "bench") return capsim::cli::bench_command(rest);
    if (cmd == "keys") return capsim::cli::keys_command(rest);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "capsim: internal error: %s\n", e.what());
    return capsim::kExitInternalError;
  }
  std::fprintf(stderr, "capsim: unknown command '%s' (see capsim --help)\n", cmd.c_str());
  return capsim::kExitBadInput;
}
