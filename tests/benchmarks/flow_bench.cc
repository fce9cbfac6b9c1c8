// Cost of one flow evaluation (membrane → load → boundary integral, solver/README.md §2–§3) against the number of
// nodes N (mesh levels 1–5), on 1 and 2 OpenMP threads, split into the named phases of CapsuleFlow; and the
// OpenMP efficiency t(1)/(2 t(2)). The capsule is a/b = 2, Skalak, Ca = 0.3, deformed so that the mirror
// symmetry does not apply (the general case; with symmetry the boundary integral costs about half).
//
// Usage: flow_bench [max_level (5)] [repetitions (auto)]. Prints a markdown table. Results depend on the
// load of the machine: compare the columns of one run, not runs of different days.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "solver/config/case_config.h"
#include "solver/dynamics/capsule_flow.h"

namespace {

using namespace capsim;

struct Timing {
  double total_ms, membrane_ms, load_ms, stokes_ms;
};

Timing time_evaluations(dynamics::CapsuleFlow& flow, const Eigen::Matrix3Xd& x, int reps) {
  Eigen::Matrix3Xd v;
  flow.velocity(x, v);  // warm-up: first-touch allocation
  const dynamics::FlowTimings before = flow.timings();
  std::vector<double> totals;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    flow.velocity(x, v);
    totals.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(totals.begin(), totals.end());
  const dynamics::FlowTimings& after = flow.timings();
  const double n = reps;
  return {totals[totals.size() / 2], 1e3 * (after.membrane_s - before.membrane_s) / n,
          1e3 * (after.load_s - before.load_s) / n, 1e3 * (after.stokes_s - before.stokes_s) / n};
}

}  // namespace

int main(int argc, char** argv) {
  const int max_level = argc > 1 ? std::atoi(argv[1]) : 5;
  const int forced_reps = argc > 2 ? std::atoi(argv[2]) : 0;
  std::printf("| level | nodes N | 1 thread: ms / eval (membrane / load / BI) | 2 threads: ms / eval (membrane / load / BI) | "
              "efficiency t1/(2 t2) | ms/eval ÷ N² (ns, 2 threads) |\n|---|---|---|---|---|---|\n");
  for (int level = 1; level <= max_level; ++level) {
    config::CaseConfig c;
    c.aspect_ratio = 2.0;
    c.law = "skalak";
    c.capillary_number = 0.3;
    c.level = level;
    dynamics::CapsuleFlow flow(c);
    Eigen::Matrix3Xd x = flow.reference();
    for (int i = 0; i < x.cols(); ++i) {  // a smooth, non-symmetric deformation
      const double x1 = x(0, i), x2 = x(1, i), x3 = x(2, i);
      x(0, i) = x1 * (1.0 + 0.08 * std::sin(1.3 * x2 + 0.4 * x3));
      x(1, i) = x2 + 0.05 * std::cos(x1) + 0.03 * x3;
      x(2, i) = x3 * (1.0 - 0.04 * x1);
    }
    const int reps = forced_reps > 0 ? forced_reps : std::max(3, 400 >> (2 * level));
    Timing t[2];
    for (int k = 0; k < 2; ++k) {
      omp_set_num_threads(k + 1);
      t[k] = time_evaluations(flow, x, reps);
    }
    const double N = flow.mesh().num_nodes();
    std::printf("| %d | %.0f | %.2f (%.2f / %.2f / %.2f) | %.2f (%.2f / %.2f / %.2f) | %.2f | %.3f |\n", level, N,
                t[0].total_ms, t[0].membrane_ms, t[0].load_ms, t[0].stokes_ms, t[1].total_ms, t[1].membrane_ms,
                t[1].load_ms, t[1].stokes_ms, t[0].total_ms / (2.0 * t[1].total_ms), 1e6 * t[1].total_ms / (N * N));
    std::fflush(stdout);
  }
  return 0;
}
