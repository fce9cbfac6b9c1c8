#pragma once
/// @file
/// @brief Sub-commands of the `capsim` executable. Each takes the arguments after its own name and
/// returns the process exit code, one of those of campaign/common/exit_codes.h.

#include <string>
#include <vector>

#include "campaign/common/exit_codes.h"

namespace capsim::cli {

/// @brief `capsim run CASE.toml [--set key=value]... [--out DIR] [--threads N] [--resume] [--json]`.
int run_command(const std::vector<std::string>& args);

/// @brief `capsim _summary key=value...` (hidden; for test workers): the case summary
/// (solver/driver/case_summary.h) with the given fields, printed as `capsim run --json` prints it, so a
/// stand-in worker reports through the same code as the real one. Values that parse as JSON (numbers,
/// true/false, null) are taken as such, others as strings. Exit 2 if a required field is missing.
int summary_command(const std::vector<std::string>& args);

/// @brief `capsim campaign run|status|...`.
int campaign_command(const std::vector<std::string>& args);

/// @brief `capsim query table1|cases|transitions|sql ... --db FILE [--format md|csv|json]`.
int query_command(const std::vector<std::string>& args);

/// @brief `capsim keys --format md`: the case-key table of schemas/case_keys.md, from the registry.
int keys_command(const std::vector<std::string>& args);

/// @brief `capsim bench kernel|flow [--json] [--threads N] [--repeat R]`; flow also takes `--set key=value`.
int bench_command(const std::vector<std::string>& args);

}  // namespace capsim::cli
