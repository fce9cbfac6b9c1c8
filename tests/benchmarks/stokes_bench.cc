// Boundary-integral flow benchmarks (issue 3 "Benchmark", issue 6 §1): the full single-layer evaluation at
// levels 2, 3, 4 next to the same evaluation with the plain reference loop, and the bare Stokeslet sums
// (fast kernel variants and plain loop) in the same run. items_per_second = Stokeslet interactions/s.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <Eigen/Core>

#include "solver/mesh/mesh.h"
#include "solver/stokes/kernel_problem.h"
#include "solver/stokes/single_layer.h"
#include "solver/stokes/stokeslet.h"

namespace {

using namespace capsim;
namespace sk = capsim::stokes::kernel;

// A smooth load on the sphere; mirror-symmetric under x3 → −x3 when `symmetric`.
Eigen::Matrix3Xd test_load(const Eigen::Matrix3Xd& x, bool symmetric) {
  Eigen::Matrix3Xd q(3, x.cols());
  for (int i = 0; i < x.cols(); ++i)
    q.col(i) << 1.0 + 0.5 * x(0, i) * x(1, i), -0.4 + x(2, i) * x(2, i),
        symmetric ? 0.7 * x(2, i) : 0.7 * x(0, i) - 0.2 * x(1, i);
  return q;
}

void single_layer(benchmark::State& state, stokes::KernelChoice kernel, bool symmetric) {
  const auto mesh = mesh::make_sphere_mesh(static_cast<int>(state.range(0)));
  stokes::SingleLayerOptions opt;
  opt.kernel = kernel;
  opt.symmetry = symmetric ? stokes::Symmetry::On : stokes::Symmetry::Off;
  stokes::SingleLayer op(mesh, opt);
  const Eigen::Matrix3Xd q = test_load(mesh.nodes, symmetric);
  Eigen::Matrix3Xd u;
  double regular = 0, singular = 0, build = 0;
  for (auto _ : state) {
    op.apply(mesh.nodes, q, u);
    benchmark::DoNotOptimize(u.data());
    regular += op.last_stats().regular_s;
    singular += op.last_stats().singular_s;
    build += op.last_stats().build_s;
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["nodes"] = mesh.num_nodes();
  state.counters["targets"] = op.last_stats().targets;
  state.counters["build_ms"] = 1e3 * build / n;
  state.counters["regular_ms"] = 1e3 * regular / n;
  state.counters["singular_ms"] = 1e3 * singular / n;
  state.counters["threads"] = omp_get_max_threads();
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(op.last_stats().targets) *
                          op.num_quadrature_points());
}

void BM_SingleLayerFast(benchmark::State& s) { single_layer(s, stokes::KernelChoice::Fast, false); }
void BM_SingleLayerPlain(benchmark::State& s) { single_layer(s, stokes::KernelChoice::Plain, false); }
void BM_SingleLayerFastSymmetric(benchmark::State& s) { single_layer(s, stokes::KernelChoice::Fast, true); }
BENCHMARK(BM_SingleLayerFast)->DenseRange(2, 4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SingleLayerPlain)->DenseRange(2, 4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SingleLayerFastSymmetric)->DenseRange(2, 4)->Unit(benchmark::kMillisecond)->UseRealTime();

// Bare sums: args = level, block (0 = plain loop), mode (0 sqrt+div, 1 rsqrt+Newton, 2 hybrid).
void BM_StokesletSum(benchmark::State& state) {
  const auto prob = stokes::make_kernel_problem(static_cast<int>(state.range(0)));
  const int block = static_cast<int>(state.range(1));
  const int mode = static_cast<int>(state.range(2));
  const sk::FastConfig cfg{block, mode == 0 ? sk::InvSqrt::SqrtDiv : mode == 1 ? sk::InvSqrt::Newton : sk::InvSqrt::Hybrid};
  std::vector<double> ux(prob.num_targets()), uy(prob.num_targets()), uz(prob.num_targets());
  const sk::Result out{ux.data(), uy.data(), uz.data()};
  for (auto _ : state) {
    if (block == 0)
      sk::sum_plain(prob.targets(), prob.sources(), out);
    else
      sk::sum_fast(prob.targets(), prob.sources(), out, cfg);
    benchmark::DoNotOptimize(ux.data());
  }
  const char* names[3] = {" sqrt+div", " rsqrt+newton", " hybrid"};
  state.SetLabel(block == 0 ? "plain" : std::string(sk::kernel_isa()) + names[mode]);
  state.counters["threads"] = omp_get_max_threads();
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(prob.interactions()));
}
BENCHMARK(BM_StokesletSum)
    ->ArgNames({"level", "block", "mode"})
    ->Args({3, 0, 0})
    ->Args({3, 1, 1})
    ->Args({3, 3, 1})
    ->Args({3, 1, 0})
    ->Args({3, 3, 0})
    ->Args({3, 2, 2})
    ->Args({3, 4, 2})
    ->Args({4, 0, 0})
    ->Args({4, 2, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
