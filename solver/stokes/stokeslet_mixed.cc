// The regular Stokeslet sum in mixed precision (stokeslet.h, sum_mixed): pair terms in float, sums in double.
#include <algorithm>
#include <cmath>
#include <vector>

#include "solver/stokes/stokeslet.h"

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

namespace capsim::stokes::kernel {
namespace {

// Structure-of-arrays in float (one rounding per coordinate and load component).
struct FloatSoA {
  std::vector<float> x, y, z, qx, qy, qz;
};

void to_float(const double* in, int n, std::vector<float>& out) {
  out.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) out[i] = static_cast<float>(in[i]);
}

#if defined(__AVX2__) && defined(__FMA__)
constexpr int kLanes8 = 8;   // floats per __m256
constexpr int kBlock8 = 2;   // target vectors per tile (register blocking: 2 × 8 targets)

// kBlock8 × 8 targets against all sources. Per block of kMixedBlock sources the float accumulators are added
// into double ones (two __m256d per __m256).
inline void tile8(const float* tx, const float* ty, const float* tz, const FloatSoA& s, int ns, double* ux,
                  double* uy, double* uz) {
  constexpr int kBlock = kBlock8, kLanes = kLanes8;
  __m256 X[kBlock], Y[kBlock], Z[kBlock], UX[kBlock], UY[kBlock], UZ[kBlock];
  __m256d DX[2 * kBlock], DY[2 * kBlock], DZ[2 * kBlock];
  for (int b = 0; b < kBlock; ++b) {
    X[b] = _mm256_loadu_ps(tx + kLanes * b);
    Y[b] = _mm256_loadu_ps(ty + kLanes * b);
    Z[b] = _mm256_loadu_ps(tz + kLanes * b);
  }
  for (int b = 0; b < 2 * kBlock; ++b) DX[b] = DY[b] = DZ[b] = _mm256_setzero_pd();
  const __m256 zero = _mm256_setzero_ps(), half = _mm256_set1_ps(0.5f), three = _mm256_set1_ps(3.0f);
  const float *sx = s.x.data(), *sy = s.y.data(), *sz = s.z.data();
  const float *sqx = s.qx.data(), *sqy = s.qy.data(), *sqz = s.qz.data();
  for (int j0 = 0; j0 < ns; j0 += kMixedBlock) {
    for (int b = 0; b < kBlock; ++b) UX[b] = UY[b] = UZ[b] = _mm256_setzero_ps();
    const int j1 = std::min(ns, j0 + kMixedBlock);
    for (int j = j0; j < j1; ++j) {
      const __m256 px = _mm256_broadcast_ss(sx + j), py = _mm256_broadcast_ss(sy + j), pz = _mm256_broadcast_ss(sz + j);
      const __m256 qx = _mm256_broadcast_ss(sqx + j), qy = _mm256_broadcast_ss(sqy + j),
                   qz = _mm256_broadcast_ss(sqz + j);
      for (int b = 0; b < kBlock; ++b) {
        const __m256 dx = _mm256_sub_ps(X[b], px), dy = _mm256_sub_ps(Y[b], py), dz = _mm256_sub_ps(Z[b], pz);
        const __m256 r2 = _mm256_fmadd_ps(dz, dz, _mm256_fmadd_ps(dy, dy, _mm256_mul_ps(dx, dx)));
        const __m256 keep = _mm256_cmp_ps(r2, zero, _CMP_NEQ_UQ);  // r = 0 masked, NaN kept
        __m256 y = _mm256_and_ps(_mm256_rsqrt_ps(r2), keep);
        // One Newton step, y (3 − r² y²)/2: the estimate's 1.5·2^-12 becomes ≈ 2e-7 (float rounding).
        y = _mm256_mul_ps(_mm256_mul_ps(half, y), _mm256_fnmadd_ps(_mm256_mul_ps(r2, y), y, three));
        const __m256 rq = _mm256_fmadd_ps(dz, qz, _mm256_fmadd_ps(dy, qy, _mm256_mul_ps(dx, qx)));
        const __m256 s2 = _mm256_mul_ps(rq, _mm256_mul_ps(y, y));
        UX[b] = _mm256_fmadd_ps(y, _mm256_fmadd_ps(dx, s2, qx), UX[b]);
        UY[b] = _mm256_fmadd_ps(y, _mm256_fmadd_ps(dy, s2, qy), UY[b]);
        UZ[b] = _mm256_fmadd_ps(y, _mm256_fmadd_ps(dz, s2, qz), UZ[b]);
      }
    }
    for (int b = 0; b < kBlock; ++b) {
      auto widen = [](__m256 v, __m256d& lo, __m256d& hi) {
        lo = _mm256_add_pd(lo, _mm256_cvtps_pd(_mm256_castps256_ps128(v)));
        hi = _mm256_add_pd(hi, _mm256_cvtps_pd(_mm256_extractf128_ps(v, 1)));
      };
      widen(UX[b], DX[2 * b], DX[2 * b + 1]);
      widen(UY[b], DY[2 * b], DY[2 * b + 1]);
      widen(UZ[b], DZ[2 * b], DZ[2 * b + 1]);
    }
  }
  for (int b = 0; b < 2 * kBlock; ++b) {
    _mm256_storeu_pd(ux + 4 * b, DX[b]);
    _mm256_storeu_pd(uy + 4 * b, DY[b]);
    _mm256_storeu_pd(uz + 4 * b, DZ[b]);
  }
}
#endif

#if defined(__AVX512F__)
constexpr int kLanes16 = 16;  // floats per __m512
constexpr int kBlock16 = 2;   // target vectors per tile (2 × 16 targets)

// The same tile with 16 float lanes: on an AVX-512 machine the double kernel (sum_fast) already runs 8 lanes,
// so the 8-lane float tile above gains only ≈ 1.15× over it; twice the lanes restore mixed precision's point.
// 1/r from the 14-bit hardware estimate (rsqrt14) and one Newton step, as accurate as the 8-lane tile's or more.
inline void tile16(const float* tx, const float* ty, const float* tz, const FloatSoA& s, int ns, double* ux,
                   double* uy, double* uz) {
  constexpr int kBlock = kBlock16, kLanes = kLanes16;
  __m512 X[kBlock], Y[kBlock], Z[kBlock], UX[kBlock], UY[kBlock], UZ[kBlock];
  __m512d DX[2 * kBlock], DY[2 * kBlock], DZ[2 * kBlock];
  for (int b = 0; b < kBlock; ++b) {
    X[b] = _mm512_loadu_ps(tx + kLanes * b);
    Y[b] = _mm512_loadu_ps(ty + kLanes * b);
    Z[b] = _mm512_loadu_ps(tz + kLanes * b);
  }
  for (int b = 0; b < 2 * kBlock; ++b) DX[b] = DY[b] = DZ[b] = _mm512_setzero_pd();
  const __m512 zero = _mm512_setzero_ps(), half = _mm512_set1_ps(0.5f), three = _mm512_set1_ps(3.0f);
  const float *sx = s.x.data(), *sy = s.y.data(), *sz = s.z.data();
  const float *sqx = s.qx.data(), *sqy = s.qy.data(), *sqz = s.qz.data();
  for (int j0 = 0; j0 < ns; j0 += kMixedBlock) {
    for (int b = 0; b < kBlock; ++b) UX[b] = UY[b] = UZ[b] = _mm512_setzero_ps();
    const int j1 = std::min(ns, j0 + kMixedBlock);
    for (int j = j0; j < j1; ++j) {
      const __m512 px = _mm512_set1_ps(sx[j]), py = _mm512_set1_ps(sy[j]), pz = _mm512_set1_ps(sz[j]);
      const __m512 qx = _mm512_set1_ps(sqx[j]), qy = _mm512_set1_ps(sqy[j]), qz = _mm512_set1_ps(sqz[j]);
      for (int b = 0; b < kBlock; ++b) {
        const __m512 dx = _mm512_sub_ps(X[b], px), dy = _mm512_sub_ps(Y[b], py), dz = _mm512_sub_ps(Z[b], pz);
        const __m512 r2 = _mm512_fmadd_ps(dz, dz, _mm512_fmadd_ps(dy, dy, _mm512_mul_ps(dx, dx)));
        const __mmask16 keep = _mm512_cmp_ps_mask(r2, zero, _CMP_NEQ_UQ);  // r = 0 masked, NaN kept
        __m512 y = _mm512_maskz_rsqrt14_ps(keep, r2);
        y = _mm512_mul_ps(_mm512_mul_ps(half, y), _mm512_fnmadd_ps(_mm512_mul_ps(r2, y), y, three));
        const __m512 rq = _mm512_fmadd_ps(dz, qz, _mm512_fmadd_ps(dy, qy, _mm512_mul_ps(dx, qx)));
        const __m512 s2 = _mm512_mul_ps(rq, _mm512_mul_ps(y, y));
        UX[b] = _mm512_fmadd_ps(y, _mm512_fmadd_ps(dx, s2, qx), UX[b]);
        UY[b] = _mm512_fmadd_ps(y, _mm512_fmadd_ps(dy, s2, qy), UY[b]);
        UZ[b] = _mm512_fmadd_ps(y, _mm512_fmadd_ps(dz, s2, qz), UZ[b]);
      }
    }
    for (int b = 0; b < kBlock; ++b) {
      auto widen = [](__m512 v, __m512d& lo, __m512d& hi) {
        lo = _mm512_add_pd(lo, _mm512_cvtps_pd(_mm512_castps512_ps256(v)));
        hi = _mm512_add_pd(hi, _mm512_cvtps_pd(_mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(v), 1))));
      };
      widen(UX[b], DX[2 * b], DX[2 * b + 1]);
      widen(UY[b], DY[2 * b], DY[2 * b + 1]);
      widen(UZ[b], DZ[2 * b], DZ[2 * b + 1]);
    }
  }
  for (int b = 0; b < 2 * kBlock; ++b) {
    _mm512_storeu_pd(ux + 8 * b, DX[b]);
    _mm512_storeu_pd(uy + 8 * b, DY[b]);
    _mm512_storeu_pd(uz + 8 * b, DZ[b]);
  }
}
#endif

