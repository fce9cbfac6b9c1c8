#include "solver/stokes/stokeslet.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#if defined(__AVX512F__) || defined(__AVX2__)
#include <immintrin.h>
#endif

namespace capsim::stokes::kernel {
namespace {

// ---------------------------------------------------------------------------------------------------
// 1/r refinement. With y ≈ r2^{-1/2} of relative error δ, e = 1 − r2 y² ≈ −2δ and
//   r2^{-1/2} = y (1 − e)^{-1/2} = y (1 + e/2 + 3e²/8 + 5e³/16 + 35e⁴/128 + 63e⁵/256 + …).
// rsqrt14 (AVX-512): |δ| ≤ 2^-14, |e| ≤ 2^-13: terms to e³ leave 35/128·e⁴ ≤ 6e-17 (full double).
// rsqrtps (AVX2, single precision): |δ| ≤ 1.5·2^-12, |e| ≤ 7.4e-4: terms to e⁴ leave 63/256·e⁵ ≤ 6e-17.
constexpr double kC1 = 0.5, kC2 = 0.375, kC3 = 0.3125, kC4 = 35.0 / 128.0;

#if defined(__AVX512F__)
constexpr int kLanes = 8;
constexpr const char* kIsa = "avx512";

// kMode: 0 = sqrt+div, 1 = rsqrt14+Newton, 2 = hybrid (odd target vectors use sqrt+div, even ones Newton:
// the divider and the FMA pipes then work in parallel).
template <int B, int kMode>
inline void tile(const double* tx, const double* ty, const double* tz, const Sources& s, double* ux, double* uy,
                 double* uz) {
  __m512d X[B], Y[B], Z[B], UX[B], UY[B], UZ[B];
  for (int b = 0; b < B; ++b) {
    X[b] = _mm512_loadu_pd(tx + kLanes * b);
    Y[b] = _mm512_loadu_pd(ty + kLanes * b);
    Z[b] = _mm512_loadu_pd(tz + kLanes * b);
    UX[b] = _mm512_setzero_pd();
    UY[b] = _mm512_setzero_pd();
    UZ[b] = _mm512_setzero_pd();
  }
  const __m512d zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1.0);
  const __m512d c1 = _mm512_set1_pd(kC1), c2 = _mm512_set1_pd(kC2), c3 = _mm512_set1_pd(kC3);
  const double *sxp = s.x, *syp = s.y, *szp = s.z, *qxp = s.qx, *qyp = s.qy, *qzp = s.qz;
  const int n = s.n;
  for (int j = 0; j < n; ++j) {
    const __m512d sx = _mm512_set1_pd(sxp[j]), sy = _mm512_set1_pd(syp[j]), sz = _mm512_set1_pd(szp[j]);
    const __m512d qx = _mm512_set1_pd(qxp[j]), qy = _mm512_set1_pd(qyp[j]), qz = _mm512_set1_pd(qzp[j]);
    for (int b = 0; b < B; ++b) {
      const __m512d dx = _mm512_sub_pd(X[b], sx);
      const __m512d dy = _mm512_sub_pd(Y[b], sy);
      const __m512d dz = _mm512_sub_pd(Z[b], sz);
      const __m512d r2 = _mm512_fmadd_pd(dz, dz, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dx, dx)));
      // Lanes with r2 == 0 get 1/r = 0; unordered (NaN) lanes stay in so that NaN propagates.
      const __mmask8 k = _mm512_cmp_pd_mask(r2, zero, _CMP_NEQ_UQ);
      __m512d y;
      if (kMode == 1 || (kMode == 2 && b % 2 == 0)) {
        y = _mm512_maskz_rsqrt14_pd(k, r2);
        const __m512d e = _mm512_fnmadd_pd(_mm512_mul_pd(r2, y), y, one);
        const __m512d p = _mm512_fmadd_pd(_mm512_fmadd_pd(e, c3, c2), e, c1);
        y = _mm512_fmadd_pd(_mm512_mul_pd(e, p), y, y);
      } else {
        y = _mm512_maskz_div_pd(k, one, _mm512_sqrt_pd(r2));
      }
      const __m512d rq = _mm512_fmadd_pd(dz, qz, _mm512_fmadd_pd(dy, qy, _mm512_mul_pd(dx, qx)));
      const __m512d s2 = _mm512_mul_pd(rq, _mm512_mul_pd(y, y));
      // u += (q + r (r·q)/r²) / r
      UX[b] = _mm512_fmadd_pd(y, _mm512_fmadd_pd(dx, s2, qx), UX[b]);
      UY[b] = _mm512_fmadd_pd(y, _mm512_fmadd_pd(dy, s2, qy), UY[b]);
      UZ[b] = _mm512_fmadd_pd(y, _mm512_fmadd_pd(dz, s2, qz), UZ[b]);
    }
  }
  for (int b = 0; b < B; ++b) {
    _mm512_storeu_pd(ux + kLanes * b, UX[b]);
    _mm512_storeu_pd(uy + kLanes * b, UY[b]);
    _mm512_storeu_pd(uz + kLanes * b, UZ[b]);
  }
}

