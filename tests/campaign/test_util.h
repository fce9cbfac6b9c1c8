#pragma once
// Helpers of the campaign tests: temporary folders, running the capsim binary, file snapshots.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <sqlite3.h>

namespace capsim::campaign::testing {

namespace fs = std::filesystem;

/// The capsim binary under test; CAPSIM_TEST_EXE overrides the one built with the tests (to check that a new
/// test fails against an older binary, as every defect's test must).
inline std::string exe() {
  const char* e = std::getenv("CAPSIM_TEST_EXE");
  return e && *e ? e : CAPSIM_EXE_PATH;
}
inline std::string fake_worker() { return std::string(CAPSIM_SOURCE_DIR) + "/tests/campaign/fake_worker.sh"; }
/// The environment that makes the fake worker the campaign's worker (CAPSIM_WORKER) and hands it the capsim
/// binary under test (FAKE_CAPSIM, whose `_summary` prints its result line): explicitly, because the worker
/// may be started by slurmd, whose process tree holds no capsim, from a build folder anywhere.
inline std::string fake_worker_env() { return "FAKE_CAPSIM=" + exe() + " CAPSIM_WORKER=" + fake_worker(); }

/// A fresh folder per test under CAPSIM_TEST_TMP.
inline std::string fresh_dir(const std::string& name) {
  fs::path p = fs::path(CAPSIM_TEST_TMP) / "campaign" / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

inline std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline void write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

/// Every file under a folder with its contents: a snapshot to compare before and after.
inline std::map<std::string, std::string> folder_snapshot(const std::string& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out[e.path().string()] = read_file(e.path().string());
  return out;
}

struct CmdResult {
  int code = -1;
  std::string out, err;
};

/// Runs a shell command line; captures stdout and stderr.
inline CmdResult sh(const std::string& cmd) {
  static int counter = 0;
  const std::string base = std::string(CAPSIM_TEST_TMP) + "/campaign/sh_" + std::to_string(getpid()) + "_" +
                           std::to_string(counter++);
  fs::create_directories(std::string(CAPSIM_TEST_TMP) + "/campaign");
  const std::string full = "(" + cmd + ") >" + base + ".out 2>" + base + ".err";
  int st = std::system(full.c_str());
  CmdResult r;
  r.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  r.out = read_file(base + ".out");
  r.err = read_file(base + ".err");
  fs::remove(base + ".out");
  fs::remove(base + ".err");
  return r;
}

/// The rows of `capsim query sql Q --db DB --format csv`, without the header line; the query must succeed.
/// Runs SQL that writes on a database directly (what a test does to a database behind the manager's back).
inline void exec_sql(const std::string& db, const std::string& text) {
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &h), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(h, text.c_str(), nullptr, nullptr, nullptr), SQLITE_OK) << sqlite3_errmsg(h);
  sqlite3_close(h);
}

inline std::string sql(const std::string& db, const std::string& q) {
  auto r = sh(exe() + " query sql \"" + q + "\" --db " + db + " --format csv");
  EXPECT_EQ(r.code, 0) << q << ": " << r.err;
  auto nl = r.out.find('\n');
  return nl == std::string::npos ? "" : r.out.substr(nl + 1);
}

/// Starts a shell command in the background; returns the pid of the exec'd program.
inline pid_t spawn_sh(const std::string& cmd) {
  pid_t pid = fork();
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

/// Waits for a child up to @p timeout_s; returns its exit code, -signal if signalled, -1000 on timeout.
inline int wait_child(pid_t pid, double timeout_s) {
  auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < deadline) {
    int st = 0;
    pid_t r = waitpid(pid, &st, WNOHANG);
    if (r == pid) return WIFEXITED(st) ? WEXITSTATUS(st) : -WTERMSIG(st);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return -1000;
}

/// Waits up to @p timeout_s until @p n case folders under @p runs_dir hold the fake worker's checkpoint.txt
/// (it writes one after each step, so such a worker has installed its signal trap and is computing); returns
/// whether they do. Tests that signal a running campaign wait for this instead of sleeping a fixed time: on a
/// loaded machine a fixed sleep can end before the workers have started (a flaky failure seen under ctest -j2).
inline bool wait_for_checkpoints(const std::string& runs_dir, int n, double timeout_s) {
  auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < deadline) {
    int found = 0;
    std::error_code ec;
    if (fs::is_directory(runs_dir, ec))
      for (const auto& e : fs::directory_iterator(runs_dir, ec))
        if (fs::exists(e.path() / "checkpoint.txt", ec)) ++found;
    if (found >= n) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

/// The campaign file most fake-worker tests share: a prolate NH capsule on level 1 at Ca 0.1-0.4 (the fake
/// worker's truth there: a Ca* band at 0.2, CaH = 0.35), with @p axes added to the grid (e.g. a second axis)
/// and @p more appended (e.g. an [analysis] table).
inline std::string prolate_campaign(const std::string& name, const std::string& axes = "", const std::string& more = "") {
  return "[campaign]\nname = \"" + name + "\"\n[defaults]\nmesh.level = 1\n[[grid]]\naspect_ratio = [2.0]\n"
         "law = [\"neo-hookean\"]\n" + axes + "capillary_number = [0.1, 0.2, 0.3, 0.4]\n" + more;
}

/// A campaign command with the fake worker and extra environment.
inline std::string campaign_cmd(const std::string& env, const std::string& file, const std::string& db,
                                const std::string& extra = "") {
  return "env " + env + " " + fake_worker_env() + " " + exe() + " campaign run " + file + " --db " + db + " " + extra;
}

/// Number of non-empty lines.
inline int count_lines(const std::string& s) {
  int n = 0;
  std::istringstream in(s);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty()) ++n;
  return n;
}

}  // namespace capsim::campaign::testing