#if !(defined(__AVX2__) && defined(__FMA__))
constexpr int kLanes8 = 8;
constexpr int kBlock8 = 2;

// Portable: the lanes as an inner loop the compiler vectorises; 1/r as 1/std::sqrt in float.
inline void tile8(const float* tx, const float* ty, const float* tz, const FloatSoA& s, int ns, double* ux,
                  double* uy, double* uz) {
  constexpr int W = kLanes8 * kBlock8;
  double dx_[W] = {}, dy_[W] = {}, dz_[W] = {};
  for (int j0 = 0; j0 < ns; j0 += kMixedBlock) {
    float ax[W] = {}, ay[W] = {}, az[W] = {};
    add_sources_to_lanes<float, W>(tx, ty, tz, s.x.data(), s.y.data(), s.z.data(), s.qx.data(), s.qy.data(),
                                   s.qz.data(), j0, std::min(ns, j0 + kMixedBlock), ax, ay, az);
    for (int l = 0; l < W; ++l) {
      dx_[l] += ax[l];
      dy_[l] += ay[l];
      dz_[l] += az[l];
    }
  }
  for (int l = 0; l < W; ++l) {
    ux[l] = dx_[l];
    uy[l] = dy_[l];
    uz[l] = dz_[l];
  }
}
#endif


