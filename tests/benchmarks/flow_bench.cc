// Cost of one flow evaluation against the number of nodes N (mesh levels 1..max), on 1 and 2 OpenMP threads,
// with the named phases and the overhead ratio of dynamics::bench_flow (the measurement behind
// `capsim bench flow`, solver/dynamics/flow_benchmark.h), and the exponent p of cost ∝ N^p fitted between
// successive levels. Times depend on the machine and its load: compare the columns of one run only.
//
// Usage: flow_bench [max_level (5)] [repetitions (auto)]. Prints markdown tables.
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "solver/dynamics/flow_benchmark.h"

int main(int argc, char** argv) {
  using capsim::dynamics::FlowBenchOptions;
  using capsim::dynamics::FlowBenchReport;
  const int max_level = argc > 1 ? std::atoi(argv[1]) : 5;
  const int repeat = argc > 2 ? std::atoi(argv[2]) : 0;
  std::vector<FlowBenchReport> reports[2];
  for (int level = 1; level <= max_level; ++level)
    for (int k = 0; k < 2; ++k) {
      omp_set_num_threads(k + 1);
      FlowBenchOptions o;
      o.scene.level = level;
      o.repeat = repeat;
      reports[k].push_back(capsim::dynamics::bench_flow(o));
      const auto& s = reports[k].back().scenes;
      std::fprintf(stderr, "level %d, %d thread(s): %.2f / %.2f ms\n", level, k + 1, s[0].evaluation_ms,
                   s[1].evaluation_ms);
    }
  std::printf("Kernel %s. ms per evaluation (median), and evaluation / bare regular sum over the same targets.\n\n",
              reports[0].front().isa.c_str());
  std::printf("| level | N | scene | 1 thread: ms (ratio) | 2 threads: ms (ratio) | t1 / (2 t2) | "
              "2 threads: membrane / load / layout / singular / near / volume ms | p (N^p from level − 1) |\n"
              "|---|---|---|---|---|---|---|---|\n");
  for (std::size_t l = 0; l < reports[0].size(); ++l)
    for (int sc = 0; sc < 2; ++sc) {
      const auto& a = reports[0][l].scenes[sc];
      const auto& b = reports[1][l].scenes[sc];
      char p[32] = "—";
      if (l > 0) {
        const auto& prev = reports[1][l - 1].scenes[sc];
        std::snprintf(p, sizeof p, "%.2f",
                      std::log(b.evaluation_ms / prev.evaluation_ms) / std::log(double(b.nodes) / prev.nodes));
      }
      std::printf("| %d | %d | %s | %.3f (%.2f) | %.3f (%.2f) | %.2f | %.2f / %.2f / %.2f / %.2f / %.2f / %.2f | %s |\n",
                  reports[0][l].level, a.nodes, a.name.c_str(), a.evaluation_ms, a.overhead_ratio, b.evaluation_ms,
                  b.overhead_ratio, a.evaluation_ms / (2.0 * b.evaluation_ms), b.membrane_ms, b.load_ms, b.layout_ms,
                  b.singular_ms, b.near_ms, b.volume_ms, p);
    }
  return 0;
}
