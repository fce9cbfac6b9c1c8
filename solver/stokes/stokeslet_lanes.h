#pragma once
/// @file
/// @brief The SIMD tiles of the Stokeslet sums (stokeslet.h), written once over the lane type. Internal to
/// solver/stokes: included by stokeslet.cc (sum_fast, sum_blocks) and stokeslet_mixed.cc (sum_mixed).
///
/// A lane type L is a small struct of static functions over one vector register of L::Scalar (double or
/// float): zero, set1, broadcast, load, sub, mul, fmadd (a·b + c), fnmadd (c − a·b), nonzero (r² ≠ 0 or
/// unordered, so that NaN propagates) and rsqrt_estimate (the hardware 1/√ estimate, zero where the mask is
/// off). Double lanes add store, reduce_add, inv_sqrt_div (1/√ by the vector sqrt and division, masked) and
/// kHouseholderTerms (terms of the series that refines the estimate to full double accuracy); float lanes add
/// Wide (the double lanes of the same instruction set) and widen_add (a float vector converted and added
/// into two Wide vectors).
/// The four lane types: Avx512d, Avx2d (sum_fast, sum_blocks, stresslet_sum_fast) and Avx512f, Avx2f (sum_mixed,
/// stresslet_sum_mixed). The double layer's tiles (stresslet_tile, stresslet_tile_mixed, below) restate
/// kernel::add_stresslet in lanes; tests/solver/stokes/double_layer_test.cc compares them with it.
///
/// Every lane type runs the same operations in the same order. What differs per instruction set is the 1/√
/// estimate (14 bits with AVX-512, 12 with AVX2) and so the length of its refinement in double: an AVX-512 and
/// an AVX2 build agree to round-off, not bitwise. The cost of this one body against the per-instruction-set
/// copies it replaced is in results/benchmarks.md, "Stokeslet tiles as one template".

#include <algorithm>
#include <type_traits>

#if defined(__AVX512F__) || (defined(__AVX2__) && defined(__FMA__))
#include <immintrin.h>
#endif

namespace capsim::stokes::kernel::lanes {

// ---------------------------------------------------------------------------------------------------
// 1/r refinement in double. With y ≈ r2^{-1/2} of relative error δ, e = 1 − r2 y² ≈ −2δ and
//   r2^{-1/2} = y (1 − e)^{-1/2} = y (1 + e/2 + 3e²/8 + 5e³/16 + 35e⁴/128 + 63e⁵/256 + …).
// rsqrt14 (AVX-512): |δ| ≤ 2^-14, |e| ≤ 2^-13: terms to e³ leave 35/128·e⁴ ≤ 6e-17 (full double).
// rsqrtps (AVX2, single precision): |δ| ≤ 1.5·2^-12, |e| ≤ 7.4e-4: terms to e⁴ leave 63/256·e⁵ ≤ 6e-17.
inline constexpr double kC1 = 0.5, kC2 = 0.375, kC3 = 0.3125, kC4 = 35.0 / 128.0;

#if defined(__AVX512F__)
/// @brief 8 double lanes (AVX-512F); 1/√ estimate rsqrt14 (14 bits).
struct Avx512d {
  using Scalar = double;
  using V = __m512d;
  using Mask = __mmask8;
  static constexpr int kLanes = 8;
  static constexpr int kHouseholderTerms = 3;
  static V zero() { return _mm512_setzero_pd(); }
  static V set1(double a) { return _mm512_set1_pd(a); }
  static V broadcast(const double* p) { return _mm512_set1_pd(*p); }
  static V load(const double* p) { return _mm512_loadu_pd(p); }
  static void store(double* p, V v) { _mm512_storeu_pd(p, v); }
  static V sub(V a, V b) { return _mm512_sub_pd(a, b); }
  static V mul(V a, V b) { return _mm512_mul_pd(a, b); }
  static V fmadd(V a, V b, V c) { return _mm512_fmadd_pd(a, b, c); }
  static V fnmadd(V a, V b, V c) { return _mm512_fnmadd_pd(a, b, c); }
  static Mask nonzero(V r2) { return _mm512_cmp_pd_mask(r2, _mm512_setzero_pd(), _CMP_NEQ_UQ); }
  static V rsqrt_estimate(Mask k, V r2) { return _mm512_maskz_rsqrt14_pd(k, r2); }
  static V inv_sqrt_div(Mask k, V r2, V one) { return _mm512_maskz_div_pd(k, one, _mm512_sqrt_pd(r2)); }
  /// Sum of the lanes in the order of GCC's _mm512_reduce_add_pd (upper half + lower half, then the 128-bit
  /// halves, then the two lanes), so results are bitwise those of the intrinsic; written out because GCC 12's
  /// intrinsic extracts the upper half through a masked builtin that -Wuninitialized flags.
  static double reduce_add(V v) {
    alignas(64) double t[kLanes];
    _mm512_store_pd(t, v);
    const double h0 = t[4] + t[0], h1 = t[5] + t[1], h2 = t[6] + t[2], h3 = t[7] + t[3];
    const double q0 = h2 + h0, q1 = h3 + h1;
    return q0 + q1;
  }
};

/// @brief 16 float lanes (AVX-512F); 1/√ estimate rsqrt14; widened into Avx512d.
struct Avx512f {
  using Scalar = float;
  using V = __m512;
  using Mask = __mmask16;
  using Wide = Avx512d;
  static constexpr int kLanes = 16;
  static V zero() { return _mm512_setzero_ps(); }
  static V set1(float a) { return _mm512_set1_ps(a); }
  static V broadcast(const float* p) { return _mm512_set1_ps(*p); }
  static V load(const float* p) { return _mm512_loadu_ps(p); }
  static V sub(V a, V b) { return _mm512_sub_ps(a, b); }
  static V mul(V a, V b) { return _mm512_mul_ps(a, b); }
  static V fmadd(V a, V b, V c) { return _mm512_fmadd_ps(a, b, c); }
  static V fnmadd(V a, V b, V c) { return _mm512_fnmadd_ps(a, b, c); }
  static Mask nonzero(V r2) { return _mm512_cmp_ps_mask(r2, _mm512_setzero_ps(), _CMP_NEQ_UQ); }
  static V rsqrt_estimate(Mask k, V r2) { return _mm512_maskz_rsqrt14_ps(k, r2); }
  static void widen_add(V v, Wide::V& lo, Wide::V& hi) {
    lo = _mm512_add_pd(lo, _mm512_cvtps_pd(_mm512_castps512_ps256(v)));
    hi = _mm512_add_pd(hi, _mm512_cvtps_pd(_mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(v), 1))));
  }
};
#endif