// The sum with tiles of W targets computed by Tile.
template <int W, void (*Tile)(const float*, const float*, const float*, const FloatSoA&, int, double*, double*,
                              double*)>
void sum_mixed_tiles(const Targets& t, const Sources& s, const Result& u) {
  if (t.n <= 0) return;
  // Targets padded to whole tiles with copies of the last one (their results are dropped).
  const int ntiles = (t.n + W - 1) / W, padded = ntiles * W;
  // The float copies live on between calls (one set per calling thread): a run calls this thousands of times
  // with the same sizes, so after the first call nothing is allocated.
  thread_local std::vector<float> tx, ty, tz;
  thread_local FloatSoA f;
  tx.resize(static_cast<std::size_t>(padded));
  ty.resize(tx.size());
  tz.resize(tx.size());
  for (int i = 0; i < padded; ++i) {
    const int k = std::min(i, t.n - 1);
    tx[i] = static_cast<float>(t.x[k]);
    ty[i] = static_cast<float>(t.y[k]);
    tz[i] = static_cast<float>(t.z[k]);
  }
  to_float(s.x, s.n, f.x);
  to_float(s.y, s.n, f.y);
  to_float(s.z, s.n, f.z);
  to_float(s.qx, s.n, f.qx);
  to_float(s.qy, s.n, f.qy);
  to_float(s.qz, s.n, f.qz);
  // The OpenMP threads must see this thread's copies, not their own thread_local ones: plain locals.
  const FloatSoA& src = f;
  const float *px = tx.data(), *py = ty.data(), *pz = tz.data();
#pragma omp parallel for schedule(static)
  for (int it = 0; it < ntiles; ++it) {
    const int i0 = it * W;
    alignas(64) double ox[W], oy[W], oz[W];
    Tile(px + i0, py + i0, pz + i0, src, s.n, ox, oy, oz);
    for (int l = 0; l < W && i0 + l < t.n; ++l) {
      u.x[i0 + l] = ox[l];
      u.y[i0 + l] = oy[l];
      u.z[i0 + l] = oz[l];
    }
  }
}

}  // namespace

void sum_mixed(const Targets& t, const Sources& s, const Result& u) {
#if defined(__AVX512F__)
  sum_mixed_tiles<kLanes16 * kBlock16, tile16>(t, s, u);
#else
  sum_mixed_tiles<kLanes8 * kBlock8, tile8>(t, s, u);
#endif
}

void sum_mixed_8_lanes(const Targets& t, const Sources& s, const Result& u) {
  sum_mixed_tiles<kLanes8 * kBlock8, tile8>(t, s, u);
}

const char* mixed_kernel_isa() {
#if defined(__AVX512F__)
  return "avx512";
#elif defined(__AVX2__) && defined(__FMA__)
  return "avx2";
#else
  return "portable";
#endif
}

}  // namespace capsim::stokes::kernel
