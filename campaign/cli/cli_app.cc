#include "campaign/cli/cli_app.h"

#include <cstdio>
#include <iostream>

#include "campaign/common/exit_codes.h"

namespace capsim::cli {

std::optional<int> parse_args(CLI::App& app, const std::vector<std::string>& args) {
  // CLI11 takes the arguments as a stack: last argument first.
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  try {
    app.parse(reversed);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);  // the help of the sub-command asked for, on stdout; exit code 0
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    const std::string name = app.get_name();
    std::fprintf(stderr, "%s: %s (see %s --help)\n", name.c_str(), e.what(), name.c_str());
    return kExitBadInput;
  }
  return std::nullopt;
}

CLI::Option* add_set_option(CLI::App& app, std::vector<std::string>& overrides) {
  // One value per --set: a container option would otherwise take every following word, the case file too.
  return app.add_option("--set", overrides, "override one case key: section.key=value (repeatable)")
      ->allow_extra_args(false);
}

CLI::Option* add_threads_option(CLI::App& app, int& threads) {
  return app.add_option("--threads", threads, "OpenMP threads (default: all cores)")->check(CLI::Range(0, 4096));
}

}  // namespace capsim::cli