#if defined(__AVX2__) && defined(__FMA__)
/// @brief 4 double lanes (AVX2 + FMA); 1/√ estimate from the single-precision rsqrtps (12 bits).
struct Avx2d {
  using Scalar = double;
  using V = __m256d;
  using Mask = __m256d;
  static constexpr int kLanes = 4;
  static constexpr int kHouseholderTerms = 4;
  static V zero() { return _mm256_setzero_pd(); }
  static V set1(double a) { return _mm256_set1_pd(a); }
  static V broadcast(const double* p) { return _mm256_broadcast_sd(p); }
  static V load(const double* p) { return _mm256_loadu_pd(p); }
  static void store(double* p, V v) { _mm256_storeu_pd(p, v); }
  static V sub(V a, V b) { return _mm256_sub_pd(a, b); }
  static V mul(V a, V b) { return _mm256_mul_pd(a, b); }
  static V fmadd(V a, V b, V c) { return _mm256_fmadd_pd(a, b, c); }
  static V fnmadd(V a, V b, V c) { return _mm256_fnmadd_pd(a, b, c); }
  static Mask nonzero(V r2) { return _mm256_cmp_pd(r2, _mm256_setzero_pd(), _CMP_NEQ_UQ); }
  /// Single-precision estimate (r2 within float range for capsule geometries).
  static V rsqrt_estimate(Mask k, V r2) {
    return _mm256_and_pd(_mm256_cvtps_pd(_mm_rsqrt_ps(_mm256_cvtpd_ps(r2))), k);
  }
  static V inv_sqrt_div(Mask k, V r2, V one) { return _mm256_and_pd(_mm256_div_pd(one, _mm256_sqrt_pd(r2)), k); }
  static double reduce_add(V v) {
    const __m128d lo = _mm256_castpd256_pd128(v), hi = _mm256_extractf128_pd(v, 1);
    const __m128d s = _mm_add_pd(lo, hi);
    return _mm_cvtsd_f64(_mm_add_sd(s, _mm_unpackhi_pd(s, s)));
  }
};

