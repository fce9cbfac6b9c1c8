// `capsim keys --format md`: the case-key registry as the documentation block of schemas/case_keys.md.
#include <cstdio>
#include <string>
#include <vector>

#include "campaign/cli/commands.h"
#include "solver/config/case_keys.h"

namespace capsim::cli {

int keys_command(const std::vector<std::string>& args) {
  if (args.size() != 2 || args[0] != "--format" || args[1] != "md") {
    std::fprintf(stderr,
                 "capsim keys: usage: capsim keys --format md (prints the generated block of "
                 "schemas/case_keys.md)\n");
    return kExitBadInput;
  }
  std::fputs(config::case_keys_markdown().c_str(), stdout);
  return 0;
}

}  // namespace capsim::cli
