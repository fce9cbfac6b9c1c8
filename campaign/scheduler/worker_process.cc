#include "campaign/scheduler/worker_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "solver/io/checkpoint.h"

namespace capsim::campaign {

namespace fs = std::filesystem;

std::string default_worker_executable() {
  if (const char* w = std::getenv("CAPSIM_WORKER"); w && *w) return w;
  std::error_code ec;
  auto p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot resolve /proc/self/exe: " + ec.message());
  return p.string();
}

std::vector<std::string> worker_args(const std::string& case_toml, const std::string& out_dir, int threads, bool resume) {
  std::vector<std::string> a = {"run", case_toml, "--out", out_dir, "--threads", std::to_string(threads)};
  if (resume) a.push_back("--resume");
  a.push_back("--json");
  return a;
}

pid_t spawn_worker(const WorkerCommand& cmd) {
  // Everything the child needs is prepared before fork (the child only calls async-signal-safe functions
  // plus setenv in a single-threaded copy).
  std::vector<std::string> all = {cmd.executable};
  all.insert(all.end(), cmd.args.begin(), cmd.args.end());
  std::vector<char*> argv;
  for (auto& s : all) argv.push_back(s.data());
  argv.push_back(nullptr);
  const std::string threads = std::to_string(cmd.threads);
  const pid_t parent = getpid();
  pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("fork failed: ") + std::strerror(errno));
  if (pid == 0) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(125);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    signal(SIGPIPE, SIG_DFL);
    int out = open(cmd.stdout_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int err = open(cmd.stderr_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    int in = open("/dev/null", O_RDONLY);
    if (out < 0 || err < 0 || in < 0) _exit(126);
    dup2(in, 0);
    dup2(out, 1);
    dup2(err, 2);
    setenv("OMP_NUM_THREADS", threads.c_str(), 1);
    execv(argv[0], argv.data());
    const char msg[] = "capsim campaign: cannot execute worker\n";
    (void)!write(2, msg, sizeof msg - 1);
    _exit(127);
  }
  setpgid(pid, pid);  // also from the parent, so signalling the group never races the child's setpgid
  return pid;
}

std::vector<pid_t> find_orphan_workers(const std::string& runs_dir, const std::set<std::string>& only_dirs) {
  std::vector<pid_t> out;
  const std::string prefix = fs::weakly_canonical(runs_dir).string() + "/";
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc", ec)) {
    const std::string name = e.path().filename().string();
    if (name.empty() || !std::all_of(name.begin(), name.end(), ::isdigit)) continue;
    pid_t pid = static_cast<pid_t>(std::stol(name));
    if (pid == getpid()) continue;
    std::ifstream cf(e.path() / "cmdline", std::ios::binary);
    std::string raw((std::istreambuf_iterator<char>(cf)), std::istreambuf_iterator<char>());
    std::vector<std::string> args;
    std::string cur;
    for (char c : raw) {
      if (c == '\0') {
        args.push_back(cur);
        cur.clear();
      } else {
        cur.push_back(c);
      }
    }
    bool match = false;
    for (std::size_t i = 0; i + 1 < args.size(); ++i)
      if (args[i] == "--out" && args[i + 1].rfind(prefix, 0) == 0 &&
          (only_dirs.empty() || only_dirs.count(args[i + 1]) ||
           only_dirs.count(fs::weakly_canonical(args[i + 1], ec).string())))
        match = true;
    if (!match) continue;
    std::ifstream sf(e.path() / "stat");
    std::string stat_line;
    std::getline(sf, stat_line);
    auto rp = stat_line.rfind(')');
    if (rp != std::string::npos && rp + 2 < stat_line.size() && stat_line[rp + 2] == 'Z') continue;
    out.push_back(pid);
  }
  return out;
}

namespace {
bool alive(pid_t pid) {
  if (kill(pid, 0) != 0) return false;
  std::ifstream sf("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  std::getline(sf, line);
  auto rp = line.rfind(')');
  return !(rp != std::string::npos && rp + 2 < line.size() && line[rp + 2] == 'Z');
}
}  // namespace

void stop_processes(const std::vector<pid_t>& pids, double grace_s) {
  for (pid_t p : pids) kill(p, SIGTERM);
  auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(grace_s);
  while (std::chrono::steady_clock::now() < deadline) {
    if (std::none_of(pids.begin(), pids.end(), alive)) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  for (pid_t p : pids)
    if (alive(p)) kill(p, SIGKILL);
  for (int i = 0; i < 40 && std::any_of(pids.begin(), pids.end(), alive); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

std::string last_line_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") != std::string::npos) last = line;
  }
  return last;
}

std::string tail_of(const std::string& path, std::size_t max_chars) {
  std::ifstream in(path, std::ios::binary);
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (!all.empty() && (all.back() == '\n' || all.back() == ' ')) all.pop_back();
  if (all.size() > max_chars) all = "..." + all.substr(all.size() - max_chars);
  std::string out;
  for (char c : all) {
    if (c == '\n') out += " | ";
    else if (c != '\r') out.push_back(c);
  }
  return out;
}

bool has_checkpoint(const std::string& dir) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    std::string n = e.path().filename().string();
    std::transform(n.begin(), n.end(), n.begin(), ::tolower);
    if (n.find("checkpoint") != std::string::npos && e.is_regular_file(ec) && n.find(".tmp") == std::string::npos)
      return true;
  }
  return false;
}

double work_fraction_left(const std::string& dir, double t_end) {
  if (dir.empty() || !(t_end > 0)) return 1.0;
  const fs::path file = fs::path(dir) / io::kCheckpointFileName;
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return 1.0;
  try {
    return std::clamp(1.0 - io::read_checkpoint(file).time / t_end, 0.0, 1.0);
  } catch (const std::exception&) {
    return 1.0;  // unreadable: resuming fails and the case is started afresh (campaign status says so)
  }
}

}  // namespace capsim::campaign