// Sum of the 8 lanes, added in the order of GCC's _mm512_reduce_add_pd (upper half + lower half, then the
// 128-bit halves, then the two lanes), so results are bitwise those of the intrinsic; written out because
// GCC 12's intrinsic extracts the upper half through a masked builtin that -Wuninitialized flags.
inline double reduce_add(__m512d v) {
  alignas(64) double t[kLanes];
  _mm512_store_pd(t, v);
  const double h0 = t[4] + t[0], h1 = t[5] + t[1], h2 = t[6] + t[2], h3 = t[7] + t[3];
  const double q0 = h2 + h0, q1 = h3 + h1;
  return q0 + q1;
}

// One target (broadcast) against blocks of sources in lanes; Newton 1/r as in tile<·, 1>.
inline void blocks(const double x0[3], const Sources& s, const int* begins, int count, int length, double u[3]) {
  const __m512d X = _mm512_set1_pd(x0[0]), Y = _mm512_set1_pd(x0[1]), Z = _mm512_set1_pd(x0[2]);
  const __m512d zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1.0);
  const __m512d c1 = _mm512_set1_pd(kC1), c2 = _mm512_set1_pd(kC2), c3 = _mm512_set1_pd(kC3);
  __m512d UX = zero, UY = zero, UZ = zero;
  for (int k = 0; k < count; ++k) {
    const int b = begins[k];
    for (int p = b; p < b + length; p += kLanes) {
      const __m512d dx = _mm512_sub_pd(X, _mm512_loadu_pd(s.x + p));
      const __m512d dy = _mm512_sub_pd(Y, _mm512_loadu_pd(s.y + p));
      const __m512d dz = _mm512_sub_pd(Z, _mm512_loadu_pd(s.z + p));
      const __m512d qx = _mm512_loadu_pd(s.qx + p), qy = _mm512_loadu_pd(s.qy + p), qz = _mm512_loadu_pd(s.qz + p);
      const __m512d r2 = _mm512_fmadd_pd(dz, dz, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dx, dx)));
      const __mmask8 m = _mm512_cmp_pd_mask(r2, zero, _CMP_NEQ_UQ);
      __m512d y = _mm512_maskz_rsqrt14_pd(m, r2);
      const __m512d e = _mm512_fnmadd_pd(_mm512_mul_pd(r2, y), y, one);
      y = _mm512_fmadd_pd(_mm512_mul_pd(e, _mm512_fmadd_pd(_mm512_fmadd_pd(e, c3, c2), e, c1)), y, y);
      const __m512d rq = _mm512_fmadd_pd(dz, qz, _mm512_fmadd_pd(dy, qy, _mm512_mul_pd(dx, qx)));
      const __m512d s2 = _mm512_mul_pd(rq, _mm512_mul_pd(y, y));
      UX = _mm512_fmadd_pd(y, _mm512_fmadd_pd(dx, s2, qx), UX);
      UY = _mm512_fmadd_pd(y, _mm512_fmadd_pd(dy, s2, qy), UY);
      UZ = _mm512_fmadd_pd(y, _mm512_fmadd_pd(dz, s2, qz), UZ);
    }
  }
  u[0] += reduce_add(UX);
  u[1] += reduce_add(UY);
  u[2] += reduce_add(UZ);
}

