#pragma once
/// @file
/// @brief Helpers shared by the Slurm sources (not part of the campaign layer's interface).

#include <string>
#include <vector>

namespace capsim::campaign {

/// @brief What a program printed and how it ended.
struct ProgramOutput {
  int code = -1;    ///< exit code, 128+signal, -1 if it could not start
  std::string out;  ///< stdout
  std::string err;  ///< stderr, trailing blanks removed
};

/// @brief Runs a program (looked up in $PATH, no shell) with stdin from /dev/null.
ProgramOutput run_program(const std::vector<std::string>& argv);

/// @brief @p s quoted for a POSIX shell.
std::string shell_quote(const std::string& s);

}  // namespace capsim::campaign
