#pragma once
/// @file
/// @brief The exit codes of the `capsim` executable, in one place. Every sub-command returns one of these;
/// the campaign manager reads a worker's (`capsim run`) code with describe_exit_code. README.md lists them.
///
///   0  a recorded outcome: `run` finished with status done or unstable (a blow-up is a result, not an error)
///   1  internal error: an unexpected exception (a bug or an unforeseen condition; stderr says what)
///   2  bad input: unknown key, wrong type, out-of-range value, missing or corrupt input file; one clear
///      message on stderr, nothing stored is changed
///   3  interrupted (SIGINT/SIGTERM or --stop-after) after writing the checkpoint; `--resume` continues
///   4  output could not be written (output folder not creatable, disk full, permissions); the input was
///      fine, so the same command succeeds once the output location is writable

#include <string>

namespace capsim {

inline constexpr int kExitOutcome = 0;
inline constexpr int kExitInternalError = 1;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitInterrupted = 3;
inline constexpr int kExitWriteFailed = 4;

/// @brief A short parenthesised description of a worker's exit code for error texts, e.g. " (bad input)";
/// "" for codes without a documented meaning.
inline std::string describe_exit_code(int code) {
  switch (code) {
    case kExitInternalError: return " (internal error)";
    case kExitBadInput: return " (bad input)";
    case kExitInterrupted: return " (interrupted, checkpoint written)";
    case kExitWriteFailed: return " (output could not be written: folder, disk space or permissions)";
    default: return "";
  }
}

}  // namespace capsim