#elif defined(__AVX2__) && defined(__FMA__)
constexpr int kLanes = 4;
constexpr const char* kIsa = "avx2";

template <int B, int kMode>
inline void tile(const double* tx, const double* ty, const double* tz, const Sources& s, double* ux, double* uy,
                 double* uz) {
  __m256d X[B], Y[B], Z[B], UX[B], UY[B], UZ[B];
  for (int b = 0; b < B; ++b) {
    X[b] = _mm256_loadu_pd(tx + kLanes * b);
    Y[b] = _mm256_loadu_pd(ty + kLanes * b);
    Z[b] = _mm256_loadu_pd(tz + kLanes * b);
    UX[b] = _mm256_setzero_pd();
    UY[b] = _mm256_setzero_pd();
    UZ[b] = _mm256_setzero_pd();
  }
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
  const __m256d c1 = _mm256_set1_pd(kC1), c2 = _mm256_set1_pd(kC2), c3 = _mm256_set1_pd(kC3),
                c4 = _mm256_set1_pd(kC4);
  const int n = s.n;
  for (int j = 0; j < n; ++j) {
    const __m256d sx = _mm256_broadcast_sd(s.x + j), sy = _mm256_broadcast_sd(s.y + j),
                  sz = _mm256_broadcast_sd(s.z + j);
    const __m256d qx = _mm256_broadcast_sd(s.qx + j), qy = _mm256_broadcast_sd(s.qy + j),
                  qz = _mm256_broadcast_sd(s.qz + j);
    for (int b = 0; b < B; ++b) {
      const __m256d dx = _mm256_sub_pd(X[b], sx);
      const __m256d dy = _mm256_sub_pd(Y[b], sy);
      const __m256d dz = _mm256_sub_pd(Z[b], sz);
      const __m256d r2 = _mm256_fmadd_pd(dz, dz, _mm256_fmadd_pd(dy, dy, _mm256_mul_pd(dx, dx)));
      const __m256d keep = _mm256_cmp_pd(r2, zero, _CMP_NEQ_UQ);
      __m256d y;
      if (kMode == 1 || (kMode == 2 && b % 2 == 0)) {
        // Single-precision estimate (r2 within float range for capsule geometries), then one step.
        y = _mm256_cvtps_pd(_mm_rsqrt_ps(_mm256_cvtpd_ps(r2)));
        y = _mm256_and_pd(y, keep);
        const __m256d e = _mm256_fnmadd_pd(_mm256_mul_pd(r2, y), y, one);
        __m256d p = _mm256_fmadd_pd(_mm256_fmadd_pd(e, c4, c3), e, c2);
        p = _mm256_fmadd_pd(p, e, c1);
        y = _mm256_fmadd_pd(_mm256_mul_pd(e, p), y, y);
      } else {
        y = _mm256_and_pd(_mm256_div_pd(one, _mm256_sqrt_pd(r2)), keep);
      }
      const __m256d rq = _mm256_fmadd_pd(dz, qz, _mm256_fmadd_pd(dy, qy, _mm256_mul_pd(dx, qx)));
      const __m256d s2 = _mm256_mul_pd(rq, _mm256_mul_pd(y, y));
      UX[b] = _mm256_fmadd_pd(y, _mm256_fmadd_pd(dx, s2, qx), UX[b]);
      UY[b] = _mm256_fmadd_pd(y, _mm256_fmadd_pd(dy, s2, qy), UY[b]);
      UZ[b] = _mm256_fmadd_pd(y, _mm256_fmadd_pd(dz, s2, qz), UZ[b]);
    }
  }
  for (int b = 0; b < B; ++b) {
    _mm256_storeu_pd(ux + kLanes * b, UX[b]);
    _mm256_storeu_pd(uy + kLanes * b, UY[b]);
    _mm256_storeu_pd(uz + kLanes * b, UZ[b]);
  }
}

inline double hsum(__m256d v) {
  const __m128d lo = _mm256_castpd256_pd128(v), hi = _mm256_extractf128_pd(v, 1);
  const __m128d s = _mm_add_pd(lo, hi);
  return _mm_cvtsd_f64(_mm_add_sd(s, _mm_unpackhi_pd(s, s)));
}

