// `capsim run`: one case from a TOML file, with overrides, progress on stderr and a JSON summary line.
#include <omp.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "campaign/cli/cli_app.h"
#include "campaign/cli/commands.h"
#include "capsim/version.h"
#include "solver/config/case_config.h"
#include "solver/driver/case_driver.h"
#include "solver/driver/case_summary.h"
#include "solver/io/io_error.h"

namespace capsim::cli {
namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_stop_signal(int) { g_stop.store(true); }

}  // namespace

int run_command(const std::vector<std::string>& args) {
  CLI::App app{"Run one capsule case", "capsim run"};
  std::string case_file;
  std::vector<std::string> overrides;
  std::string out_dir = "capsim-run";
  int threads = 0;
  bool resume = false, json = false, quiet = false;
  app.add_option("case", case_file, "case file (TOML); '-' or an empty file = all defaults")->required();
  add_set_option(app, overrides);
  app.add_option("--out", out_dir, "output directory (case.h5, case.xmf, checkpoint.h5)");
  add_threads_option(app, threads);
  app.add_flag("--resume", resume, "continue from OUT/checkpoint.h5 if present");
  app.add_flag("--json", json, "print a JSON summary as the last stdout line");
  app.add_flag("--quiet", quiet, "no configuration echo or progress on stderr");
  long stop_after = 0;
  app.add_option("--stop-after", stop_after,
                 "checkpoint and stop (exit 3) after this many steps of this invocation, as if interrupted")
      ->check(CLI::NonNegativeNumber);
  if (const auto code = parse_args(app, args)) return *code;

  config::CaseConfig config;
  try {
    if (case_file == "-")
      config = config::parse_case_config("", "defaults", overrides);
    else
      config = config::load_case_config(case_file, overrides);
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "capsim run: %s\n", e.what());
    return kExitBadInput;
  }
  if (threads > 0) omp_set_num_threads(threads);
  if (!quiet) {
    std::fprintf(stderr, "# capsim %s (commit %s), %d threads\n# effective configuration:\n", kVersion, kGitCommit,
                 omp_get_max_threads());
    std::string toml = config.to_toml();
    std::fprintf(stderr, "%s\n", toml.c_str());
  }

  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
  driver::RunOptions opt;
  opt.out_dir = out_dir;
  opt.resume = resume;
  opt.stop_requested = &g_stop;
  opt.stop_after_steps = stop_after;
  if (!quiet)
    opt.progress = [](const driver::Progress& p) {
      std::fprintf(stderr, "t = %8.3f / %g  step %7ld  D12 = %.4f  tau_min = %+.4f  wall %.0f s\n", p.t, p.t_end,
                   p.step, p.D12, p.tau_min, p.wall_s);
    };

  driver::CaseResult r;
  try {
    r = driver::run_case(config, opt);
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "capsim run: %s\n", e.what());
    return kExitBadInput;
  } catch (const io::IoError& e) {
    std::fprintf(stderr, "capsim run: cannot write the output: %s\n", e.what());
    return kExitWriteFailed;
  }

  const auto& a = r.analysis;
  if (!quiet) {
    std::fprintf(stderr, "# %s%s%s after %ld steps (t = %.3f, dt = %.3e, %ld flow evaluations, %.1f s)\n",
                 r.status.c_str(), r.reason.empty() ? "" : ": ", r.reason.c_str(), r.steps, r.t_final, r.dt,
                 r.flow_evaluations, r.wall_s);
    std::fprintf(stderr, "# regime %s  period %.4g  min_D12 %.5f  max_tau_min %+.5f  mean_D12 %.5f  volume drift %.2e\n",
                 std::string(diagnostics::to_string(a.regime)).c_str(), a.period, a.min_D12, a.max_tau_min,
                 a.mean_D12, r.volume_drift);
    if (config.tilt != 0.0 || r.final_tilt != 0.0)  // a case off the plane (an in-plane one prints as before)
      std::fprintf(stderr,
                   "# orientation: started at tilt %.4g deg, azimuth %.4g deg; final tilt %.4g deg, tilt growth rate "
                   "%+.4g +- %.2g per unit shear time; membrane spin about the axis %+.4g rad per unit shear time\n",
                   config.tilt, config.azimuth, r.final_tilt, r.tilt_growth_rate, r.tilt_growth_rate_error,
                   r.final_spin_rate);
    std::fprintf(stderr, "# phases: membrane %.1f s, load %.1f s, boundary integral %.1f s\n", r.membrane_s, r.load_s,
                 r.stokes_s);
    std::fprintf(stderr,
                 "# wrinkle indicators (final / largest sampled): compressed area %.3f / %.3f, q.n roughness %.3f / "
                 "%.3f; wrinkle wavelength (final / most wrinkled sample) %.3g / %.3g at relief %.2g / %.2g\n",
                 r.wrinkle_final.compressed_area_fraction, r.wrinkle_max.compressed_area_fraction,
                 r.wrinkle_final.load_roughness, r.wrinkle_max.load_roughness, r.wrinkle_final.wrinkle_wavelength,
                 r.wrinkle_max.wrinkle_wavelength, r.wrinkle_final.wrinkle_amplitude, r.wrinkle_max.wrinkle_amplitude);
  }
  if (json) {
    const nlohmann::json j = driver::CaseSummary::of(config, r).to_json();
    std::printf("%s\n", j.dump().c_str());
    std::fflush(stdout);
  }
  return r.status == "interrupted" ? kExitInterrupted : kExitOutcome;
}

int summary_command(const std::vector<std::string>& args) {
  CLI::App app{"The case summary of `capsim run --json` with the given fields (for stand-in test workers)",
               "capsim _summary"};
  std::vector<std::string> items;
  app.add_option("fields", items, "key=value (a value that parses as a JSON number, true/false or null is one)");
  if (const auto code = parse_args(app, args)) return *code;
  nlohmann::json fields = nlohmann::json::object();
  for (const auto& arg : items) {
    const auto eq = arg.find('=');
    if (eq == std::string::npos || eq == 0) {
      std::fprintf(stderr, "capsim _summary: expected key=value, got '%s'\n", arg.c_str());
      return kExitBadInput;
    }
    const std::string key = arg.substr(0, eq), value = arg.substr(eq + 1);
    auto parsed = nlohmann::json::parse(value, nullptr, /*allow_exceptions=*/false);
    fields[key] = parsed.is_discarded() || parsed.is_string() || parsed.is_structured() ? nlohmann::json(value) : parsed;
  }
  try {
    std::printf("%s\n", driver::CaseSummary::from_json(fields).to_json().dump().c_str());
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "capsim _summary: %s\n", e.what());
    return kExitBadInput;
  }
  return kExitOutcome;
}

}  // namespace capsim::cli
