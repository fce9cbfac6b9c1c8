// Stokeslet sums: the fast kernel against the plain loop, masking of zero distance, NaN propagation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "solver/stokes/kernel_problem.h"
#include "solver/stokes/stokeslet.h"

namespace capsim::stokes::kernel {
namespace {

struct Cloud {
  std::vector<double> tx, ty, tz, sx, sy, sz, qx, qy, qz;
  Targets targets() const { return {tx.data(), ty.data(), tz.data(), static_cast<int>(tx.size())}; }
  Sources sources() const {
    return {sx.data(), sy.data(), sz.data(), qx.data(), qy.data(), qz.data(), static_cast<int>(sx.size())};
  }
};

// Random targets and sources in a box; the first targets sit exactly on sources (zero distance).
Cloud random_cloud(int nt, int ns, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Cloud c;
  for (int j = 0; j < ns; ++j) {
    c.sx.push_back(u(rng));
    c.sy.push_back(u(rng));
    c.sz.push_back(u(rng));
    c.qx.push_back(u(rng) + 1.5);  // non-zero mean: sums do not vanish
    c.qy.push_back(u(rng));
    c.qz.push_back(u(rng));
  }
  for (int i = 0; i < nt; ++i) {
    const bool on_source = i < 5;
    c.tx.push_back(on_source ? c.sx[3 * i] : u(rng));
    c.ty.push_back(on_source ? c.sy[3 * i] : u(rng));
    c.tz.push_back(on_source ? c.sz[3 * i] : u(rng));
  }
  return c;
}

// Scalar reference in long double.
void reference(const Cloud& c, std::vector<double>& rx, std::vector<double>& ry, std::vector<double>& rz) {
  const std::size_t nt = c.tx.size();
  rx.assign(nt, 0.0);
  ry.assign(nt, 0.0);
  rz.assign(nt, 0.0);
  for (std::size_t i = 0; i < nt; ++i) {
    long double a[3] = {0, 0, 0};
    for (std::size_t j = 0; j < c.sx.size(); ++j) {
      const long double dx = static_cast<long double>(c.tx[i]) - c.sx[j], dy = static_cast<long double>(c.ty[i]) - c.sy[j],
                        dz = static_cast<long double>(c.tz[i]) - c.sz[j];
      const long double r2 = dx * dx + dy * dy + dz * dz;
      if (r2 == 0) continue;
      const long double inv = 1.0L / std::sqrt(r2);
      add_stokeslet<long double>(dx, dy, dz, c.qx[j], c.qy[j], c.qz[j], inv, 1.0L, a[0], a[1], a[2]);
    }
    rx[i] = static_cast<double>(a[0]);
    ry[i] = static_cast<double>(a[1]);
    rz[i] = static_cast<double>(a[2]);
  }
}

double max_rel(const std::vector<double>& ax, const std::vector<double>& ay, const std::vector<double>& az,
               const std::vector<double>& bx, const std::vector<double>& by, const std::vector<double>& bz) {
  double e = 0.0;
  for (std::size_t i = 0; i < ax.size(); ++i) {
    const double d = std::hypot(ax[i] - bx[i], ay[i] - by[i], az[i] - bz[i]);
    if (!(d == d)) return std::numeric_limits<double>::infinity();
    e = std::max(e, d / std::hypot(bx[i], by[i], bz[i]));
  }
  return e;
}

// The arithmetic 1/√x of the omp-simd loops (Duffy correction, source layout; the float one in mixed
// precision) against 1/√x in long double, over the exponent range a capsule can reach and a dense mantissa
// sweep: the double one to a few ulps, the float one to float rounding (each Newton or Householder step
// left out misses by orders of magnitude: one step fewer leaves 1e-4 in float).
TEST(StokesletKernel, ArithmeticInverseSquareRootsReachTheirPrecision) {
  double worst_d = 0.0, worst_f = 0.0;
  for (double x = 1e-30; x < 1e30; x *= 1.000731) {
    const long double ref = 1.0L / std::sqrt(static_cast<long double>(x));
    worst_d = std::max(worst_d, static_cast<double>(std::fabs(rsqrt_arith(x) / ref - 1.0L)));
    const float xf = static_cast<float>(x);
    const long double reff = 1.0L / std::sqrt(static_cast<long double>(xf));
    worst_f = std::max(worst_f, static_cast<double>(std::fabs(rsqrt_arith(xf) / reff - 1.0L)));
  }
  std::printf("  max rel error: double %.2e, float %.2e\n", worst_d, worst_f);
  EXPECT_LT(worst_d, 1e-15);
  EXPECT_LT(worst_f, 2e-7);
}

// The one scalar Stokeslet (add_stokeslet) against the tensor it stands for: J(r)·q = 2q/|r| along r,
// q/|r| across it (exact in binary for |r| = 2), linear in q, weighted by w, masked by inv_r = 0.
TEST(StokesletKernel, ScalarStokesletIsTheOseenTensor) {
  double u[3] = {0.0, 0.0, 0.0};
  add_stokeslet(2.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.5, 1.0, u[0], u[1], u[2]);  // q ∥ r
  EXPECT_EQ(u[0], 1.0);
  EXPECT_EQ(u[1], 0.0);
  add_stokeslet(2.0, 0.0, 0.0, 0.0, 3.0, 0.0, 0.5, 1.0, u[0], u[1], u[2]);  // q ⊥ r, accumulates
  EXPECT_EQ(u[0], 1.0);
  EXPECT_EQ(u[1], 1.5);
  add_stokeslet(2.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 1.0, u[0], u[1], u[2]);  // masked pair
  EXPECT_EQ(u[0], 1.0);
  EXPECT_EQ(u[2], 0.0);
  // A general pair against (I/r + r rᵀ/r³)·q written as a matrix; w scales. The two orders of operation
  // differ by a few ulps: 1e-15 relative.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  for (int k = 0; k < 100; ++k) {
    const double r[3] = {d(rng), d(rng), d(rng)}, q[3] = {d(rng), d(rng), d(rng)}, w = 1.0 + d(rng);
    const double rn = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    double v[3] = {0.0, 0.0, 0.0}, ref[3], norm = 0.0;
    add_stokeslet(r[0], r[1], r[2], q[0], q[1], q[2], 1.0 / rn, w, v[0], v[1], v[2]);
    for (int i = 0; i < 3; ++i) {
      ref[i] = 0.0;
      for (int j = 0; j < 3; ++j) ref[i] += w * ((i == j ? 1.0 / rn : 0.0) + r[i] * r[j] / (rn * rn * rn)) * q[j];
      norm = std::max(norm, std::abs(ref[i]));
    }
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(v[i], ref[i], 4e-15 * norm) << "pair " << k;
  }
}

TEST(StokesletKernel, FastMatchesPlainAndLongDoubleForAllVariants) {
  // 203 targets: not a multiple of any tile width, so the padded last tile is exercised.
  const Cloud c = random_cloud(203, 517, 7);
  std::vector<double> rx, ry, rz, px(203), py(203), pz(203);
  reference(c, rx, ry, rz);
  sum_plain(c.targets(), c.sources(), {px.data(), py.data(), pz.data()});
  const double plain_err = max_rel(px, py, pz, rx, ry, rz);
  // Round-off bound, not a golden value: 517 terms of O(1) summed in double against long double.
  EXPECT_LT(plain_err, 1e-13);
  std::printf("  ISA %s, width %d; plain vs long double %.2e\n", kernel_isa(), simd_width(), plain_err);
  for (int block = 1; block <= 4; ++block)
    for (const InvSqrt inv : {InvSqrt::Newton, InvSqrt::SqrtDiv, InvSqrt::Hybrid}) {
      std::vector<double> fx(203, -1.0), fy(203, -1.0), fz(203, -1.0);
      sum_fast(c.targets(), c.sources(), {fx.data(), fy.data(), fz.data()}, {block, inv});
      const double e_plain = max_rel(fx, fy, fz, px, py, pz), e_ref = max_rel(fx, fy, fz, rx, ry, rz);
      std::printf("  block %d %s: vs plain %.2e, vs long double %.2e\n", block,
                  inv == InvSqrt::Newton ? "rsqrt+Newton" : inv == InvSqrt::SqrtDiv ? "sqrt+div" : "hybrid", e_plain, e_ref);
      EXPECT_LT(e_plain, kFastRelativeBound) << "block " << block;
      EXPECT_LT(e_ref, 1e-13) << "block " << block;
    }
}

// Every full sum (sum_fast, sum_plain, sum_mixed) has the same contract at the edges: a source exactly at the
// target contributes nothing, and a NaN propagates.
TEST(StokesletKernel, ZeroDistanceIsMaskedAndNaNPropagates) {
  using Sum = void (*)(const Targets&, const Sources&, const Result&);
  const std::pair<const char*, Sum> sums[] = {{"fast", [](const Targets& t, const Sources& s, const Result& u) { sum_fast(t, s, u); }},
                                              {"plain", &sum_plain},
                                              {"mixed", &sum_mixed},
                                              {"mixed, 8 lanes", &sum_mixed_8_lanes}};
  const std::vector<double> sx = {0.0, 1.0}, sy = {0.0, 0.0}, sz = {0.0, 0.0}, q1 = {1.0, 1.0}, q0 = {0.0, 0.0};
  const Sources s{sx.data(), sy.data(), sz.data(), q1.data(), q0.data(), q0.data(), 2};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> sxn = {nan, 1.0};
  const Sources sn{sxn.data(), sy.data(), sz.data(), q1.data(), q0.data(), q0.data(), 2};
  const double t0 = 0.0;
  for (const auto& [name, sum] : sums) {
    double ux = 0, uy = 0, uz = 0;
    sum({&t0, &t0, &t0, 1}, s, {&ux, &uy, &uz});
    // From the source at (1,0,0) with q = e1: r = (−1,0,0), J·q = q/r + r(r·q)/r³ = (1 + 1) e1 (exact in float).
    EXPECT_DOUBLE_EQ(ux, 2.0) << name;
    EXPECT_DOUBLE_EQ(uy, 0.0) << name;
    sum({&t0, &t0, &t0, 1}, sn, {&ux, &uy, &uz});
    EXPECT_TRUE(std::isnan(ux)) << name;
  }
}

// sum_blocks (the near-singular correction's kernel): one target against a chosen subset of equal blocks of
// sources equals the long-double sum over exactly those sources; a source at the target is masked; it adds
// to what u held; a NaN propagates.
TEST(StokesletKernel, BlocksSumExactlyTheListedBlocks) {
  const int w = simd_width(), len = 3 * w, nblocks = 7;
  Cloud c = random_cloud(1, len * nblocks, 11);
  c.tx[0] = c.sx[len + 2];  // the target sits on a source of block 1 (listed)
  c.ty[0] = c.sy[len + 2];
  c.tz[0] = c.sz[len + 2];
  const std::vector<int> begins = {len * 1, len * 4, len * 6, len * 2};
  Cloud listed = c;
  for (auto* v : {&listed.sx, &listed.sy, &listed.sz, &listed.qx, &listed.qy, &listed.qz}) v->clear();
  for (int b : begins)
    for (int p = b; p < b + len; ++p) {
      listed.sx.push_back(c.sx[p]);
      listed.sy.push_back(c.sy[p]);
      listed.sz.push_back(c.sz[p]);
      listed.qx.push_back(c.qx[p]);
      listed.qy.push_back(c.qy[p]);
      listed.qz.push_back(c.qz[p]);
    }
  std::vector<double> rx, ry, rz;
  reference(listed, rx, ry, rz);
  const double x0[3] = {c.tx[0], c.ty[0], c.tz[0]};
  double u[3] = {1.0, -2.0, 0.5};  // added to
  sum_blocks(x0, c.sources(), begins.data(), static_cast<int>(begins.size()), len, u);
  const std::vector<double> ux = {u[0] - 1.0}, uy = {u[1] + 2.0}, uz = {u[2] - 0.5};
  EXPECT_LT(max_rel(ux, uy, uz, rx, ry, rz), 1e-13);
  EXPECT_TRUE(std::isfinite(u[0]) && std::isfinite(u[1]) && std::isfinite(u[2]));

  c.sy[4 * len + 1] = std::numeric_limits<double>::quiet_NaN();
  double un[3] = {0.0, 0.0, 0.0};
  sum_blocks(x0, c.sources(), begins.data(), static_cast<int>(begins.size()), len, un);
  EXPECT_TRUE(std::isnan(un[0]));
}

TEST(StokesletKernel, Level2ProblemFastEqualsPlain) {
  const KernelProblem p = make_kernel_problem(2);
  EXPECT_EQ(p.num_targets(), 642);
  EXPECT_EQ(p.num_sources, 320 * 6);
  const int n = p.num_targets();
  std::vector<double> fx(n), fy(n), fz(n), px(n), py(n), pz(n);
  sum_fast(p.targets(), p.sources(), {fx.data(), fy.data(), fz.data()});
  sum_plain(p.targets(), p.sources(), {px.data(), py.data(), pz.data()});
  EXPECT_LT(max_rel(fx, fy, fz, px, py, pz), kFastRelativeBound);
}

// sum_mixed (numerics.kernel_precision = "mixed"): pair terms in float, sums in double. Against the plain
// double loop on the level-2 and level-3 problems (targets = nodes, sources = the regular quadrature points of
// the same mesh: the distances of a real evaluation, none below ≈ h/10). The bound follows from float
// arithmetic, not from a measurement: each term carries a few float roundings (2^-24 ≈ 6e-8 each, 1/r after
// one Newton step ≈ 2e-7) and the positions' rounding (6e-8 absolute) over r ≥ h/10; per target the float
// partial sums of kMixedBlock terms add at most ≈ kMixedBlock · 6e-8 of their size. kMixedRelativeBound = 1e-5 of |u| at each
// target holds those with room; the estimate 1/r without its Newton step (error 3.7e-4) or a load rounded to
// half precision would not. The partial last tile (642 = 40 · 16 + 2 = 20 · 32 + 2 targets) is covered by level 2.
// Both widths are held to it: sum_mixed (16 lanes on an AVX-512 build) and the 8-lane tile.
TEST(StokesletKernel, MixedPrecisionIsWithinFloatAccuracyOfThePlainSum) {
  using Sum = void (*)(const Targets&, const Sources&, const Result&);
  for (const auto& [name, sum] : {std::pair<const char*, Sum>{"sum_mixed", &sum_mixed}, {"8 lanes", &sum_mixed_8_lanes}})
    for (const int level : {2, 3}) {
      const KernelProblem p = make_kernel_problem(level);
      const int n = p.num_targets();
      std::vector<double> mx(n), my(n), mz(n), px(n), py(n), pz(n);
      sum(p.targets(), p.sources(), {mx.data(), my.data(), mz.data()});
      sum_plain(p.targets(), p.sources(), {px.data(), py.data(), pz.data()});
      const double e = max_rel(mx, my, mz, px, py, pz);
      std::printf("  level %d (%s; sum_mixed is %s here): mixed vs plain, max relative difference per target %.2e\n",
                  level, name, mixed_kernel_isa(), e);
      EXPECT_LT(e, kMixedRelativeBound) << name << ", level " << level;
      EXPECT_GT(e, 0.0) << "float terms cannot reproduce the double sum exactly";
    }
}

}  // namespace
}  // namespace capsim::stokes::kernel
