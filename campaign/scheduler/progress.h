#pragma once
/// @file
/// @brief The campaign progress display on stderr: a redrawn line on a terminal, a plain log otherwise.

#include <chrono>
#include <string>

namespace capsim::campaign {

/// @brief Counts shown by the progress display.
struct ProgressCounts {
  int total = 0;      ///< cases in the campaign
  int finished = 0;   ///< done or unstable (including before this run)
  int failed = 0;     ///< failed
  int running = 0;    ///< workers alive
  int queued = 0;     ///< waiting to start
  double eta_s = -1;  ///< estimated seconds to go (< 0 unknown)
};

/// @brief Progress line "[name] 12/40 done, 2 running, 1 failed, 25 queued, ETA 3m20s".
class Progress {
 public:
  /// @brief @p name labels the lines; detects whether stderr is a terminal.
  explicit Progress(std::string name);
  /// @brief Shows the counts: redraws on a terminal (at most 10/s), logs a line on change or every 30 s
  /// otherwise. @p force always prints.
  void show(const ProgressCounts& c, bool force = false);
  /// @brief Prints a message on its own line (keeps the bar intact on a terminal).
  void message(const std::string& text);
  /// @brief Ends the redrawn line.
  void finish();

 private:
  std::string format(const ProgressCounts& c) const;
  std::string name_;
  bool tty_;
  bool drawn_ = false;
  std::string last_;
  std::chrono::steady_clock::time_point last_time_{};
};

/// @brief "1h02m", "3m20s", "12s".
std::string format_duration(double seconds);

}  // namespace capsim::campaign
