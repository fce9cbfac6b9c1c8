// `capsim bench kernel [--json] [--threads N] [--repeat R]`: the Stokeslet kernel on a level-3-sized problem
// (2562 targets × all regular quadrature points of the level-3 sphere), fast kernel against the plain
// `omp simd` loop, so users can check a new machine.
// `capsim bench flow [--set KEY=VALUE]... [--level L] [--bending KB] [--precision double|mixed] [--json]
// [--threads N] [--repeat R]`: one flow evaluation by named phase against the bare regular Stokeslet sum in the
// same run (solver/dynamics/flow_benchmark.h); with numerics.kernel_precision = mixed also against the double
// evaluation. The scene is a case: any case key reaches it through --set; --level, --bending and --precision
// are shorthands for three of them.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "campaign/cli/cli_app.h"
#include "campaign/cli/commands.h"
#include "solver/config/case_config.h"
#include "solver/dynamics/flow_benchmark.h"
#include "solver/stokes/kernel_problem.h"
#include "solver/stokes/stokeslet.h"

namespace capsim::cli {
namespace {

namespace sk = capsim::stokes::kernel;

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Best-of timing: run f `repeat` times (after one warm-up), return the shortest wall time.
template <class F>
double best_time(F&& f, int repeat) {
  f();
  double best = 1e300;
  for (int r = 0; r < repeat; ++r) {
    const double t0 = now_s();
    f();
    best = std::min(best, now_s() - t0);
  }
  return best;
}

// max over targets of |u − ref| / |ref|.
double max_rel_error(const std::vector<double>& ux, const std::vector<double>& uy, const std::vector<double>& uz,
                     const std::vector<double>& rx, const std::vector<double>& ry, const std::vector<double>& rz) {
  double e = 0.0;
  for (std::size_t i = 0; i < rx.size(); ++i) {
    const double d = std::hypot(ux[i] - rx[i], uy[i] - ry[i], uz[i] - rz[i]);
    const double n = std::hypot(rx[i], ry[i], rz[i]);
    e = std::max(e, d / n);
    if (std::isnan(d)) return d;
  }
  return e;
}

// The options of both benchmarks; the scene's keys only for `flow`.
struct BenchArgs {
  bool json = false;
  int threads = 0, repeat = 0;
  std::vector<std::string> overrides;  ///< shorthands and --set, in this order (a later one wins)
};
int bench_flow(const BenchArgs& ba) {
  capsim::dynamics::FlowBenchOptions opt;
  opt.repeat = ba.repeat;
  try {
    opt.scene = capsim::dynamics::FlowBenchOptions::scene_with(ba.overrides);
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "capsim bench flow: %s\n", e.what());
    return kExitBadInput;
  }
  if (std::string why; !opt.valid(&why)) {
    std::fprintf(stderr, "capsim bench flow: %s\n", why.c_str());
    return kExitBadInput;
  }
  const config::CaseConfig& scene = opt.scene;
  if (ba.threads > 0) omp_set_num_threads(ba.threads);
  const capsim::dynamics::FlowBenchReport r = capsim::dynamics::bench_flow(opt);
  if (ba.json) {
    nlohmann::json scenes = nlohmann::json::array();
    for (const auto& s : r.scenes)
      scenes.push_back({{"scene", s.name},
                        {"nodes", s.nodes},
                        {"targets", s.targets},
                        {"sources", s.sources},
                        {"used_symmetry", s.used_symmetry},
                        {"used_central", s.used_central},
                        {"repeat", s.repeat},
                        {"evaluation_ms", s.evaluation_ms},
                        {"evaluation_double_ms", s.evaluation_double_ms},
                        {"regular_sum_ms", s.regular_sum_ms},
                        {"overhead_ratio", s.overhead_ratio},
                        {"membrane_ms", s.membrane_ms},
                        {"bending_ms", s.bending_ms},
                        {"load_ms", s.load_ms},
                        {"layout_ms", s.layout_ms},
                        {"regular_ms", s.regular_ms},
                        {"far_ms", s.far_ms},
                        {"singular_ms", s.singular_ms},
                        {"near_ms", s.near_ms},
                        {"volume_ms", s.volume_ms},
                        {"second_kind_ms", s.second_kind_ms},
                        {"gmres_iterations", s.gmres_iterations},
                        {"layer_applications", s.layer_applications},
                        {"layer_prepare_ms", s.layer_prepare_ms},
                        {"layer_layout_ms", s.layer_layout_ms},
                        {"layer_regular_ms", s.layer_regular_ms},
                        {"layer_singular_ms", s.layer_singular_ms},
                        {"layer_near_ms", s.layer_near_ms},
                        {"deflation_setup_ms", s.deflation_setup_ms},
                        {"gmres_other_ms", s.gmres_other_ms},
                        {"evaluation_warm_ms", s.evaluation_warm_ms},
                        {"gmres_iterations_warm", s.gmres_iterations_warm},
                        {"evaluation_equal_viscosity_ms", s.evaluation_equal_viscosity_ms},
                        {"other_ms", s.other_ms}});
    // The symmetric scene's fields also at the top level: the scene of every run that starts in the shear plane.
    const auto& sym = r.scenes.front();
    const nlohmann::json j = {{"level", r.level},
                              {"nodes", sym.nodes},
                              {"threads", r.threads},
                              {"kernel_isa", r.isa},
                              {"kernel_precision", scene.kernel_precision},
                              {"overrides", ba.overrides},
                              {"evaluation_ms", sym.evaluation_ms},
                              {"evaluation_double_ms", sym.evaluation_double_ms},
                              {"regular_sum_ms", sym.regular_sum_ms},
                              {"overhead_ratio", sym.overhead_ratio},
                              {"scenes", scenes}};
    std::printf("%s\n", j.dump().c_str());
    return 0;
  }
  std::printf("Flow evaluation, level %d (%d nodes), a/b = %g %s Ca = %g deformed, bending modulus %g, %d "
              "thread(s), kernel %s\n",
              r.level, r.scenes.front().nodes, scene.aspect_ratio, std::string(config::word_of(scene.law)).c_str(), scene.capillary_number,
              scene.bending_modulus, r.threads, r.isa.c_str());
  std::printf("%-10s %7s %9s %9s %8s | %8s %8s %8s %8s %8s %8s %8s %8s %8s %8s\n", "scene", "targets", "eval ms",
              "bare ms", "ratio", "membrane", "bending", "load", "layout", "regular", "far", "singular", "near",
              "volume", "other");
  for (const auto& s : r.scenes)
    std::printf("%-10s %7d %9.3f %9.3f %8.3f | %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f\n",
                s.name.c_str(), s.targets, s.evaluation_ms, s.regular_sum_ms, s.overhead_ratio, s.membrane_ms,
                s.bending_ms, s.load_ms, s.layout_ms, s.regular_ms, s.far_ms, s.singular_ms, s.near_ms, s.volume_ms,
                s.other_ms);
  std::printf("ratio = evaluation / bare regular sum (double) over the same targets and sources (medians of %d, "
              "alternated); phases are means per evaluation in ms\n",
              r.scenes.front().repeat);
  if (scene.viscosity_ratio != 1.0) {
    std::printf("viscosity ratio %g: the second-kind solve by phase, ms per evaluation (every timed solve cold)\n",
                scene.viscosity_ratio);
    std::printf("%-10s %9s %9s %7s %7s %6s | %8s %8s %8s %8s %8s %8s %8s %8s\n", "scene", "eval ms", "lambda=1",
                "ratio", "iters", "apps", "solve", "D prep", "D layout", "D regul", "D corr", "D rest", "setup",
                "gmres");
    for (const auto& s : r.scenes)
      std::printf("%-10s %9.3f %9.3f %7.2f %7.2f %6.2f | %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f\n",
                  s.name.c_str(), s.evaluation_ms, s.evaluation_equal_viscosity_ms,
                  s.evaluation_equal_viscosity_ms > 0.0 ? s.evaluation_ms / s.evaluation_equal_viscosity_ms : 0.0,
                  s.gmres_iterations, s.layer_applications, s.second_kind_ms, s.layer_prepare_ms, s.layer_layout_ms,
                  s.layer_regular_ms,
                  s.layer_singular_ms, s.layer_near_ms, s.deflation_setup_ms, s.gmres_other_ms);
    for (const auto& s : r.scenes)
      std::printf("%s: second stage (x + dt v, warm-started from the first): %.3f ms, %.2f iterations, %.2fx lambda = 1\n",
                  s.name.c_str(), s.evaluation_warm_ms, s.gmres_iterations_warm,
                  s.evaluation_equal_viscosity_ms > 0.0 ? s.evaluation_warm_ms / s.evaluation_equal_viscosity_ms : 0.0);
    std::printf("ratio = evaluation / the same scene at lambda = 1 (medians, alternated in this run)\n");
  }
  if (scene.kernel_precision != "double")
    for (const auto& s : r.scenes)
      std::printf("%s: %s evaluation %.3f ms, double %.3f ms (alternated in this run): %.2fx faster\n", s.name.c_str(),
                  scene.kernel_precision.c_str(), s.evaluation_ms, s.evaluation_double_ms,
                  s.evaluation_double_ms / s.evaluation_ms);
  return 0;
}

int bench_kernel(const BenchArgs& ba) {
  const bool json = ba.json;
  const int repeat = ba.repeat > 0 ? ba.repeat : 20;
  if (ba.threads > 0) omp_set_num_threads(ba.threads);
  const int nthreads = omp_get_max_threads();

  // The level-3 problem (built inside the solver library; only std::vector storage crosses over).
  const capsim::stokes::KernelProblem prob = capsim::stokes::make_kernel_problem(3);
  const sk::Targets tg = prob.targets();
  const sk::Sources src = prob.sources();
  const int nt = prob.num_targets();
  const int ns = prob.num_sources;  // padding carries zero load: not counted as interactions
  const double interactions = prob.interactions();

  std::vector<double> px(nt), py(nt), pz(nt), fx(nt), fy(nt), fz(nt);
  const double t_plain = best_time([&] { sk::sum_plain(tg, src, {px.data(), py.data(), pz.data()}); }, repeat);
  const double plain_rate = interactions / t_plain;

  std::printf("Stokeslet kernel: %d targets x %d sources (level-3 sphere), %d thread(s), ISA %s, best of %d\n", nt,
              ns, nthreads, sk::kernel_isa(), repeat);
  std::printf("%-22s %10s %14s %9s %12s\n", "kernel", "time [ms]", "interactions/s", "speedup", "max rel err");
  std::printf("%-22s %10.3f %14.3e %9.2f %12s\n", "plain omp simd", 1e3 * t_plain, plain_rate, 1.0, "(reference)");

  struct Variant {
    std::string name;
    sk::FastConfig cfg;
  };
  std::vector<Variant> variants;
  for (int b = 1; b <= 4; ++b) {
    variants.push_back({"fast rsqrt+Newton B=" + std::to_string(b), {b, sk::InvSqrt::Newton}});
    variants.push_back({"fast sqrt+div    B=" + std::to_string(b), {b, sk::InvSqrt::SqrtDiv}});
    if (b >= 2) variants.push_back({"fast hybrid      B=" + std::to_string(b), {b, sk::InvSqrt::Hybrid}});
  }
  const sk::FastConfig def{};
  double fast_rate = 0.0, fast_err = 0.0;
  for (const auto& v : variants) {
    const double t = best_time([&] { sk::sum_fast(tg, src, {fx.data(), fy.data(), fz.data()}, v.cfg); }, repeat);
    const double err = max_rel_error(fx, fy, fz, px, py, pz);
    const bool is_default = v.cfg.block == def.block && v.cfg.inv_sqrt == def.inv_sqrt;
    std::printf("%-22s %10.3f %14.3e %9.2f %12.2e%s\n", v.name.c_str(), 1e3 * t, interactions / t,
                t_plain / t, err, is_default ? "  (default)" : "");
    if (is_default) {
      fast_rate = interactions / t;
      fast_err = err;
    }
  }
  // Mixed precision (numerics.kernel_precision = "mixed"): float pair terms, double sums.
  const double t_mixed = best_time([&] { sk::sum_mixed(tg, src, {fx.data(), fy.data(), fz.data()}); }, repeat);
  const double mixed_err = max_rel_error(fx, fy, fz, px, py, pz);
  std::printf("%-22s %10.3f %14.3e %9.2f %12.2e  (numerics.kernel_precision = mixed, %s)\n", "mixed float/double",
              1e3 * t_mixed, interactions / t_mixed, t_plain / t_mixed, mixed_err, sk::mixed_kernel_isa());
  // The 8-lane tile, which sum_mixed replaces on an AVX-512 build (elsewhere it is sum_mixed itself).
  const double t_mixed8 = best_time([&] { sk::sum_mixed_8_lanes(tg, src, {fx.data(), fy.data(), fz.data()}); }, repeat);
  const double mixed8_err = max_rel_error(fx, fy, fz, px, py, pz);
  std::printf("%-22s %10.3f %14.3e %9.2f %12.2e  (the 8-lane tile)\n", "mixed, 8 lanes", 1e3 * t_mixed8,
              interactions / t_mixed8, t_plain / t_mixed8, mixed8_err);
  std::printf("default fast kernel: %.3e interactions/s = %.2fx plain; max rel error %.2e; mixed %.2fx the default "
              "(%.2fx the 8-lane tile)\n",
              fast_rate, fast_rate / plain_rate, fast_err, interactions / t_mixed / fast_rate, t_mixed8 / t_mixed);
  if (json) {
    const nlohmann::json j = {{"interactions_per_s", fast_rate},
                              {"plain_interactions_per_s", plain_rate},
                              {"max_rel_error", fast_err},
                              {"mixed_interactions_per_s", interactions / t_mixed},
                              {"mixed_max_rel_error", mixed_err},
                              {"mixed_8_lanes_interactions_per_s", interactions / t_mixed8},
                              {"mixed_kernel_isa", sk::mixed_kernel_isa()},
                              {"threads", nthreads},
                              {"kernel_isa", sk::kernel_isa()}};
    std::printf("%s\n", j.dump().c_str());
  }
  return fast_err <= sk::kFastRelativeBound && mixed_err <= sk::kMixedRelativeBound &&
                 mixed8_err <= sk::kMixedRelativeBound
             ? 0
             : 1;  // the kernels' contracts
}

// Declares the options both benchmarks take.
void add_common_options(CLI::App& sub, BenchArgs& ba) {
  sub.add_flag("--json", ba.json, "print the measurement as one JSON line");
  add_threads_option(sub, ba.threads);
  sub.add_option("--repeat", ba.repeat, "timed repetitions (default: automatic)")->check(CLI::Range(1, 1000000));
}

}  // namespace