/// @brief 8 float lanes (AVX2 + FMA); 1/√ estimate rsqrtps; widened into Avx2d.
struct Avx2f {
  using Scalar = float;
  using V = __m256;
  using Mask = __m256;
  using Wide = Avx2d;
  static constexpr int kLanes = 8;
  static V zero() { return _mm256_setzero_ps(); }
  static V set1(float a) { return _mm256_set1_ps(a); }
  static V broadcast(const float* p) { return _mm256_broadcast_ss(p); }
  static V load(const float* p) { return _mm256_loadu_ps(p); }
  static V sub(V a, V b) { return _mm256_sub_ps(a, b); }
  static V mul(V a, V b) { return _mm256_mul_ps(a, b); }
  static V fmadd(V a, V b, V c) { return _mm256_fmadd_ps(a, b, c); }
  static V fnmadd(V a, V b, V c) { return _mm256_fnmadd_ps(a, b, c); }
  static Mask nonzero(V r2) { return _mm256_cmp_ps(r2, _mm256_setzero_ps(), _CMP_NEQ_UQ); }
  static V rsqrt_estimate(Mask k, V r2) { return _mm256_and_ps(_mm256_rsqrt_ps(r2), k); }
  static void widen_add(V v, Wide::V& lo, Wide::V& hi) {
    lo = _mm256_add_pd(lo, _mm256_cvtps_pd(_mm256_castps256_ps128(v)));
    hi = _mm256_add_pd(hi, _mm256_cvtps_pd(_mm256_extractf128_ps(v, 1)));
  }
};
#endif

/// @brief How a tile computes 1/r per target vector b: kMode 0 = sqrt + division, 1 = estimate + refinement,
/// 2 = hybrid (even b refined, odd b divided: the divider and the FMA pipes then work in parallel). Float
/// lanes always refine.
template <int kMode>
constexpr bool refined(int b) {
  return kMode == 1 || (kMode == 2 && b % 2 == 0);
}

/// @brief The loop-invariant constants of the 1/r step, set once per tile.
template <class L>
struct Constants {
  using V = typename L::V;
  using S = typename L::Scalar;
  // Double: 1 and the series coefficients kC1..kC4. Float: one Newton step y (3 − r² y²)/2, 1/2 and 3.
  V one = L::set1(S(1)), c1 = L::set1(S(kC1)), c2 = L::set1(S(kC2)), c3 = L::set1(S(kC3)), c4 = L::set1(S(kC4));
  V half = L::set1(S(0.5)), three = L::set1(S(3));
  V minus6 = L::set1(S(-6));  // the stresslet's factor
};

/// @brief 1/r for the lanes' r2 (0 where r2 = 0, NaN kept), refined or divided.
template <class L, bool kRefined>
inline typename L::V inv_r(typename L::V r2, const Constants<L>& c) {
  using V = typename L::V;
  const typename L::Mask k = L::nonzero(r2);
  if constexpr (std::is_same_v<typename L::Scalar, float>) {
    // One Newton step, y (3 − r² y²)/2: a 12- or 14-bit estimate becomes ≈ 2e-7 (float rounding).
    const V y = L::rsqrt_estimate(k, r2);
    return L::mul(L::mul(c.half, y), L::fnmadd(L::mul(r2, y), y, c.three));
  } else if constexpr (kRefined) {
    V y = L::rsqrt_estimate(k, r2);
    const V e = L::fnmadd(L::mul(r2, y), y, c.one);
    V p;
    if constexpr (L::kHouseholderTerms == 3) {
      p = L::fmadd(L::fmadd(e, c.c3, c.c2), e, c.c1);
    } else {
      static_assert(L::kHouseholderTerms == 4);
      p = L::fmadd(L::fmadd(L::fmadd(e, c.c4, c.c3), e, c.c2), e, c.c1);
    }
    return L::fmadd(L::mul(e, p), y, y);
  } else {
    return L::inv_sqrt_div(k, r2, c.one);
  }
}

/// @brief u += J(r)·q for one vector of pairs, r = (dx, dy, dz): u += (q + r (r·q)/r²) / r.
template <class L, bool kRefined>
inline void add_pairs(typename L::V dx, typename L::V dy, typename L::V dz, typename L::V qx, typename L::V qy,
                      typename L::V qz, const Constants<L>& c, typename L::V& ux, typename L::V& uy,
                      typename L::V& uz) {
  using V = typename L::V;
  const V r2 = L::fmadd(dz, dz, L::fmadd(dy, dy, L::mul(dx, dx)));
  const V y = inv_r<L, kRefined>(r2, c);
  const V rq = L::fmadd(dz, qz, L::fmadd(dy, qy, L::mul(dx, qx)));
  const V s2 = L::mul(rq, L::mul(y, y));
  ux = L::fmadd(y, L::fmadd(dx, s2, qx), ux);
  uy = L::fmadd(y, L::fmadd(dy, s2, qy), uy);
  uz = L::fmadd(y, L::fmadd(dz, s2, qz), uz);
}

