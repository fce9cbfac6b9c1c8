// The regular Stokeslet sum in mixed precision (stokeslet.h, sum_mixed): pair terms in float, sums in double.
#include <algorithm>
#include <cmath>
#include <vector>

#include "solver/stokes/stokeslet.h"
#include "solver/stokes/stokeslet_lanes.h"

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

// Targets padded to `padded` (whole tiles) with copies of the last one, whose results the tiles drop.
void to_float_padded(const double* in, int n, int padded, std::vector<float>& out) {
  out.resize(static_cast<std::size_t>(padded));
  for (int i = 0; i < padded; ++i) out[i] = static_cast<float>(in[std::min(i, n - 1)]);
}

// The portable tiles' accumulation (without the SIMD lane types): per block of kMixedBlock sources,
// add_chunk(j0, j1, ax, ay, az) adds the pairs of sources [j0, j1) to W float sums started at zero, which are
// added into double ones; u overwritten. The float-lane counterpart is lanes::accumulate_mixed.
template <int W, class AddChunk>
inline void accumulate_portable(int ns, AddChunk&& add_chunk, double* ux, double* uy, double* uz) {
  double dx_[W] = {}, dy_[W] = {}, dz_[W] = {};
  for (int j0 = 0; j0 < ns; j0 += kMixedBlock) {
    float ax[W] = {}, ay[W] = {}, az[W] = {};
    add_chunk(j0, std::min(ns, j0 + kMixedBlock), ax, ay, az);
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

#if defined(__AVX512F__) || (defined(__AVX2__) && defined(__FMA__))
// kBlock vectors of L's float lanes of targets against all sources; per block of kMixedBlock sources the float
// sums are added into double ones (lanes::tile_mixed).
template <class L, int kBlock>
inline void tile_lanes(const float* tx, const float* ty, const float* tz, const FloatSoA& s, int ns, double* ux,
                       double* uy, double* uz) {
  lanes::tile_mixed<L, kBlock, kMixedBlock>(
      tx, ty, tz, {s.x.data(), s.y.data(), s.z.data(), s.qx.data(), s.qy.data(), s.qz.data()}, ns, ux, uy, uz);
}
#endif

#if defined(__AVX2__) && defined(__FMA__)
constexpr int kLanes8 = lanes::Avx2f::kLanes;
constexpr int kBlock8 = 2;  // target vectors per tile (register blocking: 2 × 8 targets)
constexpr auto tile8 = tile_lanes<lanes::Avx2f, kBlock8>;
#endif

#if defined(__AVX512F__)
// The same tile with 16 float lanes: on an AVX-512 machine the double kernel (sum_fast) already runs 8 lanes,
// so the 8-lane float tile above gains only ≈ 1.15× over it; twice the lanes restore mixed precision's point.
// 1/r from the 14-bit hardware estimate (rsqrt14) and one Newton step, as accurate as the 8-lane tile's or more.
constexpr int kLanes16 = lanes::Avx512f::kLanes;
constexpr int kBlock16 = 2;  // target vectors per tile (2 × 16 targets)
constexpr auto tile16 = tile_lanes<lanes::Avx512f, kBlock16>;
#endif

#if !(defined(__AVX2__) && defined(__FMA__))
constexpr int kLanes8 = 8;
constexpr int kBlock8 = 2;

// Portable: the lanes as an inner loop the compiler vectorises; 1/r as 1/std::sqrt in float.
inline void tile8(const float* tx, const float* ty, const float* tz, const FloatSoA& s, int ns, double* ux,
                  double* uy, double* uz) {
  constexpr int W = kLanes8 * kBlock8;
  accumulate_portable<W>(
      ns,
      [&](int j0, int j1, float* ax, float* ay, float* az) {
        add_sources_to_lanes<float, W>(tx, ty, tz, s.x.data(), s.y.data(), s.z.data(), s.qx.data(), s.qy.data(),
                                       s.qz.data(), j0, j1, ax, ay, az);
      },
      ux, uy, uz);
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
  to_float_padded(t.x, t.n, padded, tx);
  to_float_padded(t.y, t.n, padded, ty);
  to_float_padded(t.z, t.n, padded, tz);
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

// The double layer's sum in float lanes (stresslet_sum_mixed): two target vectors per tile.
struct StressletFloatSoA {
  std::vector<float> x, y, z, vx, vy, vz, nx, ny, nz;
};

#if defined(__AVX512F__) || (defined(__AVX2__) && defined(__FMA__))
#if defined(__AVX512F__)
using StressletLanes = lanes::Avx512f;
#else
using StressletLanes = lanes::Avx2f;
#endif
constexpr int kStressletWidth = StressletLanes::kLanes * 2;
inline void stresslet_tile_f(const float* const (&t)[6], const StressletFloatSoA& s, int ns, double* ux, double* uy,
                             double* uz) {
  lanes::stresslet_tile_mixed<StressletLanes, 2, kMixedBlock>(
      t, {s.x.data(), s.y.data(), s.z.data(), s.vx.data(), s.vy.data(), s.vz.data(), s.nx.data(), s.ny.data(),
          s.nz.data()},
      ns, ux, uy, uz);
}
#else
// Portable: the lanes as an inner loop the compiler vectorises, float terms, block sums in double.
constexpr int kStressletWidth = 16;
inline void stresslet_tile_f(const float* const (&t)[6], const StressletFloatSoA& s, int ns, double* ux, double* uy,
                             double* uz) {
  constexpr int W = kStressletWidth;
  accumulate_portable<W>(
      ns,
      [&](int j0, int j1, float* ax, float* ay, float* az) {
        for (int j = j0; j < j1; ++j) {
#pragma omp simd
          for (int l = 0; l < W; ++l) {
            const float rx = s.x[j] - t[0][l], ry = s.y[j] - t[1][l], rz = s.z[j] - t[2][l];
            const float r2 = rx * rx + ry * ry + rz * rz;
            const float inv = r2 == 0.0f ? 0.0f : 1.0f / std::sqrt(r2);
            add_stresslet(rx, ry, rz, s.vx[j] - t[3][l], s.vy[j] - t[4][l], s.vz[j] - t[5][l], s.nx[j], s.ny[j],
                          s.nz[j], inv, ax[l], ay[l], az[l]);
          }
        }
      },
      ux, uy, uz);
}
#endif

}  // namespace

void stresslet_sum_mixed(const StressletTargets& t, const StressletSources& s, const Result& u) {
  if (t.n <= 0) return;
  constexpr int W = kStressletWidth;
  const int ntiles = (t.n + W - 1) / W, padded = ntiles * W;
  // Float copies kept between calls (one set per calling thread), as in sum_mixed_tiles.
  thread_local std::vector<float> tf[6];
  thread_local StressletFloatSoA f;
  const double* tin[6] = {t.x, t.y, t.z, t.vx, t.vy, t.vz};
  for (int k = 0; k < 6; ++k) to_float_padded(tin[k], t.n, padded, tf[k]);
  to_float(s.x, s.n, f.x);
  to_float(s.y, s.n, f.y);
  to_float(s.z, s.n, f.z);
  to_float(s.vx, s.n, f.vx);
  to_float(s.vy, s.n, f.vy);
  to_float(s.vz, s.n, f.vz);
  to_float(s.nx, s.n, f.nx);
  to_float(s.ny, s.n, f.ny);
  to_float(s.nz, s.n, f.nz);
  // The OpenMP threads must see this thread's copies, not their own thread_local ones: plain locals.
  const StressletFloatSoA& src = f;
  const float* tp0[6] = {tf[0].data(), tf[1].data(), tf[2].data(), tf[3].data(), tf[4].data(), tf[5].data()};
  const float* const* tpp = tp0;
#pragma omp parallel for schedule(static)
  for (int it = 0; it < ntiles; ++it) {
    const int i0 = it * W;
    alignas(64) double ox[W], oy[W], oz[W];
    const float* const tp[6] = {tpp[0] + i0, tpp[1] + i0, tpp[2] + i0, tpp[3] + i0, tpp[4] + i0, tpp[5] + i0};
    stresslet_tile_f(tp, src, s.n, ox, oy, oz);
    for (int l = 0; l < W && i0 + l < t.n; ++l) {
      u.x[i0 + l] = ox[l];
      u.y[i0 + l] = oy[l];
      u.z[i0 + l] = oz[l];
    }
  }
}

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
