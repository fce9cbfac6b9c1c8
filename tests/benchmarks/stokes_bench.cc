// Boundary-integral flow benchmarks: the full single-layer evaluation at
// levels 2, 3, 4 next to the same evaluation with the plain reference loop and the double layer of the same density
// (stokes/double_layer.h), and the bare Stokeslet sums
// (fast kernel variants and plain loop) in the same run. items_per_second = Stokeslet interactions/s.
// After the Google benchmarks, a far-field-tier table (SingleLayerOptions::far_degree / far_radius): wall
// time and error against the full rule on a deformed surface, and the discretisation error of the sphere
// identity for comparison. `--far_field=only` runs just the table, `--far_field=skip` just the benchmarks,
// `--far_field_reps=N` sets the repetitions per variant (median reported).
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "solver/mesh/mesh.h"
#include "solver/stokes/double_layer.h"
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

// One boundary operator's evaluations (SingleLayer or DoubleLayer: the same stats fields) on the sphere mesh,
// with the phase times as counters. items_per_second = target × regular-source pairs per second.
template <class Op>
void run_operator(benchmark::State& state, Op& op, const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& q) {
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
                          mesh.num_elements() * mesh::P2Tabulation::of_degree(op.options().regular_degree).size());
}

void single_layer(benchmark::State& state, stokes::KernelChoice kernel, bool symmetric) {
  const auto mesh = mesh::make_sphere_mesh(static_cast<int>(state.range(0)));
  stokes::SingleLayerOptions opt;
  opt.kernel = kernel;
  opt.symmetry = symmetric ? stokes::Symmetry::On : stokes::Symmetry::Off;
  stokes::SingleLayer op(mesh, opt);
  run_operator(state, op, mesh, test_load(mesh.nodes, symmetric));
}

// The double layer of the same density on the same mesh (all targets; its regular sum: targets in lanes, omp simd).
void BM_DoubleLayer(benchmark::State& state) {
  const auto mesh = mesh::make_sphere_mesh(static_cast<int>(state.range(0)));
  stokes::SingleLayerOptions opt;
  opt.symmetry = stokes::Symmetry::Off;
  stokes::DoubleLayer op(mesh, opt);
  run_operator(state, op, mesh, test_load(mesh.nodes, false));
}
BENCHMARK(BM_DoubleLayer)->DenseRange(2, 4)->Unit(benchmark::kMillisecond)->UseRealTime();

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

// ---- Far-field tier table ----

// A deformed ellipsoid-like surface without any mirror plane (stretched, sheared, bent) and a smooth load.
void deformed_scene(const mesh::SurfaceMesh& m, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& q) {
  x.resize(3, m.num_nodes());
  q.resize(3, m.num_nodes());
  for (int i = 0; i < m.num_nodes(); ++i) {
    const Eigen::Vector3d X = m.nodes.col(i);
    x.col(i) << 1.3 * X(0) + 0.25 * X(1) * X(1) + 0.1 * X(2), 0.8 * X(1) + 0.2 * X(0) * X(2),
        0.7 * X(2) + 0.15 * X(0) * X(0) + 0.1 * X(1);
    q.col(i) << 0.5 + X(0) * X(1) + 0.3 * X(2), -0.3 + X(2) * X(2) - 0.2 * X(0), X(2) * (1.0 + X(0)) + 0.4 * X(1);
  }
}

struct Timed {
  double median_s = 0.0;
  stokes::SingleLayerStats stats;  // of the median repetition (its phase breakdown)
};

Timed time_apply(stokes::SingleLayer& op, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q, Eigen::Matrix3Xd& u,
                 int reps) {
  std::vector<std::pair<double, stokes::SingleLayerStats>> t;
  op.apply(x, q, u);  // warm-up (first-touch of the work arrays)
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    op.apply(x, q, u);
    t.emplace_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), op.last_stats());
  }
  std::sort(t.begin(), t.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  return {t[t.size() / 2].first, t[t.size() / 2].second};
}

// Max over nodes of |u − (16π/3) f| / |(16π/3) f| for a uniform load on the unit sphere (discretisation error).
double sphere_identity_error(const mesh::SurfaceMesh& sphere, const stokes::SingleLayerOptions& opt) {
  stokes::SingleLayer op(sphere, opt);
  const Eigen::Vector3d f(0.3, -0.5, 0.8);
  const Eigen::Matrix3Xd u = op.apply(sphere.nodes, f.replicate(1, sphere.num_nodes()));
  const Eigen::Vector3d exact = 16.0 * std::numbers::pi / 3.0 * f;
  return (u.colwise() - exact).colwise().norm().maxCoeff() / exact.norm();
}

