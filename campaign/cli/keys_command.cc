// `capsim keys --format md`: the case-key registry as the documentation block of schemas/case_keys.md.
#include <cstdio>
#include <string>
#include <vector>

#include "campaign/cli/cli_app.h"
#include "campaign/cli/commands.h"
#include "solver/config/case_keys.h"

namespace capsim::cli {

int keys_command(const std::vector<std::string>& args) {
  CLI::App app{"The case keys of the registry (solver/config/case_keys.def) as the generated block of "
               "schemas/case_keys.md",
               "capsim keys"};
  std::string format;
  app.add_option("--format", format, "md (Markdown; the only format)")->required()->check(CLI::IsMember({"md"}));
  if (const auto code = parse_args(app, args)) return *code;
  std::fputs(config::case_keys_markdown().c_str(), stdout);
  return 0;
}

}  // namespace capsim::cli
