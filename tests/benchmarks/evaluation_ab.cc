// One flow evaluation timed with any build of the solver library, for before/after comparisons of the
// per-evaluation cost: scripts/bench-eval-ab compiles this file against two builds' solver
// libraries and runs them alternately. It uses only the API that existed before `capsim bench flow`
// (CapsuleFlow, SingleLayer::build_sources, kernel::sum_fast), so it compiles against older commits.
//
// Prints one JSON line per scene: evaluation_ms (median of CapsuleFlow::velocity) and regular_sum_ms (median
// of the bare kernel::sum_fast over the targets the scene evaluates and all regular sources, timed
// alternately with the evaluations).
//   evaluation_ab LEVEL REPEAT
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "solver/config/case_config.h"
#include "solver/dynamics/capsule_flow.h"
#include "solver/stokes/single_layer.h"

namespace {
double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
}  // namespace

int main(int argc, char** argv) {
  using namespace capsim;
  const int level = argc > 1 ? std::atoi(argv[1]) : 3;
  const int repeat = argc > 2 ? std::atoi(argv[2]) : 20;
  config::CaseConfig c;
  c.aspect_ratio = 2.0;
  c.law = config::MembraneLawKind::Skalak;
  c.capillary_number = 0.3;
  c.level = level;
  dynamics::CapsuleFlow flow(c);
  stokes::SingleLayer op(flow.mesh());  // for the bare sum's sources only
  for (const bool symmetric : {true, false}) {
    // The deformation of dynamics::bench_flow (solver/dynamics/flow_benchmark.cc).
    const Eigen::Matrix3Xd& ref = flow.reference();
    Eigen::Matrix3Xd x = ref;
    for (int i = 0; i < x.cols(); ++i) {
      const double x1 = ref(0, i), x2 = ref(1, i), x3 = ref(2, i);
      const double s3 = symmetric ? x3 * x3 : x3;
      x(0, i) = x1 * (1.0 + 0.08 * std::sin(1.3 * x2 + 0.4 * s3));
      x(1, i) = x2 + 0.05 * std::cos(x1) + 0.03 * s3;
      x(2, i) = x3 * (1.0 - 0.04 * x1);
    }
    Eigen::Matrix3Xd v, q;
    const dynamics::FlowEvaluation ev = flow.velocity(x, v, &q);
    std::vector<double> tx, ty, tz;
    for (int i = 0; i < x.cols(); ++i) {
      const int m = flow.mesh().mirror_node.empty() ? i : flow.mesh().mirror_node[i];
      const bool mine = !ev.used_symmetry || m == i || x(2, i) > x(2, m) || (x(2, i) == x(2, m) && i < m);
      if (!mine) continue;
      tx.push_back(x(0, i));
      ty.push_back(x(1, i));
      tz.push_back(x(2, i));
    }
    const stokes::kernel::Sources s0 = op.build_sources(x, q);
    std::vector<double> sx(s0.x, s0.x + s0.n), sy(s0.y, s0.y + s0.n), sz(s0.z, s0.z + s0.n), sqx(s0.qx, s0.qx + s0.n),
        sqy(s0.qy, s0.qy + s0.n), sqz(s0.qz, s0.qz + s0.n);
    const stokes::kernel::Sources src{sx.data(), sy.data(), sz.data(), sqx.data(), sqy.data(), sqz.data(), s0.n};
    const int nt = static_cast<int>(tx.size());
    std::vector<double> ux(nt), uy(nt), uz(nt);
    const stokes::kernel::Targets tg{tx.data(), ty.data(), tz.data(), nt};
    stokes::kernel::sum_fast(tg, src, {ux.data(), uy.data(), uz.data()});
    std::vector<double> te, tb;
    for (int r = 0; r < repeat; ++r) {
      double t0 = now_ms();
      flow.velocity(x, v);
      te.push_back(now_ms() - t0);
      t0 = now_ms();
      stokes::kernel::sum_fast(tg, src, {ux.data(), uy.data(), uz.data()});
      tb.push_back(now_ms() - t0);
    }
    std::printf("{\"scene\": \"%s\", \"level\": %d, \"nodes\": %d, \"targets\": %d, \"threads\": %d, "
                "\"used_symmetry\": %s, \"evaluation_ms\": %.4f, \"regular_sum_ms\": %.4f}\n",
                symmetric ? "symmetric" : "general", level, static_cast<int>(x.cols()), nt, omp_get_max_threads(),
                ev.used_symmetry ? "true" : "false", median(te), median(tb));
  }
  return 0;
}
