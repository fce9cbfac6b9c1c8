// `capsim bench kernel [--json] [--threads N] [--repeat R]`: the Stokeslet kernel on a level-3-sized problem
// (2562 targets × all regular quadrature points of the level-3 sphere), fast kernel against the plain
// `omp simd` loop, so users can check a new machine (issue 6 §1).
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "campaign/cli/commands.h"
#include "solver/stokes/kernel_problem.h"
#include "solver/stokes/stokeslet.h"

namespace capsim::cli {
namespace {

namespace sk = capsim::stokes::kernel;

void usage_error(const std::string& msg) {
  std::fprintf(stderr, "capsim bench: %s (usage: capsim bench kernel [--json] [--threads N] [--repeat R])\n",
               msg.c_str());
}

bool parse_positive_int(const std::string& s, int& out) {
  try {
    std::size_t pos = 0;
    const long v = std::stol(s, &pos);
    if (pos != s.size() || v < 1 || v > 1000000) return false;
    out = static_cast<int>(v);
    return true;
  } catch (...) {
    return false;
  }
}

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

}  // namespace

int bench_command(const std::vector<std::string>& args) {
  if (args.empty() || args[0] != "kernel") {
    usage_error(args.empty() ? "missing benchmark name" : "unknown benchmark '" + args[0] + "'");
    return kExitBadInput;
  }
  bool json = false;
  int threads = 0, repeat = 20;
  for (std::size_t k = 1; k < args.size(); ++k) {
    const std::string& a = args[k];
    if (a == "--json") {
      json = true;
    } else if (a == "--threads" || a == "--repeat") {
      if (k + 1 >= args.size()) {
        usage_error(a + " needs a value");
        return kExitBadInput;
      }
      int v = 0;
      if (!parse_positive_int(args[k + 1], v)) {
        usage_error(a + " must be a positive integer, got '" + args[k + 1] + "'");
        return kExitBadInput;
      }
      (a == "--threads" ? threads : repeat) = v;
      ++k;
    } else {
      usage_error("unknown option '" + a + "'");
      return kExitBadInput;
    }
  }
  if (threads > 0) omp_set_num_threads(threads);
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
  std::printf("default fast kernel: %.3e interactions/s = %.2fx plain; max rel error %.2e\n", fast_rate,
              fast_rate / plain_rate, fast_err);
  if (json) {
    const nlohmann::json j = {{"interactions_per_s", fast_rate},
                              {"plain_interactions_per_s", plain_rate},
                              {"max_rel_error", fast_err},
                              {"threads", nthreads},
                              {"isa", sk::kernel_isa()}};
    std::printf("%s\n", j.dump().c_str());
  }
  return fast_err <= 1e-12 ? 0 : 1;
}

}  // namespace capsim::cli
