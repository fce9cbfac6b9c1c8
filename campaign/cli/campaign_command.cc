// Placeholder until the campaign sub-command lands; replaced by its real implementation.
#include <cstdio>

#include "campaign/cli/commands.h"

namespace capsim::cli {
int campaign_command(const std::vector<std::string>&) {
  std::fprintf(stderr, "capsim: 'campaign' is not available in this build yet\n");
  return kExitBadInput;
}
}  // namespace capsim::cli