/// @brief The tile body: B target vectors (X, Y, Z) against the sources [j0, j1) (src = their x, y, z, qx, qy, qz),
/// one source broadcast at a time, accumulated into (UX, UY, UZ).
template <class L, int B, int kMode>
inline void add_sources(const typename L::V (&X)[B], const typename L::V (&Y)[B], const typename L::V (&Z)[B],
                        const typename L::Scalar* const (&src)[6], int j0, int j1, const Constants<L>& c,
                        typename L::V (&UX)[B], typename L::V (&UY)[B], typename L::V (&UZ)[B]) {
  using V = typename L::V;
  for (int j = j0; j < j1; ++j) {
    const V sx = L::broadcast(src[0] + j), sy = L::broadcast(src[1] + j), sz = L::broadcast(src[2] + j);
    const V qx = L::broadcast(src[3] + j), qy = L::broadcast(src[4] + j), qz = L::broadcast(src[5] + j);
    for (int b = 0; b < B; ++b) {
      const V dx = L::sub(X[b], sx), dy = L::sub(Y[b], sy), dz = L::sub(Z[b], sz);
      if (refined<kMode>(b))
        add_pairs<L, true>(dx, dy, dz, qx, qy, qz, c, UX[b], UY[b], UZ[b]);
      else
        add_pairs<L, false>(dx, dy, dz, qx, qy, qz, c, UX[b], UY[b], UZ[b]);
    }
  }
}

/// @brief B·L::kLanes targets against all sources in double lanes L (sum_fast's tile); u overwritten.
template <class L, int B, int kMode>
inline void tile(const double* tx, const double* ty, const double* tz, const double* const (&src)[6], int ns,
                 double* ux, double* uy, double* uz) {
  using V = typename L::V;
  V X[B], Y[B], Z[B], UX[B], UY[B], UZ[B];
  for (int b = 0; b < B; ++b) {
    X[b] = L::load(tx + L::kLanes * b);
    Y[b] = L::load(ty + L::kLanes * b);
    Z[b] = L::load(tz + L::kLanes * b);
    UX[b] = UY[b] = UZ[b] = L::zero();
  }
  const Constants<L> c;
  add_sources<L, B, kMode>(X, Y, Z, src, 0, ns, c, UX, UY, UZ);
  for (int b = 0; b < B; ++b) {
    L::store(ux + L::kLanes * b, UX[b]);
    L::store(uy + L::kLanes * b, UY[b]);
    L::store(uz + L::kLanes * b, UZ[b]);
  }
}

/// @brief The accumulation of a mixed tile: per block of kChunk sources, @p add_chunk(j0, j1, UX, UY, UZ) adds
/// the pairs of sources [j0, j1) to float vectors started at zero, which are widened and added into double sums;
/// the double sums are stored to u (overwritten). Shared by the Stokeslet's and the stresslet's mixed tiles.
template <class L, int B, int kChunk, class AddChunk>
inline void accumulate_mixed(int ns, AddChunk&& add_chunk, double* ux, double* uy, double* uz) {
  using V = typename L::V;
  using W = typename L::Wide;
  V UX[B], UY[B], UZ[B];
  typename W::V DX[2 * B], DY[2 * B], DZ[2 * B];
  for (int b = 0; b < 2 * B; ++b) DX[b] = DY[b] = DZ[b] = W::zero();
  for (int j0 = 0; j0 < ns; j0 += kChunk) {
    for (int b = 0; b < B; ++b) UX[b] = UY[b] = UZ[b] = L::zero();
    add_chunk(j0, std::min(ns, j0 + kChunk), UX, UY, UZ);
    for (int b = 0; b < B; ++b) {
      L::widen_add(UX[b], DX[2 * b], DX[2 * b + 1]);
      L::widen_add(UY[b], DY[2 * b], DY[2 * b + 1]);
      L::widen_add(UZ[b], DZ[2 * b], DZ[2 * b + 1]);
    }
  }
  for (int b = 0; b < 2 * B; ++b) {
    W::store(ux + W::kLanes * b, DX[b]);
    W::store(uy + W::kLanes * b, DY[b]);
    W::store(uz + W::kLanes * b, DZ[b]);
  }
}