// Discretisation error of the full method on the deformed scene at `level`: max over the level's nodes of
// |u_L − u_{L+1}| / max |u_{L+1}|. The sphere meshes nest (every level-L node is bit for bit a level-(L+1)
// node, and the deformation is a function of the sphere point), and the method converges at order ~3, so
// this estimates the error of u_L to ~10%.
double deformed_discretisation_error(const mesh::SurfaceMesh& m, const Eigen::Matrix3Xd& u, int level) {
  const auto fine = mesh::make_sphere_mesh(level + 1);
  Eigen::Matrix3Xd xf, qf;
  deformed_scene(fine, xf, qf);
  stokes::SingleLayerOptions o;
  o.symmetry = stokes::Symmetry::Off;
  stokes::SingleLayer op(fine, o);
  const Eigen::Matrix3Xd uf = op.apply(xf, qf);
  std::map<std::array<double, 3>, int> index;
  for (int j = 0; j < fine.num_nodes(); ++j) index[{fine.nodes(0, j), fine.nodes(1, j), fine.nodes(2, j)}] = j;
  double worst = 0.0;
  for (int i = 0; i < m.num_nodes(); ++i) {
    const auto it = index.find({m.nodes(0, i), m.nodes(1, i), m.nodes(2, i)});
    if (it == index.end()) return -1.0;  // meshes do not nest: no estimate
    worst = std::max(worst, (u.col(i) - uf.col(it->second)).norm());
  }
  return worst / uf.colwise().norm().maxCoeff();
}

void far_field_table(int reps) {
  std::printf("\n## Far-field tier (regular_degree 4, kernel %s, %d OpenMP thread(s), median of %d applies)\n\n",
              sk::kernel_isa(), omp_get_max_threads(), reps);
  std::printf("err_full = max_i |u - u_full| / max |u_full| on a deformed asymmetric surface (u_full: far_degree "
              "0);\nerr/disc = err_full over the discretisation error of u_full on that surface (|u_L - u_L+1| at "
              "the shared nodes, given\nwith the far_degree 0 row); sphere = the uniform-load sphere identity error "
              "with the same options.\n\n");
  std::printf("| level | far_degree | far_radius | mid el./target | apply ms | sum / far / sing. ms | speed-up | "
              "err_full | err/disc | sphere |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const int level : {2, 3, 4}) {
    const auto m = mesh::make_sphere_mesh(level);
    Eigen::Matrix3Xd x, q, u, u_full;
    deformed_scene(m, x, q);
    stokes::SingleLayerOptions base;
    base.symmetry = stokes::Symmetry::Off;
    stokes::SingleLayer full(m, base);
    const Timed tf = time_apply(full, x, q, u_full, reps);
    const double scale = u_full.colwise().norm().maxCoeff();
    const double disc = deformed_discretisation_error(m, u_full, level);
    auto row = [&](int degree, double radius, const Timed& t, double err, double sphere) {
      const double mid = t.stats.targets > 0 ? static_cast<double>(t.stats.mid_elements) / t.stats.targets : 0.0;
      const std::string r = degree == 0 ? "-" : std::to_string(radius).substr(0, 3);
      char e[32];
      std::snprintf(e, sizeof e, degree == 0 ? "disc %.2e" : "%.3f", degree == 0 ? disc : err / disc);
      std::printf("| %d | %d | %s | %.1f of %d | %.2f | %.2f / %.2f / %.2f | %.2f | %.2e | %s | %.2e |\n", level,
                  degree, r.c_str(), degree == 0 ? m.num_elements() * 1.0 : mid, m.num_elements(), 1e3 * t.median_s,
                  1e3 * t.stats.regular_s, 1e3 * t.stats.far_s, 1e3 * t.stats.singular_s, tf.median_s / t.median_s,
                  err, e, sphere);
      std::fflush(stdout);
    };
    row(0, 0.0, tf, 0.0, sphere_identity_error(m, base));
    for (const int degree : {1, 2})
      for (const double radius : {2.0, 3.0, 4.0, 6.0, 8.0}) {
        stokes::SingleLayerOptions o = base;
        o.far_degree = degree;
        o.far_radius = radius;
        stokes::SingleLayer op(m, o);
        const Timed t = time_apply(op, x, q, u, reps);
        row(degree, radius, t, (u - u_full).colwise().norm().maxCoeff() / scale, sphere_identity_error(m, o));
      }
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string far_field = "on";
  int reps = 5;
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    if (std::strncmp(argv[i], "--far_field=", 12) == 0)
      far_field = argv[i] + 12;
    else if (std::strncmp(argv[i], "--far_field_reps=", 17) == 0)
      reps = std::max(1, std::atoi(argv[i] + 17));
    else
      rest.push_back(argv[i]);
  }
  int n = static_cast<int>(rest.size());
  if (far_field != "only") {
    benchmark::Initialize(&n, rest.data());
    if (benchmark::ReportUnrecognizedArguments(n, rest.data())) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
  }
  if (far_field != "skip") far_field_table(reps);
  return 0;
}
