// One membrane load evaluation (solver/README.md §2) split into its phases, at levels 3 and 4:
// kinematics + energy gradient R, mass-matrix assembly, CHOLMOD numeric factorisation (symbolic analysis is
// cached), triangular solves; and the conjugate-gradient alternative for the same M q = R; and the bending
// evaluation.
#include <benchmark/benchmark.h>

#include <cmath>

#include "solver/membrane/bending.h"
#include "solver/membrane/load_solver.h"
#include "solver/membrane/membrane_mechanics.h"

namespace {

using namespace capsim;

struct Problem {
  mesh::SurfaceMesh mesh;
  membrane::SkalakLaw law{1.0};
  Eigen::Matrix3Xd x;
  explicit Problem(int level) : mesh(mesh::make_capsule_mesh(level, 2.0)) {
    x = mesh.nodes;
    for (int i = 0; i < x.cols(); ++i) {
      x(0, i) *= 1.0 + 0.1 * std::sin(2.0 * x(1, i));
      x(1, i) += 0.05 * std::cos(x(0, i));
    }
  }
};

void BM_InternalForces(benchmark::State& state) {
  Problem p(static_cast<int>(state.range(0)));
  membrane::MembraneMechanics mech(p.mesh, p.mesh.nodes, p.law);
  for (auto _ : state) benchmark::DoNotOptimize(mech.evaluate(p.x));
  state.counters["nodes"] = p.mesh.num_nodes();
}

void BM_MassAssembly(benchmark::State& state) {
  Problem p(static_cast<int>(state.range(0)));
  membrane::LoadSolver solver(p.mesh);
  for (auto _ : state) solver.assemble(p.x);
}

void BM_CholmodFactorize(benchmark::State& state) {
  Problem p(static_cast<int>(state.range(0)));
  membrane::LoadSolver solver(p.mesh);
  solver.assemble(p.x);
  for (auto _ : state) solver.factorize();
}

void BM_CholmodSolve(benchmark::State& state) {
  Problem p(static_cast<int>(state.range(0)));
  membrane::MembraneMechanics mech(p.mesh, p.mesh.nodes, p.law);
  const auto R = mech.evaluate(p.x).internal_force;
  membrane::LoadSolver solver(p.mesh);
  solver.assemble(p.x);
  solver.factorize();
  Eigen::Matrix3Xd q;
  for (auto _ : state) solver.solve(R, q);
}

// CG from a cold start each time (the time loop warm-starts it from the previous q, which is cheaper).
void BM_ConjugateGradientSolve(benchmark::State& state) {
  Problem p(static_cast<int>(state.range(0)));
  membrane::MembraneMechanics mech(p.mesh, p.mesh.nodes, p.law);
  const auto R = mech.evaluate(p.x).internal_force;
  Eigen::Matrix3Xd q;
  int iterations = 0;
  for (auto _ : state) {
    state.PauseTiming();
    membrane::LoadSolver solver(p.mesh, {membrane::LoadSolver::Backend::ConjugateGradient, 6, 1e-12});
    solver.assemble(p.x);
    state.ResumeTiming();
    solver.factorize();
    solver.solve(R, q);
    iterations = solver.last_iterations();
  }
  state.counters["cg_iterations"] = iterations;
}

void BM_WholeLoadEvaluation(benchmark::State& state) {
  Problem p(static_cast<int>(state.range(0)));
  membrane::MembraneMechanics mech(p.mesh, p.mesh.nodes, p.law);
  membrane::LoadSolver solver(p.mesh);
  Eigen::Matrix3Xd q;
  for (auto _ : state) {
    const auto s = mech.evaluate(p.x);
    solver.compute_load(p.x, s.internal_force, q);
  }
}

// Bending (solver/membrane/bending.h), κ_b = 1e-3; second argument 0: the whole evaluation (K x, assembly,
// the curvature solve, the point loops, the adjoint solve), 1: its first phase alone (K x, assembly, the
// curvature solve, c at the points).
void BM_Bending(benchmark::State& state) {
  Problem p(static_cast<int>(state.range(0)));
  membrane::LoadSolver::Options o;
  membrane::BendingMechanics bending(p.mesh, p.mesh.nodes, membrane::HelfrichBending(1e-3), o);
  membrane::LoadSolver solver(p.mesh, o);
  const bool curvature_only = state.range(1) == 1;
  for (auto _ : state) {
    if (curvature_only) benchmark::DoNotOptimize(bending.total_curvature(p.x, solver));
    else benchmark::DoNotOptimize(bending.evaluate(p.x, solver));
  }
}

BENCHMARK(BM_Bending)->Args({3, 0})->Args({3, 1})->Args({4, 0})->Args({4, 1})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_InternalForces)->Arg(3)->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MassAssembly)->Arg(3)->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CholmodFactorize)->Arg(3)->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CholmodSolve)->Arg(3)->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ConjugateGradientSolve)->Arg(3)->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WholeLoadEvaluation)->Arg(3)->Arg(4)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