/// @brief B·L::kLanes targets against all sources in float lanes L (sum_mixed's tile): per block of kChunk
/// sources the float sums are widened and added into double ones; u overwritten.
template <class L, int B, int kChunk>
inline void tile_mixed(const float* tx, const float* ty, const float* tz, const float* const (&src)[6], int ns,
                       double* ux, double* uy, double* uz) {
  using V = typename L::V;
  V X[B], Y[B], Z[B];
  for (int b = 0; b < B; ++b) {
    X[b] = L::load(tx + L::kLanes * b);
    Y[b] = L::load(ty + L::kLanes * b);
    Z[b] = L::load(tz + L::kLanes * b);
  }
  const Constants<L> c;
  accumulate_mixed<L, B, kChunk>(
      ns, [&](int j0, int j1, V(&UX)[B], V(&UY)[B], V(&UZ)[B]) { add_sources<L, B, 1>(X, Y, Z, src, j0, j1, c, UX, UY, UZ); },
      ux, uy, uz);
}

/// @brief u += −6 (d·r)(r·n) r / |r|⁵ for one vector of pairs, r = (rx, ry, rz) from the target to the source, d
/// the density difference, n the weighted normal: kernel::add_stresslet (stokeslet.h) in lanes, the same
/// operation order (the products grouped as there: (−6 (d·r)) (r·n), times (1/r²)² (1/r)).
template <class L, bool kRefined>
inline void add_stresslet_pairs(typename L::V rx, typename L::V ry, typename L::V rz, typename L::V dx,
                                typename L::V dy, typename L::V dz, typename L::V nx, typename L::V ny,
                                typename L::V nz, const Constants<L>& c, typename L::V& ux, typename L::V& uy,
                                typename L::V& uz) {
  using V = typename L::V;
  const V r2 = L::fmadd(rz, rz, L::fmadd(ry, ry, L::mul(rx, rx)));
  const V y = inv_r<L, kRefined>(r2, c);
  const V y2 = L::mul(y, y);
  const V dr = L::fmadd(dz, rz, L::fmadd(dy, ry, L::mul(dx, rx)));
  const V rn = L::fmadd(nz, rz, L::fmadd(ny, ry, L::mul(nx, rx)));
  const V s = L::mul(L::mul(L::mul(c.minus6, dr), rn), L::mul(L::mul(y2, y2), y));
  ux = L::fmadd(s, rx, ux);
  uy = L::fmadd(s, ry, uy);
  uz = L::fmadd(s, rz, uz);
}

/// @brief The double layer's tile body: B target vectors (positions X, Y, Z and densities VX, VY, VZ) against the
/// sources [j0, j1) (src = their x, y, z, vx, vy, vz, nx, ny, nz), one source broadcast at a time, accumulated
/// into (UX, UY, UZ).
template <class L, int B, int kMode>
inline void add_stresslet_sources(const typename L::V (&X)[B], const typename L::V (&Y)[B],
                                  const typename L::V (&Z)[B], const typename L::V (&VX)[B],
                                  const typename L::V (&VY)[B], const typename L::V (&VZ)[B],
                                  const typename L::Scalar* const (&src)[9], int j0, int j1, const Constants<L>& c,
                                  typename L::V (&UX)[B], typename L::V (&UY)[B], typename L::V (&UZ)[B]) {
  using V = typename L::V;
  for (int j = j0; j < j1; ++j) {
    const V sx = L::broadcast(src[0] + j), sy = L::broadcast(src[1] + j), sz = L::broadcast(src[2] + j);
    const V svx = L::broadcast(src[3] + j), svy = L::broadcast(src[4] + j), svz = L::broadcast(src[5] + j);
    const V nx = L::broadcast(src[6] + j), ny = L::broadcast(src[7] + j), nz = L::broadcast(src[8] + j);
    for (int b = 0; b < B; ++b) {
      const V rx = L::sub(sx, X[b]), ry = L::sub(sy, Y[b]), rz = L::sub(sz, Z[b]);
      const V dx = L::sub(svx, VX[b]), dy = L::sub(svy, VY[b]), dz = L::sub(svz, VZ[b]);
      if (refined<kMode>(b))
        add_stresslet_pairs<L, true>(rx, ry, rz, dx, dy, dz, nx, ny, nz, c, UX[b], UY[b], UZ[b]);
      else
        add_stresslet_pairs<L, false>(rx, ry, rz, dx, dy, dz, nx, ny, nz, c, UX[b], UY[b], UZ[b]);
    }
  }
}

