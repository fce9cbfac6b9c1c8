// Placeholder until the query sub-command lands; replaced by its real implementation.
#include <cstdio>

#include "campaign/cli/commands.h"

namespace capsim::cli {
int query_command(const std::vector<std::string>&) {
  std::fprintf(stderr, "capsim: 'query' is not available in this build yet\n");
  return kExitBadInput;
}
}  // namespace capsim::cli
