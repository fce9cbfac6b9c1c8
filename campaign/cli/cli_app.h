#pragma once
/// @file
/// @brief The one command-line grammar of the `capsim` sub-commands: each declares its options on a CLI11
/// app and parses through parse_args, so that every sub-command answers `--help` the same way and reports
/// bad input as one line with exit code 2 (campaign/common/exit_codes.h).

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace capsim::cli {

/// @brief Parses @p args (the arguments after the sub-command's name) into @p app.
/// @return std::nullopt when the command should go on; otherwise the exit code to return: 0 after printing
/// the help of the (sub-)command asked for on stdout (`--help`, `-h`), kExitBadInput after printing one line
/// "APP: what is wrong (see APP --help)" on stderr, APP being @p app's name (e.g. "capsim run").
std::optional<int> parse_args(CLI::App& app, const std::vector<std::string>& args);

/// @brief Declares `--set section.key=value` (repeatable, one key each) on @p app, collected into @p overrides in
/// the order given. They are parsed and range-checked by the case-key registry (config::parse_case_config), so every
/// case key reaches a command that takes --set without an option of its own.
CLI::Option* add_set_option(CLI::App& app, std::vector<std::string>& overrides);

/// @brief Declares `--threads N` (OpenMP threads; 0 or absent: all cores) on @p app.
CLI::Option* add_threads_option(CLI::App& app, int& threads);

}  // namespace capsim::cli