/// @brief The B vectors of a double-layer tile's targets: positions t[0..2] and densities t[3..5], L::kLanes
/// targets per vector (stresslet_tile and stresslet_tile_mixed).
template <class L, int B>
inline void load_stresslet_targets(const typename L::Scalar* const (&t)[6], typename L::V (&X)[B],
                                   typename L::V (&Y)[B], typename L::V (&Z)[B], typename L::V (&VX)[B],
                                   typename L::V (&VY)[B], typename L::V (&VZ)[B]) {
  for (int b = 0; b < B; ++b) {
    X[b] = L::load(t[0] + L::kLanes * b);
    Y[b] = L::load(t[1] + L::kLanes * b);
    Z[b] = L::load(t[2] + L::kLanes * b);
    VX[b] = L::load(t[3] + L::kLanes * b);
    VY[b] = L::load(t[4] + L::kLanes * b);
    VZ[b] = L::load(t[5] + L::kLanes * b);
  }
}

/// @brief B·L::kLanes double-layer targets (t = their x, y, z, vx, vy, vz) against all sources in double lanes L
/// (stresslet_sum_fast's tile); u overwritten.
template <class L, int B, int kMode>
inline void stresslet_tile(const double* const (&t)[6], const double* const (&src)[9], int ns, double* ux,
                           double* uy, double* uz) {
  using V = typename L::V;
  V X[B], Y[B], Z[B], VX[B], VY[B], VZ[B], UX[B], UY[B], UZ[B];
  load_stresslet_targets<L, B>(t, X, Y, Z, VX, VY, VZ);
  for (int b = 0; b < B; ++b) UX[b] = UY[b] = UZ[b] = L::zero();
  const Constants<L> c;
  add_stresslet_sources<L, B, kMode>(X, Y, Z, VX, VY, VZ, src, 0, ns, c, UX, UY, UZ);
  for (int b = 0; b < B; ++b) {
    L::store(ux + L::kLanes * b, UX[b]);
    L::store(uy + L::kLanes * b, UY[b]);
    L::store(uz + L::kLanes * b, UZ[b]);
  }
}

/// @brief The same in float lanes L (stresslet_sum_mixed's tile): per block of kChunk sources the float sums are
/// widened and added into double ones; u overwritten.
template <class L, int B, int kChunk>
inline void stresslet_tile_mixed(const float* const (&t)[6], const float* const (&src)[9], int ns, double* ux,
                                 double* uy, double* uz) {
  using V = typename L::V;
  V X[B], Y[B], Z[B], VX[B], VY[B], VZ[B];
  load_stresslet_targets<L, B>(t, X, Y, Z, VX, VY, VZ);
  const Constants<L> c;
  accumulate_mixed<L, B, kChunk>(
      ns,
      [&](int j0, int j1, V(&UX)[B], V(&UY)[B], V(&UZ)[B]) {
        add_stresslet_sources<L, B, 1>(X, Y, Z, VX, VY, VZ, src, j0, j1, c, UX, UY, UZ);
      },
      ux, uy, uz);
}

/// @brief One target (broadcast) against `count` blocks of `length` sources in lanes (sum_blocks), refined 1/r;
/// the lanes are reduced once and added to u. Always inlined (GCC otherwise keeps it out of line): it runs once
/// per target of the near-singular correction.
template <class L>
[[gnu::always_inline]] inline void blocks(const double x0[3], const double* const (&src)[6], const int* begins,
                                          int count, int length, double u[3]) {
  using V = typename L::V;
  const V X = L::set1(x0[0]), Y = L::set1(x0[1]), Z = L::set1(x0[2]);
  const Constants<L> c;
  V UX = L::zero(), UY = UX, UZ = UX;
  for (int k = 0; k < count; ++k) {
    const int b = begins[k];
    for (int p = b; p < b + length; p += L::kLanes)
      add_pairs<L, true>(L::sub(X, L::load(src[0] + p)), L::sub(Y, L::load(src[1] + p)), L::sub(Z, L::load(src[2] + p)),
                         L::load(src[3] + p), L::load(src[4] + p), L::load(src[5] + p), c, UX, UY, UZ);
  }
  u[0] += L::reduce_add(UX);
  u[1] += L::reduce_add(UY);
  u[2] += L::reduce_add(UZ);
}

}  // namespace capsim::stokes::kernel::lanes
