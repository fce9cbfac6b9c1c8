// Every Stokeslet kernel variant run with any build of the solver library, for before/after comparisons of the
// kernels themselves (results/benchmarks.md, "Stokeslet tiles as one template"): one line per variant with a
// hash of all output bits (equal hashes = bitwise equal sums) and, with REPEAT > 0, the best thread CPU time
// of REPEAT calls (CLOCK_THREAD_CPUTIME_ID: time lost to other processes on a shared machine does not count).
// Only the kernel API of solver/stokes/stokeslet.h is used; the solver library's kernel objects are the only
// ones linked, e.g. per build B (OMP_NUM_THREADS=1 for the timings):
//   g++ -O3 -march=native -fopenmp -std=c++20 -I<source of B> -o kernel_ab_B tests/benchmarks/kernel_ab.cc
//       B/solver/libcapsim_solver.a
//   kernel_ab_B [REPEAT [FILTER]]      (FILTER: run only the variants whose name contains it)
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "solver/stokes/stokeslet.h"

using namespace capsim::stokes::kernel;

namespace {

double cpu_now() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// FNV-1a over the bytes of the doubles.
std::uint64_t hash_bits(const std::vector<double>& v, std::uint64_t h) {
  for (const double d : v) {
    std::uint64_t b;
    std::memcpy(&b, &d, sizeof b);
    for (int k = 0; k < 8; ++k) h = (h ^ ((b >> (8 * k)) & 0xff)) * 1099511628211ull;
  }
  return h;
}

}  // namespace

int main(int argc, char** argv) {
  const int repeat = argc > 1 ? std::atoi(argv[1]) : 0;
  const std::string only = argc > 2 ? argv[2] : "";
  // Sources on an ellipsoid (semi-axes 1, 0.5, 0.7), targets on it too, every 7th exactly on a source (masked
  // pairs); 2565 targets: not a multiple of any tile width.
  std::mt19937_64 rng(42);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int ns = 7680, nt = 2565;
  std::vector<double> sx(ns), sy(ns), sz(ns), qx(ns), qy(ns), qz(ns), tx(nt), ty(nt), tz(nt);
  auto on_ellipsoid = [&](double& x, double& y, double& z) {
    const double a = g(rng), b = g(rng), c = g(rng), n = std::sqrt(a * a + b * b + c * c);
    x = a / n;
    y = 0.5 * b / n;
    z = 0.7 * c / n;
  };
  for (int j = 0; j < ns; ++j) {
    on_ellipsoid(sx[j], sy[j], sz[j]);
    qx[j] = 1e-3 * (u(rng) + 0.3);
    qy[j] = 1e-3 * u(rng);
    qz[j] = 1e-3 * u(rng);
  }
  for (int i = 0; i < nt; ++i) {
    if (i % 7 == 0) {
      tx[i] = sx[3 * i];
      ty[i] = sy[3 * i];
      tz[i] = sz[3 * i];
    } else {
      on_ellipsoid(tx[i], ty[i], tz[i]);
    }
  }
  const Targets t{tx.data(), ty.data(), tz.data(), nt};
  const Sources s{sx.data(), sy.data(), sz.data(), qx.data(), qy.data(), qz.data(), ns};
  std::vector<double> ox(nt), oy(nt), oz(nt);
  const Result r{ox.data(), oy.data(), oz.data()};
  auto report = [&](const std::string& name, auto&& sum) {
    if (name.find(only) == std::string::npos) return;
    sum();
    const std::uint64_t h = hash_bits(oz, hash_bits(oy, hash_bits(ox, 1469598103934665603ull)));
    double best = 1e30;
    for (int k = 0; k < repeat; ++k) {
      const double a = cpu_now();
      sum();
      best = std::min(best, cpu_now() - a);
    }
    std::printf("%-20s %016llx", name.c_str(), static_cast<unsigned long long>(h));
    if (repeat > 0) std::printf(" %9.3f ms", 1e3 * best);
    std::printf("\n");
  };
  for (int b = 1; b <= 4; ++b)
    for (const InvSqrt m : {InvSqrt::Newton, InvSqrt::SqrtDiv, InvSqrt::Hybrid})
      report("fast B=" + std::to_string(b) +
                 (m == InvSqrt::Newton ? " newton" : m == InvSqrt::SqrtDiv ? " sqrtdiv" : " hybrid"),
             [&] { sum_fast(t, s, r, {b, m}); });
  report("plain", [&] { sum_plain(t, s, r); });
  report("mixed", [&] { sum_mixed(t, s, r); });
  report("mixed 8 lanes", [&] { sum_mixed_8_lanes(t, s, r); });
  // sum_blocks: each target against 40 blocks of 64 sources, the blocks chosen per target.
  const int len = 64, count = 40;
  report("blocks", [&] {
    std::vector<int> begins(count);
    for (int i = 0; i < nt; ++i) {
      for (int k = 0; k < count; ++k) begins[k] = ((i * 37 + k * 101) % (ns / len)) * len;
      const double x0[3] = {tx[i], ty[i], tz[i]};
      double a[3] = {0.1, 0.2, 0.3};
      sum_blocks(x0, s, begins.data(), count, len, a);
      ox[i] = a[0];
      oy[i] = a[1];
      oz[i] = a[2];
    }
  });
  std::printf("kernel_isa %s, mixed_kernel_isa %s, simd_width %d\n", kernel_isa(), mixed_kernel_isa(), simd_width());
  return 0;
}