int bench_command(const std::vector<std::string>& args) {
  CLI::App app{"capsim bench: measure this machine", "capsim bench"};
  app.require_subcommand(1);
  BenchArgs ba;
  auto* kernel = app.add_subcommand(
      "kernel", "the Stokeslet kernel on the level-3 sphere: fast and mixed-precision sums against the plain loop");
  add_common_options(*kernel, ba);
  auto* flow = app.add_subcommand(
      "flow", "one flow evaluation by named phase against the bare regular Stokeslet sum, in three scenes "
              "(symmetric, general, central) of a capsule given by case keys");
  add_common_options(*flow, ba);
  // The shorthands are case keys: each becomes the override it names, checked by the key registry as --set is.
  auto shorthand = [&](const char* name, const char* key, const char* what) {
    flow->add_option_function<std::string>(
        name, [&ba, key](const std::string& v) { ba.overrides.push_back(std::string(key) + "=" + v); },
        std::string(what) + " (= --set " + key + "=VALUE)");
  };
  shorthand("--level", "mesh.level", "mesh level of the scene");
  shorthand("--bending", "capsule.bending_modulus", "bending modulus of the scene");
  shorthand("--precision", "numerics.kernel_precision", "double or mixed (mixed: also measured in double)");
  std::vector<std::string> sets;
  add_set_option(*flow, sets)->description("override one case key of the scene: section.key=value (repeatable; "
                                            "after the shorthands)");
  if (const auto code = parse_args(app, args)) return *code;
  if (*kernel) return bench_kernel(ba);
  ba.overrides.insert(ba.overrides.end(), sets.begin(), sets.end());
  return bench_flow(ba);
}

}  // namespace capsim::cli
