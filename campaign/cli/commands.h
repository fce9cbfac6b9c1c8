#pragma once
/// @file
/// @brief Sub-commands of the `capsim` executable. Each takes the arguments after its own name and
/// returns the process exit code: 0 success, 1 a run that ended badly (e.g. interrupted), 2 bad input
/// (one clear message on stderr, nothing stored is changed).

#include <string>
#include <vector>

namespace capsim::cli {

/// @brief Exit code for bad input (unknown key, wrong type, out-of-range value, missing/corrupt file).
inline constexpr int kExitBadInput = 2;

/// @brief `capsim run CASE.toml [--set key=value]... [--out DIR] [--threads N] [--resume] [--json]`.
int run_command(const std::vector<std::string>& args);

/// @brief `capsim campaign run|status|...`.
int campaign_command(const std::vector<std::string>& args);

/// @brief `capsim query table1|cases|sql ... --db FILE [--format md|csv|json]`.
int query_command(const std::vector<std::string>& args);

/// @brief `capsim keys --format md`: the case-key table of schemas/case_keys.md, from the registry.
int keys_command(const std::vector<std::string>& args);

/// @brief `capsim bench kernel [--json]`.
int bench_command(const std::vector<std::string>& args);

}  // namespace capsim::cli