// One target (broadcast) against blocks of sources in lanes; Newton 1/r as in tile<·, 1>.
inline void blocks(const double x0[3], const Sources& s, const int* begins, int count, int length, double u[3]) {
  const __m256d X = _mm256_set1_pd(x0[0]), Y = _mm256_set1_pd(x0[1]), Z = _mm256_set1_pd(x0[2]);
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
  const __m256d c1 = _mm256_set1_pd(kC1), c2 = _mm256_set1_pd(kC2), c3 = _mm256_set1_pd(kC3),
                c4 = _mm256_set1_pd(kC4);
  __m256d UX = zero, UY = zero, UZ = zero;
  for (int k = 0; k < count; ++k) {
    const int b = begins[k];
    for (int p = b; p < b + length; p += kLanes) {
      const __m256d dx = _mm256_sub_pd(X, _mm256_loadu_pd(s.x + p));
      const __m256d dy = _mm256_sub_pd(Y, _mm256_loadu_pd(s.y + p));
      const __m256d dz = _mm256_sub_pd(Z, _mm256_loadu_pd(s.z + p));
      const __m256d qx = _mm256_loadu_pd(s.qx + p), qy = _mm256_loadu_pd(s.qy + p), qz = _mm256_loadu_pd(s.qz + p);
      const __m256d r2 = _mm256_fmadd_pd(dz, dz, _mm256_fmadd_pd(dy, dy, _mm256_mul_pd(dx, dx)));
      const __m256d keep = _mm256_cmp_pd(r2, zero, _CMP_NEQ_UQ);
      __m256d y = _mm256_and_pd(_mm256_cvtps_pd(_mm_rsqrt_ps(_mm256_cvtpd_ps(r2))), keep);
      const __m256d e = _mm256_fnmadd_pd(_mm256_mul_pd(r2, y), y, one);
      __m256d pe = _mm256_fmadd_pd(_mm256_fmadd_pd(e, c4, c3), e, c2);
      pe = _mm256_fmadd_pd(pe, e, c1);
      y = _mm256_fmadd_pd(_mm256_mul_pd(e, pe), y, y);
      const __m256d rq = _mm256_fmadd_pd(dz, qz, _mm256_fmadd_pd(dy, qy, _mm256_mul_pd(dx, qx)));
      const __m256d s2 = _mm256_mul_pd(rq, _mm256_mul_pd(y, y));
      UX = _mm256_fmadd_pd(y, _mm256_fmadd_pd(dx, s2, qx), UX);
      UY = _mm256_fmadd_pd(y, _mm256_fmadd_pd(dy, s2, qy), UY);
      UZ = _mm256_fmadd_pd(y, _mm256_fmadd_pd(dz, s2, qz), UZ);
    }
  }
  u[0] += hsum(UX);
  u[1] += hsum(UY);
  u[2] += hsum(UZ);
}

#else
constexpr int kLanes = 8;
constexpr const char* kIsa = "portable";

// Portable: the same tile structure, lanes as a short inner loop the compiler vectorises (kMode unused).
template <int B, int kMode>
inline void tile(const double* tx, const double* ty, const double* tz, const Sources& s, double* ux, double* uy,
                 double* uz) {
  constexpr int W = kLanes * B;
  double ax[W] = {}, ay[W] = {}, az[W] = {};
  add_sources_to_lanes<double, W>(tx, ty, tz, s.x, s.y, s.z, s.qx, s.qy, s.qz, 0, s.n, ax, ay, az);
  for (int l = 0; l < W; ++l) {
    ux[l] = ax[l];
    uy[l] = ay[l];
    uz[l] = az[l];
  }
}

