#include "solver/stokes/stokeslet.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "solver/stokes/stokeslet_lanes.h"

namespace capsim::stokes::kernel {
namespace {

#if defined(__AVX512F__) || (defined(__AVX2__) && defined(__FMA__))
#if defined(__AVX512F__)
using Lanes = lanes::Avx512d;
constexpr const char* kIsa = "avx512";
#else
using Lanes = lanes::Avx2d;
constexpr const char* kIsa = "avx2";
#endif
constexpr int kLanes = Lanes::kLanes;

template <int B, int kMode>
inline void tile(const double* tx, const double* ty, const double* tz, const Sources& s, double* ux, double* uy,
                 double* uz) {
  lanes::tile<Lanes, B, kMode>(tx, ty, tz, {s.x, s.y, s.z, s.qx, s.qy, s.qz}, s.n, ux, uy, uz);
}

inline void blocks(const double x0[3], const Sources& s, const int* begins, int count, int length, double u[3]) {
  lanes::blocks<Lanes>(x0, {s.x, s.y, s.z, s.qx, s.qy, s.qz}, begins, count, length, u);
}

// The double layer's tile: two target vectors (register blocking), 1/r hybrid (InvSqrt::Hybrid).
constexpr int kStressletBlock = 2;
constexpr int kStressletWidth = kLanes * kStressletBlock;
inline void stresslet_tile(const double* const (&t)[6], const StressletSources& s, double* ux, double* uy,
                           double* uz) {
  lanes::stresslet_tile<Lanes, kStressletBlock, 2>(t, {s.x, s.y, s.z, s.vx, s.vy, s.vz, s.nx, s.ny, s.nz}, s.n,
                                                   ux, uy, uz);
}
constexpr bool kStressletTiles = true;

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

constexpr int kStressletWidth = 16;
inline void stresslet_tile(const double* const (&)[6], const StressletSources&, double*, double*, double*) {}
constexpr bool kStressletTiles = false;  // stresslet_sum_fast is the plain loop
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

void stresslet_sum_plain(const StressletTargets& t, const StressletSources& s, const Result& u) {
  const int nt = t.n, ns = s.n;
  const double *sx = s.x, *sy = s.y, *sz = s.z, *vx = s.vx, *vy = s.vy, *vz = s.vz, *nx = s.nx, *ny = s.ny,
               *nz = s.nz;
#pragma omp parallel for schedule(static)
  for (int i = 0; i < nt; ++i) {
    const double x0 = t.x[i], y0 = t.y[i], z0 = t.z[i], v0x = t.vx[i], v0y = t.vy[i], v0z = t.vz[i];
    double ax = 0.0, ay = 0.0, az = 0.0;
#pragma omp simd reduction(+ : ax, ay, az)
    for (int j = 0; j < ns; ++j) {
      const double rx = sx[j] - x0, ry = sy[j] - y0, rz = sz[j] - z0;
      const double r2 = rx * rx + ry * ry + rz * rz;
      const double inv = r2 == 0.0 ? 0.0 : 1.0 / std::sqrt(r2);
      add_stresslet(rx, ry, rz, vx[j] - v0x, vy[j] - v0y, vz[j] - v0z, nx[j], ny[j], nz[j], inv, ax, ay, az);
    }
    u.x[i] = ax;
    u.y[i] = ay;
    u.z[i] = az;
  }
}

void stresslet_sum_fast(const StressletTargets& t, const StressletSources& s, const Result& u) {
  if (!kStressletTiles) {
    stresslet_sum_plain(t, s, u);
    return;
  }
  constexpr int W = kStressletWidth;
  const int ntiles = (t.n + W - 1) / W;
#pragma omp parallel for schedule(static)
  for (int it = 0; it < ntiles; ++it) {
    const int i0 = it * W;
    // Every tile through a local copy (six short arrays; the last tile padded with copies of the last target,
    // whose results are dropped).
    alignas(64) double b[6][W], ox[W], oy[W], oz[W];
    const double* in[6] = {t.x, t.y, t.z, t.vx, t.vy, t.vz};
    for (int k = 0; k < 6; ++k)
      for (int l = 0; l < W; ++l) b[k][l] = in[k][std::min(i0 + l, t.n - 1)];
    const double* const tp[6] = {b[0], b[1], b[2], b[3], b[4], b[5]};
    stresslet_tile(tp, s, ox, oy, oz);
    for (int l = 0; l < W && i0 + l < t.n; ++l) {
      u.x[i0 + l] = ox[l];
      u.y[i0 + l] = oy[l];
      u.z[i0 + l] = oz[l];
    }
  }
}

void sum_blocks(const double x0[3], const Sources& s, const int* begins, int count, int length, double u[3]) {
  blocks(x0, s, begins, count, length, u);
}

const char* kernel_isa() { return kIsa; }

int simd_width() { return kLanes; }

}  // namespace capsim::stokes::kernel
