#pragma once
/// @file
/// @brief The error type for bad user input (campaign file, database file, command-line values).

#include <stdexcept>
#include <string>

namespace capsim::campaign {

/// @brief Bad input: the command prints what() as its one message and exits with code 2, having changed
/// nothing stored. Messages name the file and the key ("FILE: [grid][2].law: unknown law 'x'").
class BadInput : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// @brief @p text with line breaks folded to "; " (error messages are one line).
inline std::string one_line(std::string text) {
  std::string out;
  for (char c : text) {
    if (c == '\n') {
      if (!out.empty() && out.back() != ' ') out += "; ";
    } else if (c != '\r') {
      out.push_back(c);
    }
  }
  while (!out.empty() && (out.back() == ' ' || out.back() == ';')) out.pop_back();
  return out;
}

}  // namespace capsim::campaign