// Portable: lanes as an inner loop the compiler vectorises, accumulated over all blocks.
inline void blocks(const double x0[3], const Sources& s, const int* begins, int count, int length, double u[3]) {
  double ax[kLanes] = {}, ay[kLanes] = {}, az[kLanes] = {};
  for (int k = 0; k < count; ++k)
    for (int p = begins[k]; p < begins[k] + length; p += kLanes) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l) {
        const double dx = x0[0] - s.x[p + l], dy = x0[1] - s.y[p + l], dz = x0[2] - s.z[p + l];
        const double r2 = dx * dx + dy * dy + dz * dz;
        const double y = r2 == 0.0 ? 0.0 : 1.0 / std::sqrt(r2);
        add_stokeslet(dx, dy, dz, s.qx[p + l], s.qy[p + l], s.qz[p + l], y, 1.0, ax[l], ay[l], az[l]);
      }
    }
  for (int l = 0; l < kLanes; ++l) {
    u[0] += ax[l];
    u[1] += ay[l];
    u[2] += az[l];
  }
}
#endif

template <int B, int kMode>
void run_tiles(const Targets& t, const Sources& s, const Result& u) {
  constexpr int W = kLanes * B;
  const int ntiles = (t.n + W - 1) / W;
#pragma omp parallel for schedule(static)
  for (int it = 0; it < ntiles; ++it) {
    const int i0 = it * W;
    if (i0 + W <= t.n) {
      tile<B, kMode>(t.x + i0, t.y + i0, t.z + i0, s, u.x + i0, u.y + i0, u.z + i0);
    } else {
      // Partial last tile: pad with copies of the last target, keep only the valid lanes.
      alignas(64) double bx[W], by[W], bz[W], ox[W], oy[W], oz[W];
      for (int l = 0; l < W; ++l) {
        const int i = std::min(i0 + l, t.n - 1);
        bx[l] = t.x[i];
        by[l] = t.y[i];
        bz[l] = t.z[i];
      }
      tile<B, kMode>(bx, by, bz, s, ox, oy, oz);
      for (int l = 0; i0 + l < t.n; ++l) {
        u.x[i0 + l] = ox[l];
        u.y[i0 + l] = oy[l];
        u.z[i0 + l] = oz[l];
      }
    }
  }
}

template <int kMode>
void dispatch_block(const Targets& t, const Sources& s, const Result& u, int block) {
  switch (block) {
    case 1: run_tiles<1, kMode>(t, s, u); break;
    case 2: run_tiles<2, kMode>(t, s, u); break;
    case 3: run_tiles<3, kMode>(t, s, u); break;
    case 4: run_tiles<4, kMode>(t, s, u); break;
    default: throw std::invalid_argument("stokes kernel: block must be 1..4, got " + std::to_string(block));
  }
}

}  // namespace

void sum_fast(const Targets& t, const Sources& s, const Result& u, const FastConfig& config) {
  if (t.n <= 0) return;
  switch (config.inv_sqrt) {
    case InvSqrt::SqrtDiv: dispatch_block<0>(t, s, u, config.block); break;
    case InvSqrt::Newton: dispatch_block<1>(t, s, u, config.block); break;
    case InvSqrt::Hybrid: dispatch_block<2>(t, s, u, config.block); break;
  }
}

void sum_plain(const Targets& t, const Sources& s, const Result& u) {
  const int nt = t.n, ns = s.n;
  const double *sx = s.x, *sy = s.y, *sz = s.z, *qx = s.qx, *qy = s.qy, *qz = s.qz;
#pragma omp parallel for schedule(static)
  for (int i = 0; i < nt; ++i) {
    const double x0 = t.x[i], y0 = t.y[i], z0 = t.z[i];
    double ax = 0.0, ay = 0.0, az = 0.0;
#pragma omp simd reduction(+ : ax, ay, az)
    for (int j = 0; j < ns; ++j) {
      const double dx = x0 - sx[j], dy = y0 - sy[j], dz = z0 - sz[j];
      const double r2 = dx * dx + dy * dy + dz * dz;
      const double inv = r2 == 0.0 ? 0.0 : 1.0 / std::sqrt(r2);
      add_stokeslet(dx, dy, dz, qx[j], qy[j], qz[j], inv, 1.0, ax, ay, az);
    }
    u.x[i] = ax;
    u.y[i] = ay;
    u.z[i] = az;
  }
}

void sum_blocks(const double x0[3], const Sources& s, const int* begins, int count, int length, double u[3]) {
  blocks(x0, s, begins, count, length, u);
}

const char* kernel_isa() { return kIsa; }

int simd_width() { return kLanes; }

}  // namespace capsim::stokes::kernel
